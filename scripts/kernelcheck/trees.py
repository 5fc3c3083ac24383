# SPDX-License-Identifier: Apache-2.0
"""The kernel trees scripts/kernel-check works on: Debian's linux-source tarball extracted
once into the cache, and a hard-linked copy of it with Debian's PREEMPT_RT patch set
(debian/patches-rt of the `linux` source package, fetched with apt) applied."""
import os
import re
import shutil
import subprocess
import sys
import time


def say(msg=""):
    print(msg, flush=True)


def die(msg):
    print(f"kernel-check: {msg}", file=sys.stderr)
    sys.exit(2)


def run(cmd, cwd=None, env=None, log=None):
    """Runs cmd; returns (status, combined output). Output also goes to log if given."""
    full_env = dict(os.environ, **(env or {}))
    p = subprocess.run(cmd, cwd=cwd, env=full_env, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True, errors="replace")
    if log:
        with open(log, "a") as f:
            f.write(f"$ {' '.join(cmd)}\n{p.stdout}\n")
    return p.returncode, p.stdout


def extract(tarball, dest, label):
    stamp = os.path.join(dest, ".ccomm-extracted")
    st = os.stat(tarball)
    key = f"{tarball} {st.st_size} {int(st.st_mtime)}\n"
    if os.path.isfile(stamp) and open(stamp).read() == key:
        return
    shutil.rmtree(dest, ignore_errors=True)
    os.makedirs(dest)
    say(f"kernel-check: extracting {os.path.basename(tarball)} for {label} (once; about 30 s)")
    t = time.time()
    if subprocess.run(["tar", "-xJf", tarball, "-C", dest]).returncode != 0:
        die(f"cannot extract {tarball}")
    say(f"kernel-check: extracted in {time.time() - t:.0f} s")
    with open(stamp, "w") as f:
        f.write(key)


def tree_dir(dest):
    subdirs = [d for d in os.listdir(dest) if os.path.isdir(os.path.join(dest, d))]
    if len(subdirs) != 1:
        die(f"{dest}: expected one kernel tree, found {subdirs}")
    return os.path.join(dest, subdirs[0])


def fetch_rt_patches(cache, version):
    """debian/patches-rt from Debian's `linux` source package VERSION (or the newest 6.1 one
    apt can fetch). Returns (directory with series, version used) or (None, reason)."""
    apt = os.path.join(cache, "apt")
    os.makedirs(os.path.join(apt, "lists", "partial"), exist_ok=True)
    os.makedirs(os.path.join(apt, "cache", "archives", "partial"), exist_ok=True)
    with open(os.path.join(apt, "sources.list"), "w") as f:
        f.write("deb-src http://deb.debian.org/debian bookworm main\n"
                "deb-src http://deb.debian.org/debian-security bookworm-security main\n")
    # a private source list and state: the system's apt configuration stays as it is
    opts = ["-o", f"Dir::Etc::SourceList={apt}/sources.list", "-o", "Dir::Etc::SourceParts=/dev/null",
            "-o", f"Dir::State::Lists={apt}/lists", "-o", f"Dir::Cache={apt}/cache", "-q",
            "-o", "Acquire::http::Timeout=30", "-o", "Acquire::Retries=2"]
    rc, out = run(["apt-get"] + opts + ["update"])
    if rc != 0:
        return None, "apt-get update of the deb-src index failed:\n" + out[-800:]
    rc, out = run(["apt-cache"] + opts + ["showsrc", "linux"])
    versions = re.findall(r"^Version: (6\.1\.\S+)$", out, re.M)
    versions = sorted(set(versions), key=lambda v: [int(x) if x.isdigit() else x
                                                    for x in re.split(r"[.\-+~]", v)], reverse=True)
    tried = []
    for v in ([version] if version in versions else []) + [x for x in versions if x != version]:
        if len(tried) >= 20:  # each miss costs a fraction of a second
            break
        rc, out = run(["apt-get"] + opts + ["source", "--print-uris", f"linux={v}"])
        m = re.search(r"'(\S+\.debian\.tar\.xz)' (\S+) \d+ (SHA256:\w+)", out)
        if not m:
            tried.append(f"{v}: no debian.tar.xz listed")
            continue
        dest = os.path.join(cache, m.group(2))
        if not os.path.isfile(dest):
            rc, out = run(["/usr/lib/apt/apt-helper"] + opts + ["download-file", m.group(1), dest, m.group(3)])
            if rc != 0:
                tried.append(f"{v}: {out.strip().splitlines()[-1] if out.strip() else 'download failed'}")
                continue
        unpack = os.path.join(cache, f"debian-{v}")
        shutil.rmtree(unpack, ignore_errors=True)
        os.makedirs(unpack)
        if subprocess.run(["tar", "-xJf", dest, "-C", unpack, "debian/patches-rt"]).returncode != 0:
            tried.append(f"{v}: no debian/patches-rt in {m.group(2)}")
            continue
        return os.path.join(unpack, "debian", "patches-rt"), v
    return None, ("no Debian PREEMPT_RT patch set could be fetched: " + "; ".join(tried[:3])
                  + (f" (and {len(tried) - 3} more)" if len(tried) > 3 else ""))


def rt_tree(cache, plain, deb_version, use_patches):
    """A copy of the plain tree with Debian's patches-rt applied: hard links, which GNU patch
    replaces rather than edits, so the plain tree stays as it is. Returns (tree, note) or
    (None, reason)."""
    dest = os.path.join(cache, "src-rt")
    stamp = os.path.join(cache, "src-rt.patched")
    origin = open(os.path.join(cache, "src", ".ccomm-extracted")).read()
    if not use_patches:
        return None, "--no-rt-patches given"
    if os.path.isfile(stamp) and os.path.isdir(dest):
        key, _, note = open(stamp).read().partition("\n")
        if key + "\n" == origin:
            return tree_dir(dest), note.strip()
    series_dir, used = fetch_rt_patches(cache, deb_version)
    if series_dir is None:
        return None, used
    shutil.rmtree(dest, ignore_errors=True)
    os.makedirs(dest)
    if subprocess.run(["cp", "-al", plain, dest]).returncode != 0:
        die(f"cannot copy {plain} to {dest}")
    tree = tree_dir(dest)
    say(f"kernel-check: applying Debian {used} debian/patches-rt to the {deb_version} tree")
    rejects = []
    with open(os.path.join(series_dir, "series")) as f:
        patches = [l.strip() for l in f if l.strip() and not l.startswith("#")]
    for p in patches:
        rc, out = run(["patch", "-p1", "-N", "-s", "--no-backup-if-mismatch", "-i",
                       os.path.join(series_dir, p)], cwd=tree)
        if rc != 0:
            files = sorted(set(re.findall(r"saving rejects to file (\S+?)\.rej", out)))
            rejects.append((p, files))
    kconfig_rejects = [r for r in rejects if any(re.search(r"(^|/)Kconfig", x) for x in r[1])]
    if kconfig_rejects:
        shutil.rmtree(dest, ignore_errors=True)
        return None, ("Debian's patches-rt " + used + " does not apply to the Kconfig files of this tree: "
                      + "; ".join(f"{p} ({', '.join(fs)})" for p, fs in kconfig_rejects))
    note = f"PREEMPT_RT patches: Debian linux {used} debian/patches-rt ({len(patches)} patches)"
    if used != deb_version:
        note += f", not {deb_version} (apt could not fetch that one)"
    if rejects:
        note += ("; rejected hunks outside Kconfig, which do not change the configuration: "
                 + "; ".join(f"{p} ({', '.join(fs) or 'already applied'})" for p, fs in rejects))
    with open(stamp, "w") as f:
        f.write(origin + note + "\n")
    return tree, note
