# SPDX-License-Identifier: Apache-2.0
"""Benchmark helpers shared by scripts/bench-floors and (later) scripts/bench.

results  -- the result-row schema, statistics, JSON files and the printed table
procs    -- running the measurement programs, in network namespaces or not
floors   -- the floor and peer measurements (shm, net, LCM, iceoryx)
plot     -- latency distribution plots (matplotlib, optional)
"""
