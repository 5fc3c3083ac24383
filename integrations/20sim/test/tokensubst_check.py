#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Checks tokensubst.py's %IF% language on the conditions 20-sim's own templates use
(EQ/NEQ on token values, nested NOT/OR/AND, numbers, tokens a target never defines) and
that malformed conditions are refused with FILE:LINE; fuzzes the condition parser
(CCOMM_FUZZ_SEED). Exit 0 if every check passes."""
import os
import random
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import tokensubst as ts  # noqa: E402

TOKENS = {"INTEGRATION_METHOD_NAME": "RungeKutta4", "FMIVERSION": "2.0", "NUMBER_STATES": "2",
          "NUMBER_MATRICES": "0", "MODEL_IS_DISCRETE": "XXFALSE", "FMI2": "fmi2"}
CASES = [  # (condition, expected)
    ("EQ(INTEGRATION_METHOD_NAME,RungeKutta4)", True),
    ("EQ(INTEGRATION_METHOD_NAME,Euler)", False),
    ("NEQ(INTEGRATION_METHOD_NAME,MeBDFi)", True),
    ("NOT(EQ(INTEGRATION_METHOD_NAME,MeBDFi))", True),
    ("EQ(FMIVERSION,2.0)", True), ("EQ(FMIVERSION,2)", True), ("EQ(FMIVERSION,1.0)", False),
    ("OR(FMI1,FMI2)", True), ("AND(FMI1,FMI2)", False), ("FMI1", False),
    ("OR(NUMBER_MATRICES, NUMBER_STATES)", True), ("NUMBER_MATRICES", False),
    ("MODEL_IS_DISCRETE", False), ("0", False), ("1", True),
    ("NOT(OR(EQ(INTEGRATION_METHOD_NAME,Discrete),EQ(INTEGRATION_METHOD_NAME,RungeKutta4)))", False),
]
BAD = [("EQ(NUMBER_STATES)", "t.c:2: %IF%%EQ(NUMBER_STATES)%: EQ takes 2 argument(s)"),
       ("FOO(NUMBER_STATES)", "t.c:2: %IF%%FOO(NUMBER_STATES)%: unknown function FOO"),
       ("NOT(A", "t.c:2: %IF%%NOT(A%: unbalanced parentheses"),
       ("EQ(A,B))", "t.c:2: unbalanced ')' in %IF% condition")]

failures = 0
for cond, want in CASES:
    got = ts.substitute(f"%IF%%{cond}%\nyes\n%ELSE%\nno\n%ENDIF%\n", TOKENS, "t.c", set()) == "yes\n"
    if got != want:
        print(f"FAIL %IF%%{cond}%: {got}, expected {want}")
        failures += 1
for cond, msg in BAD:
    try:
        ts.substitute(f"first line\n%IF%%{cond}%\nx\n%ENDIF%\n", TOKENS, "t.c", set())
        print(f"FAIL %IF%%{cond}% accepted")
        failures += 1
    except ts.TemplateError as e:
        if not str(e).startswith(msg):
            print(f"FAIL %IF%%{cond}%: error {e!r}, expected {msg!r}")
            failures += 1
nested = ts.substitute("%IF%%NUMBER_STATES%\na\n%IF%%FMI1%\nb\n%ELSE%\nc\n%ENDIF%\n%ENDIF%\n", TOKENS, "t.c", set())
if nested != "a\nc\n":
    print(f"FAIL nested %IF%/%ELSE%: {nested!r}")
    failures += 1
# Fuzz the condition parser: random conditions and %IF%/%ELSE%/%ENDIF% soup must give
# text or a TemplateError with FILE:LINE, never another exception.
rnd = random.Random(int(os.environ.get("CCOMM_FUZZ_SEED", "1")))
alphabet = ["EQ(", "NEQ(", "NOT(", "AND(", "OR(", "(", ")", ",", " ", "NUMBER_STATES", "FMI1", "2.0",
            "%IF%%", "%ELSE%", "%ENDIF%", "%", "\n", "x", "-1", "INTEGRATION_METHOD_NAME"]
for k in range(2000):
    text = "%IF%%" + "".join(rnd.choice(alphabet) for _ in range(rnd.randint(1, 12))) + "%\nbody\n%ENDIF%\n"
    try:
        ts.substitute(text, TOKENS, "f.c", set())
    except ts.TemplateError as e:
        if not str(e).startswith("f.c"):
            print(f"FAIL fuzz case {k}: error without FILE:LINE: {e}")
            failures += 1
    except Exception as e:  # noqa: BLE001 (the point of the fuzz run)
        print(f"FAIL fuzz case {k}: {type(e).__name__}: {e} for {text!r}")
        failures += 1
        break

print(f"{'PASS' if not failures else 'FAIL'} template language: {len(CASES) + len(BAD) + 1} checks and 2000 fuzzed conditions, "
      f"{failures} failed")
sys.exit(1 if failures else 0)
