#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""python_deps: every module that the Python of the test steps imports comes from a Debian
package that the step's scripts/setup groups install, and this interpreter sees it.

    python_deps.py [--step STEP]...      (default: every step below)

The cheap form of scripts/fresh-machine-check (seconds, run as a ctest): it catches
an import whose package no setup group names (a green CI on a used machine hides that:
the package is there by chance), a module the interpreter finds outside Debian's packages
(pip, pyenv) and a package that is installed but this interpreter does not see (the wrong
interpreter: issue 39, a pyenv python3 first on PATH without Debian's python3-numpy).
Imports are followed from the step's files through its local modules; an import inside a
`try:` that handles ImportError is optional and not required. Code run in a venv of its own
(tests/web, record, fmu, ros2's peer, integrations' package tests) is not listed: its
runner installs it from pinned requirements.
"""
import argparse
import ast
import functools
import importlib.util
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# Third-party module -> the Debian package that provides it.
DEBIAN = {"numpy": "python3-numpy", "pytest": "python3-pytest", "matplotlib": "python3-matplotlib"}

# step -> (setup groups, files or directories run by the chosen interpreter, modules imported
# otherwise (run with -m; imported by a program in a string, as test_clock_state.py does with
# ccomm), local module directories besides each file's own).
CORE = (["tests/integration"], ["pytest", "ccomm"], ["python/src", "scripts"])
STEPS = {
    "release": (["core"],) + CORE,
    "asan": (["core"],) + CORE,
    "tsan": (["core"],) + CORE,
    "abi": (["core", "abi"], ["tests/abi"], [], []),
    "reliability": (["core", "fuzz"], ["tests/reliability", "scripts/wire_vectors.py"], [], []),
    "manyboards": (["core", "manyboards"], ["tests/manyboards"], [], ["python/src"]),
    "wireshark": (["core", "wireshark"], ["tests/wireshark"], [], ["scripts", "tests/integration"]),
    "kernel": (["core", "kernel"], ["scripts/kernel-check"], [], ["scripts"]),
    "bench": (["core", "bench"], ["scripts/bench", "scripts/bench-floors", "bench/benchlib"], [], ["bench"]),
    "integrations": (["core"], ["integrations/20sim", "integrations/simulink"], [], ["integrations/20sim"]),
    "qemu": (["core", "isar"], ["scripts/check-image", "qemu-tests"], [], []),
}


def py_files(path):
    if os.path.isfile(path):
        return [path]
    return sorted(os.path.join(d, f) for d, _, fs in os.walk(path) for f in fs if f.endswith(".py"))


def optional_lines(tree):
    """Line numbers of imports inside a try: that catches ImportError."""
    lines = set()
    for n in ast.walk(tree):
        if isinstance(n, ast.Try) and any(
                h.type is None or any(isinstance(x, ast.Name) and x.id in ("ImportError", "ModuleNotFoundError")
                                      for x in (h.type.elts if isinstance(h.type, ast.Tuple) else [h.type]))
                for h in n.handlers):
            for s in n.body:
                lines.update(range(s.lineno, (s.end_lineno or s.lineno) + 1))
    return lines


def imports(path):
    """(names, level, FILE:LINE) of each required import in path: the dotted names it may
    load (for `from a import b`: a and a.b, b being a submodule or not)."""
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read(), path)
    opt = optional_lines(tree)
    for n in ast.walk(tree):
        if getattr(n, "lineno", None) in opt:
            continue
        where = "%s:%d" % (os.path.relpath(path, ROOT), getattr(n, "lineno", 0))
        if isinstance(n, ast.Import):
            for a in n.names:
                yield [a.name], 0, where
        elif isinstance(n, ast.ImportFrom):
            base = [n.module] if n.module else []
            yield base + [".".join(base + [a.name]) for a in n.names], n.level, where


def local(dotted, dirs):
    """The files that importing dotted loads from dirs (packages' __init__.py and the
    module), or None when it is not a local module."""
    parts = dotted.split(".")
    for d in dirs:
        files, path = [], d
        for p in parts:
            if os.path.isfile(os.path.join(path, p, "__init__.py")):
                path = os.path.join(path, p)
                files.append(os.path.join(path, "__init__.py"))
            elif os.path.isfile(os.path.join(path, p + ".py")):
                files.append(os.path.join(path, p + ".py"))
                break
            else:
                break
        if files:
            return files
    return None


def third_party(paths, extra, local_dirs, step):
    """{module: first FILE:LINE} of the non-stdlib, non-local modules reachable from paths
    and from the modules in extra."""
    roots = [os.path.join(ROOT, d) for d in local_dirs]
    todo = [f for p in paths for f in py_files(os.path.join(ROOT, p))]
    seen, found = set(), {}
    for mod in extra:
        loc = local(mod, roots)
        if loc:
            todo.extend(loc)
        else:
            found[mod] = "scripts/test (%s: %s)" % (step, mod)
    while todo:
        f = todo.pop()
        if f in seen:
            continue
        seen.add(f)
        for names, level, where in imports(f):
            if level:
                # Relative: inside f's own package, never third-party.
                base = os.path.dirname(f)
                for _ in range(level - 1):
                    base = os.path.dirname(base)
                for name in names or [""]:
                    todo.extend(local(name, [base]) or [])
                if not names:
                    todo.append(os.path.join(base, "__init__.py"))
                continue
            top = names[0].split(".")[0]
            if top in sys.stdlib_module_names:
                continue
            dirs = [os.path.dirname(f)] + roots
            if local(top, dirs):
                for name in names:
                    todo.extend(local(name, dirs) or [])
            else:
                found.setdefault(top, where)
    return found


@functools.lru_cache(maxsize=None)
def setup_list(groups):
    out = subprocess.run([os.path.join(ROOT, "scripts", "setup"), "--list"] + list(groups),
                         capture_output=True, text=True, check=True).stdout
    return set(out.split())


@functools.lru_cache(maxsize=None)
def installed(pkg):
    r = subprocess.run(["dpkg-query", "-W", "-f=${Status}", pkg], capture_output=True, text=True)
    return r.returncode == 0 and "install ok installed" in r.stdout


@functools.lru_cache(maxsize=None)
def owner(path):
    r = subprocess.run(["dpkg", "-S", path], capture_output=True, text=True)
    return r.stdout.split(":")[0].strip() if r.returncode == 0 else None


def check(step):
    groups, paths, extra, local_dirs = STEPS[step]
    wanted = setup_list(tuple(groups))
    mods = third_party(paths, extra, local_dirs, step)
    errors = []
    for mod, where in sorted(mods.items()):
        pkg = DEBIAN.get(mod)
        if pkg is None:
            errors.append("%s: imports '%s', which no Debian package in python_deps.DEBIAN provides" % (where, mod))
            continue
        if pkg not in wanted:
            errors.append("%s: imports '%s' (Debian: %s), not in scripts/setup %s" % (where, mod, pkg, " ".join(groups)))
            continue
        spec = importlib.util.find_spec(mod)
        if spec is None:
            if installed(pkg):
                errors.append("%s: '%s': %s is installed but %s does not see it: not Debian's interpreter?"
                              % (where, mod, pkg, sys.executable))
            continue
        origin = spec.origin or (list(spec.submodule_search_locations or [None])[0])
        got = owner(origin) if origin else None
        if got != pkg:
            errors.append("%s: '%s' comes from %s (%s), not from %s: pip/pyenv, not what scripts/setup installs"
                          % (where, mod, origin, got or "no Debian package", pkg))
    return mods, errors


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--step", action="append", choices=sorted(STEPS))
    a = ap.parse_args()
    bad = 0
    for step in a.step or sorted(STEPS):
        mods, errors = check(step)
        for e in errors:
            print("python_deps: %s: %s" % (step, e), file=sys.stderr)
        print("python_deps: %s: %s: %s" % (step, "FAIL" if errors else "ok", ", ".join(sorted(mods)) or "stdlib only"))
        bad += len(errors)
    print("python_deps: interpreter %s, %d problem(s)" % (sys.executable, bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
