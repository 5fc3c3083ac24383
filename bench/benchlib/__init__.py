# SPDX-License-Identifier: Apache-2.0
"""Benchmark helpers shared by scripts/bench-floors and scripts/bench.

results    -- the result-row schema, statistics, JSON files and the printed table
procs      -- running the measurement programs, in network namespaces or not
floors     -- the floor and peer measurements (shm, net, LCM, iceoryx)
plot       -- latency distribution plots (matplotlib, optional)
ccomm      -- ccomm under measurement: generated configs, daemons, ccomm-latency, /proc
callgrind  -- reading callgrind profiles (instructions in total and per call)
suite      -- scripts/bench's plan, its context (Bench) and run_case()
runners    -- how each kind of ccomm case is measured (on-target, board to board, thesis, cost)
report     -- docs/performance.md from one run (the renderer)
targets    -- the targets a run is judged against, and why one was missed
cost       -- the report's cost section (CPU time, callgrind tables)
reproduce  -- the report's closing sections (commands as run, two real boards)
formatting -- helpers the report modules share (Rows, ratios, numbers, tables)
"""
