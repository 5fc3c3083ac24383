#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""20-sim step-order test: the ccomm C-code target against 20-sim's documented step order.

For each integration method (Discrete, Euler, RungeKutta2, RungeKutta4) this generates the
StepOrder model (a PID with a derivative kick, two states and a gain matrix, see
example/StepOrder*_tokens.xml) through the ccomm target exactly as 20-sim would fill it
(tokensubst.py), compiles the generated code with -Werror, runs it off-line on a fixed
input sequence (step_trace.c) and compares every output of every sample with a reference
written here from 20-sim's documentation, not from the target's code:

  initialize  x = x0; static equations; rates, variables = dynamic(x, u0, t0);
              outputs of sample 0
  each step   inputs u_k; static and input equations; integration step from t to t + h
              whose first rate k1 is the one the dynamic equations left at the end of the
              previous step (20-sim does not re-evaluate them when the inputs change), and
              which ends with dynamic(x(t + h), u_k, t + h); output equations; outputs.

It also checks that the comparison can fail: the order the target used before (dynamic
equations evaluated with u_k before the step) differs from the reference, by a lost
first-sample derivative kick for Discrete and a one-sample-early integration otherwise.

  step_order.py --work DIR [--cc CC] [--ccomm-include DIR --ccomm-lib DIR]

With --ccomm-include/--ccomm-lib the complete generated task (ccomm_map.c, ccomm_main.c) is
also compiled and linked against libccomm, so the matrix model builds as users build it.
Exit 0 if every check passes.
"""
from __future__ import annotations

import argparse
import math
import os
import re
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
TWENTYSIM = HERE.parent
H = 0.01                 # TIME_STEP_SIZE of both tokens files
SAMPLES = 60
STEP_AT = 5              # r steps from 0 to 1 at this sample: the derivative kick
TOLERANCE = 1e-12        # relative; the target and the reference round alike
METHODS = ["Discrete", "Euler", "RungeKutta2", "RungeKutta4"]

KP, KI, KD, TAU = 2.0, 1.5, 0.3, 0.02
K = [[1.0, 0.5], [-0.25, 2.0]]


def inputs() -> list[tuple[float, float, float]]:
    """r (a step at STEP_AT), y[1], y[2]: deterministic, printed with repr (exact)."""
    return [(1.0 if k >= STEP_AT else 0.0, 0.3 * math.sin(0.2 * k), 0.5 * math.cos(0.15 * k))
            for k in range(SAMPLES)]


# ---------------------------------------------------------------- the model, from its text

def dynamic(discrete: bool, x: list[float], u: tuple[float, float, float], t: float, h: float):
    """Returns (rates or next states, outputs u[1], u[2]) for states x = [I, xf or e_prev]."""
    r, y1, y2 = u
    inv = 1.0 / h if discrete else 1.0 / TAU
    e = r - y1
    d = KD * (e - x[1]) * inv
    ff = 0.1 * math.sin(2.0 * t)
    w = (((KP * e + KI * x[0]) + d) + ff, y2)
    out = [0.0 + K[i][0] * w[0] + K[i][1] * w[1] for i in range(2)]
    if discrete:
        rates = [x[0] + h * e, e]
    else:
        rates = [e, (e - x[1]) * inv]
    return rates, out


def reference(method: str, seq, early_dynamic: bool = False) -> list[list[float]]:
    """Outputs per sample in 20-sim's order (or, early_dynamic, the old wrong order)."""
    discrete = method == "Discrete"
    x = [0.0, 0.0]
    rates, out = dynamic(discrete, x, seq[0], 0.0, H)
    trace = [out + [x[0]]]
    for k in range(1, len(seq)):
        u, t = seq[k], (k - 1) * H
        f = lambda xs, tt: dynamic(discrete, xs, u, tt, H)[0]  # noqa: E731 (stage rates)
        if early_dynamic:
            rates = f(x, t)
        k1 = rates
        if method == "Discrete":
            x = list(k1)
        elif method == "Euler":
            x = [x[i] + H * k1[i] for i in range(2)]
        elif method == "RungeKutta2":
            mid = [x[i] + (H / 2) * k1[i] for i in range(2)]
            k2 = f(mid, t + H / 2)
            x = [x[i] + H * k2[i] for i in range(2)]
        else:  # RungeKutta4, increments q = h f
            q1 = [H * v for v in k1]
            q2 = [H * v for v in f([x[i] + q1[i] / 2 for i in range(2)], t + H / 2)]
            q3 = [H * v for v in f([x[i] + q2[i] / 2 for i in range(2)], t + H / 2)]
            q4 = [H * v for v in f([x[i] + q3[i] for i in range(2)], t + H)]
            x = [x[i] + (q1[i] + 2 * q2[i] + 2 * q3[i] + q4[i]) / 6 for i in range(2)]
        rates, out = dynamic(discrete, x, u, t + H, H)
        trace.append(out + [x[0]])
    return trace


# ---------------------------------------------------------------- the target

def run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        lines = (p.stdout + p.stderr).splitlines()
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}\n" + "\n".join(lines[:40]))
    return p


def generate(method: str, work: Path) -> Path:
    name = "StepOrderDiscrete" if method == "Discrete" else "StepOrder"
    text = (TWENTYSIM / "example" / f"{name}_tokens.xml").read_text(encoding="utf-8")
    text, n = re.subn(r'(name="INTEGRATION_METHOD_NAME"><!\[CDATA\[)[A-Za-z0-9]+', rf"\g<1>{method}", text)
    assert n == 1
    tokens = work / f"{method}_tokens.xml"
    tokens.write_text(text, encoding="utf-8")
    out = work / f"gen_{method}"
    run([sys.executable, str(TWENTYSIM / "tokensubst.py"), "--targets",
         str(TWENTYSIM / "ccode-target" / "Targets.ini"), "--target", "ccomm",
         "--tokens", str(tokens), "--out", str(out)])
    return out


CFLAGS = ["-std=c11", "-O2", "-Wall", "-Wextra", "-Wshadow", "-Werror"]
MODEL_C = ["xxfuncs.c", "xxinteg.c", "xxmatrix.c", "xxmodel.c", "xxsubmod.c"]


def build_trace(cc: str, gen: Path) -> Path:
    exe = gen / "step_trace"
    run([cc, *CFLAGS, "-I", str(gen), "-o", str(exe), str(HERE / "step_trace.c"),
         *[str(gen / f) for f in MODEL_C], "-lm"])
    return exe


def build_task(cc: str, gen: Path, include: str, lib: str) -> None:
    run([cc, *CFLAGS, "-I", str(gen), "-I", include, "-o", str(gen / "task"),
         *[str(gen / f) for f in MODEL_C + ["ccomm_ports.c", "ccomm_map.c", "ccomm_main.c"]],
         "-L", lib, "-lccomm", "-lm"])


def compare(method: str, got: list[list[float]], want: list[list[float]]) -> tuple[bool, float]:
    worst, ok = 0.0, len(got) == len(want)
    if not ok:
        print(f"FAIL {method}: {len(got)} samples from the target, {len(want)} expected")
    for k, (g, w) in enumerate(zip(got, want)):
        for j, (a, b) in enumerate(zip(g, w)):
            err = abs(a - b) / max(1.0, abs(b))
            worst = max(worst, err)
            if not err <= TOLERANCE and ok:
                print(f"FAIL {method}: sample {k} output {j}: target {a!r}, 20-sim order {b!r}")
                ok = False
    return ok, worst


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--work", required=True, type=Path, help="scratch directory")
    ap.add_argument("--cc", default=os.environ.get("CC", "cc"))
    ap.add_argument("--ccomm-include", help="directory with ccomm/ccomm.h (also build the task)")
    ap.add_argument("--ccomm-lib", help="directory with libccomm.so")
    a = ap.parse_args()
    a.work.mkdir(parents=True, exist_ok=True)
    seq = inputs()
    feed = "".join(" ".join(repr(v) for v in u) + "\n" for u in seq)
    failures = 0
    for method in METHODS:
        try:
            gen = generate(method, a.work)
            exe = build_trace(a.cc, gen)
            if a.ccomm_include and a.ccomm_lib:
                build_task(a.cc, gen, a.ccomm_include, a.ccomm_lib)
            lines = run([str(exe)], input=feed).stdout.split("\n")
        except RuntimeError as e:
            print(f"FAIL {method}: {e}")
            failures += 1
            continue
        got = [[float(v) for v in line.split()] for line in lines if line.strip()]
        want = reference(method, seq)
        ok, worst = compare(method, got, want)
        old = reference(method, seq, early_dynamic=True)
        shift = max((abs(g - o) / max(1.0, abs(o)) for gs, os_ in zip(got, old) for g, o in zip(gs, os_)),
                    default=0.0)
        kick = (got[STEP_AT][0] - got[STEP_AT - 1][0]) if len(got) > STEP_AT else float("nan")
        kick_ref = want[STEP_AT][0] - want[STEP_AT - 1][0]
        kick_old = old[STEP_AT][0] - old[STEP_AT - 1][0]
        sensitive = shift > 1e-3
        if ok and sensitive:
            print(f"PASS {method}: {len(got)} samples x 3 outputs equal 20-sim's order "
                  f"(max relative difference {worst:.1e}); first-sample kick in u[1] {kick:+.6f} "
                  f"(old order: {kick_old:+.6f}); old order differs by up to {shift:.3g}")
        else:
            if ok:
                print(f"FAIL {method}: the old step order gives the same sequence (max difference "
                      f"{shift:.1e}): the test would not see the one-sample shift")
            print(f"     kick in u[1]: target {kick:+.6f}, 20-sim order {kick_ref:+.6f}, old order {kick_old:+.6f}")
            failures += 1
    print(f"step order: {len(METHODS) - failures} of {len(METHODS)} methods match 20-sim's documented order")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
