# SPDX-License-Identifier: Apache-2.0
"""Compares a ccomm-fmu run with FMPy's simulation of the same FMU.

  compare.py FMU RECORD.csv OUTPUT[,OUTPUT...] [--received planner.json]

RECORD.csv is ccomm-fmu --record: per cycle the inputs, parameters and outputs the FMU
was given / gave. FMPy's simulate_fmu (co-simulation, step = the period, the FMU's XSD
validation on) gets the same input sequence, each value held over its step; its output
after step k must equal ccomm-fmu's output of cycle k bit for bit. With --received, the
values that reached the other node (planner.py) must be the recorded outputs in order
(a subsequence: ccommd may coalesce values under load, never reorder or change them).
Exit status 0 if all equal; prints one line per output.
"""
import csv
import json
import sys

import numpy as np
from fmpy import read_model_description, simulate_fmu


def load_record(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    header, data = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
    return header, data


def columns_of(header, name):
    """Indexes of variable `name` in the record: "name" or "name[0]", "name[1]"..."""
    return [i for i, h in enumerate(header) if h == name or h.startswith(name + "[")]


def main(argv):
    fmu, record_path, outputs = argv[1], argv[2], argv[3].split(",")
    received_path = argv[5] if len(argv) > 5 and argv[4] == "--received" else None
    header, data = load_record(record_path)
    n = data.shape[0]
    md = read_model_description(fmu, validate=True)
    period = float(md.defaultExperiment.stepSize)
    given = [v for v in md.modelVariables
             if (v.causality == "input" or v.variability == "tunable") and columns_of(header, v.name)]
    # The input table as FMPy wants it: at every t_k the value before and the value after,
    # so each value is held over its step (no interpolation between samples).
    dtype = []
    for v in given:
        cols = columns_of(header, v.name)
        base = {"Real": np.float64, "Float64": np.float64, "Float32": np.float32, "Integer": np.int32,
                "Int32": np.int32, "UInt32": np.uint32, "Int64": np.int64, "Boolean": np.bool_}[v.type]
        dtype.append((v.name, base, (len(cols),)) if len(cols) > 1 else (v.name, base))
    rows = 2 * n - 1
    signals = np.zeros(rows, dtype=[("time", np.float64)] + dtype)
    for k in range(n):
        for j, r in ([(0, 0)] if k == 0 else [(2 * k - 1, k - 1), (2 * k, k)]):
            signals["time"][j] = k * period
            for v in given:
                cols = columns_of(header, v.name)
                signals[v.name][j] = data[r, cols] if len(cols) > 1 else data[r, cols[0]]
    result = simulate_fmu(fmu, validate=True, fmi_type="CoSimulation", start_time=0.0, stop_time=n * period,
                          output_interval=period, input=signals, output=outputs)
    failed = 0
    if len(result) != n + 1:
        print(f"FMPy returned {len(result)} rows, expected {n + 1}")
        return 1
    for name in outputs:
        cols = columns_of(header, name)
        mine = data[:, cols]
        theirs = np.asarray(result[name][1:], dtype=np.float64).reshape(n, len(cols))
        differ = np.nonzero(np.any(mine != theirs, axis=1))[0]
        if len(differ):
            k = differ[0]
            print(f"{name}: {len(differ)} of {n} samples differ; first at cycle {k}: ccomm-fmu {mine[k].tolist()} FMPy {theirs[k].tolist()}")
            failed += 1
        else:
            print(f"{name}: {n} samples equal FMPy's, bit for bit (range {mine.min():.6g} .. {mine.max():.6g})")
    if received_path:
        received = json.load(open(received_path))
        for name in outputs:
            cols = columns_of(header, name)
            mine = [list(r) if len(cols) > 1 else r[0] for r in data[:, cols].tolist()]
            got = received[name]
            i, in_order = 0, True
            for value in got:  # each received value, in order, among the recorded ones
                while i < len(mine) and mine[i] != value:
                    i += 1
                if i == len(mine):
                    in_order = False
                    break
                i += 1
            if not in_order:
                print(f"{name}: the values received on the other node are not the recorded outputs in order")
                failed += 1
            elif len(got) < 0.5 * n:
                print(f"{name}: only {len(got)} of {n} values reached the other node")
                failed += 1
            else:
                print(f"{name}: {len(got)} of {n} values reached the other node, in order and unchanged")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
