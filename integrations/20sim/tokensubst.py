#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Offline 20-sim C-code generation: fills a target's template files from a tokens file.

20-sim generates code by replacing %TOKEN% keywords in the template files a Targets.ini
section lists, with %IF%%COND% ... %ELSE% ... %ENDIF% blocks. It also writes every token
of the model to an XML file (the %TOKENS% keyword, e.g. <submodel>_tokens.xml). This
script repeats that replacement without 20-sim, so that:
  - CI can build and run a target's output for a model given as a tokens file, and
  - code can be regenerated for a changed target from a tokens file 20-sim wrote once.

    tokensubst.py --targets Targets.ini --target ccomm --tokens PD_tokens.xml --out DIR

Supported: %NAME% for every token in the tokens file and every %NAME%=value line of the
target section; %IF%%COND%, %ELSE%, %ENDIF% (nested), with COND as 20-sim's templates
write it: NAME, a number, NOT(C), AND(C,C,...), OR(C,C,...), EQ(A,B), NEQ(A,B) (also NE),
nested (NOT(EQ(INTEGRATION_METHOD_NAME,MeBDFi))). EQ/NEQ compare the values of A and B,
where an argument that is not a token is its own text (EQ(FMIVERSION,2.0)); numbers
compare as numbers. A COND is true when its value is a non-zero number or a non-empty
string other than XXFALSE/FALSE; a token the model does not define is false (templates
test %IF%%FMI1% in targets that never define FMI1). The newline right after
%IF%%COND%, %ELSE% and %ENDIF% is dropped, as 20-sim does.
"""
from __future__ import annotations

import argparse
import os
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

TOKEN_RE = re.compile(r"%([A-Z0-9_]+)%")
# Tokens the equations were generated with: the tokens file must win over the target's
# defaults, or the frame would name arrays differently from the equations.
EQUATION_NAMING = {
    "VARPREFIX", "FUNCTIONPREFIX", "XX_TIME", "XX_INITIALIZE",
} | {n for n in (
    "XX_VARIABLE_ARRAY_NAME XX_PARAMETER_ARRAY_NAME XX_INITIAL_VALUE_ARRAY_NAME "
    "XX_CONSTANT_ARRAY_NAME XX_STATE_ARRAY_NAME XX_RATE_ARRAY_NAME XX_DEP_STATE_ARRAY_NAME "
    "XX_DEP_RATE_ARRAY_NAME XX_ALG_IN_ARRAY_NAME XX_ALG_OUT_ARRAY_NAME XX_EXT_IN_ARRAY_NAME "
    "XX_EXT_OUT_ARRAY_NAME XX_MATRIX_ARRAY_NAME XX_UNNAMED_ARRAY_NAME "
    "XX_FAVORITE_PARS_ARRAY_NAME XX_FAVORITE_VARS_ARRAY_NAME").split()}

# 20-sim's defaults for tokens a tokens file may lack.
DEFAULTS = {
    "VARPREFIX": "xx_", "FUNCTIONPREFIX": "XX", "XX_TIME": "time",
    "XX_INITIALIZE": "initialize", "XX_VARIABLE_ARRAY_NAME": "V",
    "XX_PARAMETER_ARRAY_NAME": "P", "XX_INITIAL_VALUE_ARRAY_NAME": "I",
    "XX_CONSTANT_ARRAY_NAME": "C", "XX_STATE_ARRAY_NAME": "s", "XX_RATE_ARRAY_NAME": "R",
    "XX_DEP_STATE_ARRAY_NAME": "S", "XX_DEP_RATE_ARRAY_NAME": "r",
    "XX_ALG_IN_ARRAY_NAME": "A", "XX_ALG_OUT_ARRAY_NAME": "a", "XX_EXT_IN_ARRAY_NAME": "E",
    "XX_EXT_OUT_ARRAY_NAME": "e", "XX_MATRIX_ARRAY_NAME": "M", "XX_UNNAMED_ARRAY_NAME": "U",
    "XX_FAVORITE_PARS_ARRAY_NAME": "F", "XX_FAVORITE_VARS_ARRAY_NAME": "f",
}


class TemplateError(Exception):
    pass


def read_targets(path: Path, target: str) -> dict:
    """Returns the section of `target`: template dir, files, tokens, newline choice."""
    section = None
    found = False
    files: list[str] = []
    tokens: dict[str, str] = {}
    info: dict[str, str] = {}
    for raw in path.read_text(encoding="utf-8", errors="replace").splitlines():
        line = raw.strip()
        if not line or line.startswith(";"):
            continue
        m = re.fullmatch(r"\[(.+)\]", line)
        if m:
            section = m.group(1).strip()
            found = found or section == target
            continue
        if section != target or "=" not in line:
            continue
        key, value = line.split("=", 1)
        key, value = key.strip(), value.strip().strip('"')
        if key == "templateFiles":
            files += [f.strip().strip('"') for f in value.split(";") if f.strip()]
        elif key.startswith("%") and key.endswith("%") and len(key) > 2:
            tokens[key[1:-1]] = value
        else:
            info[key] = value
    if not found:
        raise TemplateError(f"{path}: no section [{target}]")
    tdir = info.get("templateDirectory", target).replace("\\", "/")
    return {
        "dir": (path.parent / tdir).resolve(),
        "files": files,
        "tokens": tokens,
        "newline": {"0": "\r\n", "1": "\r", "2": "\n"}.get(info.get("newLineCharacter", "0"), "\r\n"),
        "methods": [m for m in info.get("integrationMethods", "").split(";") if m],
    }


def read_tokens(path: Path) -> dict[str, str]:
    root = ET.parse(path).getroot()
    if root.tag != "tokens":
        raise TemplateError(f"{path}: root element is <{root.tag}>, expected <tokens>")
    out = {}
    for t in root.iter("token"):
        name = t.get("name")
        if name:
            out[name] = t.text or ""
    return out


def truthy(value: str) -> bool:
    v = value.strip()
    if not v or v.upper() in ("XXFALSE", "FALSE"):
        return False
    try:
        return float(v) != 0.0
    except ValueError:
        return True


def split_args(text: str, where: str) -> list[str]:
    """Splits "A, EQ(B,C)" at the top-level commas."""
    args, depth, cur = [], 0, []
    for ch in text:
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
            if depth < 0:
                raise TemplateError(f"{where}: unbalanced ')' in %IF% condition")
        if ch == "," and depth == 0:
            args.append("".join(cur).strip())
            cur = []
        else:
            cur.append(ch)
    if depth != 0:
        raise TemplateError(f"{where}: unbalanced '(' in %IF% condition")
    args.append("".join(cur).strip())
    return args


def operand(arg: str, tokens: dict[str, str]) -> str:
    """An EQ/NEQ argument: a token's value, else the text itself."""
    return tokens[arg].strip() if arg in tokens else arg


def same_value(a: str, b: str) -> bool:
    try:
        return float(a) == float(b)
    except ValueError:
        return a == b


FUNC_RE = re.compile(r"([A-Z]+)\((.*)\)", re.S)
ARITY = {"NOT": (1, 1), "AND": (2, 99), "OR": (2, 99), "EQ": (2, 2), "NEQ": (2, 2), "NE": (2, 2)}


def eval_cond(cond: str, tokens: dict[str, str], where: str = "template") -> bool:
    cond = cond.strip()
    m = FUNC_RE.fullmatch(cond)
    if m and m.group(1) in ARITY:
        name = m.group(1)
        args = split_args(m.group(2), where)
        lo, hi = ARITY[name]
        if not lo <= len(args) <= hi or any(not a for a in args):
            raise TemplateError(f"{where}: %IF%%{cond}%: {name} takes "
                                f"{lo if lo == hi else f'{lo} or more'} argument(s)")
        if name in ("EQ", "NEQ", "NE"):
            equal = same_value(operand(args[0], tokens), operand(args[1], tokens))
            return equal if name == "EQ" else not equal
        vals = [eval_cond(a, tokens, where) for a in args]
        if name == "NOT":
            return not vals[0]
        return all(vals) if name == "AND" else any(vals)
    if m:
        raise TemplateError(f"{where}: %IF%%{cond}%: unknown function {m.group(1)} "
                            f"(known: {', '.join(sorted(ARITY))})")
    if re.fullmatch(r"-?[0-9.]+", cond):
        return truthy(cond)
    if "(" in cond or ")" in cond:
        raise TemplateError(f"{where}: %IF%%{cond}%: unbalanced parentheses")
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", cond):
        raise TemplateError(f"{where}: %IF%%{cond}%: not a token name, number or function")
    return truthy(tokens.get(cond, ""))


# %IF%%COND%: COND is anything up to the next '%' (20-sim's conditions hold no '%').
COND_RE = re.compile(r"%IF%%([^%\n]+)%\n?|%ELSE%\n?|%ENDIF%\n?")


def expand_conditionals(text: str, tokens: dict[str, str], where: str) -> str:
    out: list[str] = []
    stack: list[tuple[bool, bool]] = []  # (parent active, this branch active)
    active = True
    pos = 0
    for m in COND_RE.finditer(text):
        if active:
            out.append(text[pos:m.start()])
        pos = m.end()
        tag = m.group(0).rstrip("\n")
        line = text.count("\n", 0, m.start()) + 1
        if tag.startswith("%IF%"):
            branch = active and eval_cond(m.group(1), tokens, f"{where}:{line}")
            stack.append((active, branch))
            active = branch
        elif tag == "%ELSE%":
            if not stack:
                raise TemplateError(f"{where}:{line}: %ELSE% without %IF%")
            parent, branch = stack[-1]
            stack[-1] = (parent, parent and not branch)
            active = parent and not branch
        else:
            if not stack:
                raise TemplateError(f"{where}:{line}: %ENDIF% without %IF%")
            active = stack.pop()[0]
    if stack:
        raise TemplateError(f"{where}: {len(stack)} %IF% without %ENDIF% at the end of the file")
    if active:
        out.append(text[pos:])
    return "".join(out)


def substitute(text: str, tokens: dict[str, str], where: str, unknown: set[str]) -> str:
    text = expand_conditionals(text, tokens, where)

    def repl(m: re.Match[str]) -> str:
        name = m.group(1)
        if name in tokens:
            return tokens[name]
        unknown.add(name)
        return m.group(0)

    return TOKEN_RE.sub(repl, text)


def generate(targets: Path, target: str, tokens_file: Path, out_dir: Path,
             list_only: bool = False) -> list[Path]:
    sect = read_targets(targets, target)
    model = read_tokens(tokens_file)
    tokens = dict(DEFAULTS)
    tokens.update(model)
    for k, v in sect["tokens"].items():
        if k in EQUATION_NAMING and k in model and model[k] != v:
            print(f"note: keeping {k}={model[k]!r} from {tokens_file.name} (the equations use it); "
                  f"the target asks for {v!r}", file=sys.stderr)
            continue
        tokens[k] = v
    method = tokens.get("INTEGRATION_METHOD_NAME", "")
    if sect["methods"] and method not in sect["methods"]:
        raise TemplateError(f"integration method {method!r} is not supported by target {target} "
                            f"(supported: {', '.join(sect['methods'])})")
    tokens.setdefault("GENERATION_DIR", str(out_dir))
    written = []
    for rel in sect["files"]:
        rel_out = TOKEN_RE.sub(lambda m: tokens.get(m.group(1), m.group(0)), rel.replace("\\", "/"))
        dst = out_dir / rel_out
        written.append(dst)
        if list_only:
            continue
        src = sect["dir"] / rel.replace("\\", "/")
        text = src.read_text(encoding="utf-8").replace("\r\n", "\n")
        unknown: set[str] = set()
        tokens["FILE_NAME"] = rel_out
        result = substitute(text, tokens, str(src), unknown)
        if unknown:
            print(f"warning: {src.name}: unknown tokens left as is: {', '.join(sorted(unknown))}",
                  file=sys.stderr)
        dst.parent.mkdir(parents=True, exist_ok=True)
        data = result.replace("\n", sect["newline"]).encode("utf-8")
        # Only rewrite changed files, so builds depending on them stay up to date cheaply.
        if not dst.exists() or dst.read_bytes() != data:
            dst.write_bytes(data)
    return written


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--targets", required=True, type=Path, help="the Targets.ini file")
    ap.add_argument("--target", required=True, help="section name in Targets.ini")
    ap.add_argument("--tokens", required=True, type=Path, help="tokens XML file of the model")
    ap.add_argument("--out", required=True, type=Path, help="output directory")
    ap.add_argument("--list", action="store_true", help="only print the files it would write")
    a = ap.parse_args(argv)
    try:
        files = generate(a.targets, a.target, a.tokens, a.out, a.list)
    except (TemplateError, ET.ParseError, OSError) as e:
        print(f"tokensubst: {e}", file=sys.stderr)
        return 1
    for f in files:
        print(os.fspath(f))
    return 0


if __name__ == "__main__":
    sys.exit(main())
