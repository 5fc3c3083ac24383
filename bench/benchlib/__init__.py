# SPDX-License-Identifier: Apache-2.0
"""Benchmark helpers shared by scripts/bench-floors and scripts/bench.

results  -- the result-row schema, statistics, JSON files and the printed table
procs    -- running the measurement programs, in network namespaces or not
floors   -- the floor and peer measurements (shm, net, LCM, iceoryx)
plot     -- latency distribution plots (matplotlib, optional)
ccomm    -- ccomm under measurement: generated configs, daemons, ccomm-latency, /proc, callgrind
suite    -- scripts/bench's plan and runners (on-target, board to board, thesis, cost)
report   -- docs/performance.md from one run
"""
