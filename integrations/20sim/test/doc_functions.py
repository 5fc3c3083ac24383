#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The 20-sim target's function list in docs/integrations/20sim.md against the code.

A user reads that list to know whether a model will build. It must name exactly what
xxfuncs.c and xxmatrix.c define (compiled here, read with nm: what a model links
against), and every 20-sim function known to need a helper the target lacks must be
under "Known not implemented", so a model that uses one is no surprise.

Usage: doc_functions.py [--cc CC]   (prints PASS/FAIL lines; exit 1 on a mismatch)
"""
import argparse
import pathlib
import re
import subprocess
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
TARGET = HERE.parent / "ccode-target" / "ccomm"
DOC = HERE.parents[2] / "docs" / "integrations" / "20sim.md"

# 20-sim function name -> the helper 20-sim's C code generator calls for it.
SCALAR = {
    "abs": "XXAbsolute", "arccosh": "XXArcCosineHyperbolic",
    "arcsinh": "XXArcSineHyperbolic", "arctanh": "XXArcTangentHyperbolic",
    "exp2": "XXExponent2", "exp10": "XXExponent10", "div": "XXIntegerDivide",
    "mod": "XXIntegerModulo", "log2": "XXLogarithm2", "log10": "XXLogarithm10",
    "pow2": "XXPow2", "power": "XXPower", "round": "XXRound", "sign": "XXSign",
    "xor": "XXXor", "random": "XXRandom",
    "bitand": "XXBitAnd", "bitor": "XXBitOr", "bitxor": "XXBitXor", "bitcmp": "XXBitCmp",
    "bitget": "XXBitGet", "bitinv": "XXBitInv", "bitset": "XXBitSet",
    "bitclear": "XXBitClear", "bitshift": "XXBitShift",
    "bitshiftright": "XXBitShiftRight", "swapbytes": "XXSwapBytes",
    "step": "XXStep", "ramp": "XXRamp", "impulse": "XXImpulse", "realtime": "XXRealTime",
}
MATRIX = {
    "diag": "XXMatrixDiag", "eye": "XXMatrixEye", "transpose": "XXMatrixTranspose",
    "inverse": "XXMatrixInverse", "determinant": "XXMatrixDeterminant",
    "linsolve": "XXLinearSolve", "msum": "XXMatrixSum", "mmin": "XXMatrixMinimum",
    "mmax": "XXMatrixMaximum", "trace": "XXMatrixTrace", "norm": "XXMatrixNorm",
    "norminf": "XXMatrixNormInf", "inner": "XXMatrixInnerProduct",
    "cross": "XXMatrixCrossProduct", "skew": "XXMatrixSkew",
}
# 20-sim functions whose generated code calls a helper this target does not have
# (20-sim's language reference; the list the docs once missed: tdelay, the event
# functions, stopsimulation, warning, motion profiles, six matrix functions).
KNOWN_MISSING = [
    "tdelay", "event", "eventup", "eventdown", "timeevent", "frequencyevent",
    "stopsimulation", "warning", "motionprofile", "adjoint", "antisym", "sym",
    "homogeneous", "inverseH", "tilde", "data", "table", "dll", "dlldynamic",
    "doMatlab", "toMatlab", "fromMatlab",
]

failures = 0


def check(ok, what, detail=""):
    global failures
    print(("PASS " if ok else "FAIL ") + what + ("" if ok else ": " + detail))
    failures += 0 if ok else 1


def doc_lists(text):
    """(rows of the Implemented table by group, names under Known not implemented)."""
    rows = {}
    for m in re.finditer(r"^\| *([a-z]+) *\| *([^|]+)\|$", text, re.M):
        rows[m.group(1)] = [n.strip() for n in m.group(2).split(",") if n.strip()]
    start = text.find("Known **not** implemented")
    end = text.find("\n\n", start)
    if start < 0:
        return rows, []
    paragraph = text[start:end]
    return rows, re.findall(r"`([A-Za-z]+)(?:\(\))?`", paragraph)


def defined_helpers(cc, source, work):
    obj = work / (source.stem + ".o")
    subprocess.run([cc, "-std=c11", "-c", "-I", str(TARGET), "-o", str(obj), str(source)],
                   check=True)
    out = subprocess.run(["nm", "--defined-only", str(obj)], check=True,
                         capture_output=True, text=True).stdout
    return {line.split()[2] for line in out.splitlines()
            if len(line.split()) == 3 and line.split()[1] == "T"
            and line.split()[2].startswith("XX")}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cc", default="cc")
    args = ap.parse_args()
    rows, missing = doc_lists(DOC.read_text())
    with tempfile.TemporaryDirectory() as tmp:
        funcs = defined_helpers(args.cc, TARGET / "xxfuncs.c", pathlib.Path(tmp))
        matrix = defined_helpers(args.cc, TARGET / "xxmatrix.c", pathlib.Path(tmp))

    documented = set(rows.get("arithmetic", []) + rows.get("bitwise", []) + rows.get("sources", []))
    check(documented == set(SCALAR), "the docs' scalar functions are the ones the target maps",
          f"only in the docs {sorted(documented - set(SCALAR))}, "
          f"not in the docs {sorted(set(SCALAR) - documented)}")
    check(set(SCALAR.values()) == funcs, "xxfuncs.c defines exactly their helpers",
          f"documented but not defined {sorted(set(SCALAR.values()) - funcs)}, "
          f"defined but not documented {sorted(funcs - set(SCALAR.values()))}")
    listed = set(rows.get("matrices", []))
    absent = sorted(n for n in MATRIX if n not in listed)
    undefined = sorted(h for h in MATRIX.values() if h not in matrix)
    check(not absent and not undefined, "the docs' matrix functions are defined in xxmatrix.c",
          f"not in the docs {absent}, not defined {undefined}")
    unlisted = [n for n in KNOWN_MISSING if n not in missing]
    check(not unlisted, f"\"Known not implemented\" names all {len(KNOWN_MISSING)} functions "
          "the target lacks", f"missing from the docs: {unlisted}")
    both = sorted(set(missing) & (documented | listed))
    check(not both, "no function is both implemented and not implemented", str(both))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
