# SPDX-License-Identifier: Apache-2.0
"""The closing sections of docs/performance.md: the commands as the run made them (from
its rows and the floor programs' logs, without this machine's paths) and how to run the
same measurements between two real boards (BOARDS)."""

import os


def command_line(argv):
    """A command line without this machine's paths (relative to the repository)."""
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    out = []
    for a in argv:
        a = str(a)
        if repo in a:
            a = a.replace(repo + os.sep, "").replace(repo, ".")
        out.append(a)
    return " ".join(out)


def _logged_command(outdir, name, what):
    """The "$ command" line a floor program's log starts with."""
    if not outdir:
        return None
    path = os.path.join(outdir, "logs", "%s.%s.log" % (name, what))
    try:
        with open(path, errors="replace") as f:
            line = f.readline()
    except OSError:
        return None
    return line[2:].split() if line.startswith("$ ") else None


def commands(R, outdir):
    """The "commands as run" list: a few ccomm cases' and the floors' command lines."""
    pick = [("on-target, ccomm ping-pong (the ping side; the echo runs the same with --role echo)",
             "ccomm_pp_state_spin_cycle_b2b_p8", "command"),
            ("on-target, ccomm control-loop shaped (one process: sender thread on CPU A, receive thread on CPU B)",
             "ccomm_shm_state_block_1khz_p8", "command"),
            ("board -> board, ccommd on board A (namespace a)", "ccomm_raw_oneway_block_1khz_p8", "daemon_command"),
            ("board -> board, receiving application on board B", "ccomm_raw_oneway_block_1khz_p8", "command"),
            ("thesis setup-simulation, one side", "thesis_setup_event_1khz_a2b", "command")]
    out = []
    for label, name, key in pick:
        r = R.get(name)
        if r and r.get(key):
            out.append("- %s:\n\n  ```\n  %s\n  ```" % (label, command_line(r[key])))
    floors = [("shared-memory floor", "shm_spin_b2b_p8", ("run",)),
              ("raw floor, one-way (receiver, then sender)", "net_raw_oneway_1khz_p8~1", ("sink", "source")),
              ("LCM (echo, then ping)", "lcm_netns_rtt_half_1khz_p8", ("echo", "ping")),
              ("iceoryx (echo, then ping; a private iox-roudi runs meanwhile)", "iox_spin_b2b_p8", ("echo", "ping"))]
    for label, name, whats in floors:
        cmds = [c for c in (_logged_command(outdir, name, w) for w in whats) if c]
        if cmds:
            out.append("- %s:\n\n  ```\n%s\n  ```" % (label, "\n".join("  " + command_line(c) for c in cmds)))
    return "\n".join(out)


BOARDS = """\
The same measurements run between two real boards; only the one-way rows need a common
clock, so on two boards measure round trips (RTT/2) or synchronise the clocks (PTP,
`ptp4l`/`phc2sys`, sub-microsecond on the same switch) first.

1. Build and install ccomm on both boards (the Yocto image has `ccommd`, `ccomm`,
   `ccomm-latency`; the floor programs are in `libexec/ccomm/bench`, built from `bench/`).
2. Give both boards the same configuration (e.g. `examples/single-signal.xml` or the
   default `dist/signals.xml` for the setup-simulation) with the boards' real interface,
   MAC and IP addresses, and start `ccommd` on each (systemd unit, or
   `ccommd -c signals.xml --node NAME`).
3. Quiet the boards: PREEMPT_RT kernel, `ethtool -C eth0 rx-usecs 0` (NIC interrupt
   coalescing otherwise dominates: hundreds of µs on stock drivers), the NIC's IRQ thread and the
   applications pinned to one CPU, CPU frequency governor `performance`.
4. Floors, with the same rate and payload as the ccomm run:

   ```
   board B: net_floor --transport raw --role echo --if eth0 --prio 70
   board A: net_floor --transport raw --role ping --if eth0 --dst <MAC of B> --rate 1000 --count 10000 --half --prio 70
   (UDP: --transport udp --bind <IP of B>:47900 on B, --peer <IP of B>:47900 on A)
   ```
5. ccomm, same rate, RTT/2 through both daemons:

   ```
   board B: chrt -f 70 ccomm-latency --node server --mode echo --rate 1000 --duration 12 --prio 70
   board A: chrt -f 70 ccomm-latency --node client --mode ping --rate 1000 --duration 10 --prio 70
   ```
   With synchronised clocks, one-way: `--mode oneway` on both (B receives, A sends).
6. Check the framing: `ccomm stats --json` on the receiving board, `peers[].frames_rx` minus
   `heartbeats_rx` against the `sent` cycles `ccomm-latency` prints.

On one board (on-target), with `ccommd` running for a node whose file has two state doubles
`ping8`, `pong8` produced there (see `bench/benchlib/ccomm.py`, `local_config`):

   ```
   ccomm_pingpong --role echo --node NODE --ping ping8 --pong pong8 --payload 8 --cpu 1 --floor-shm /ccpp-1 --cycle-time &
   ccomm_pingpong --role ping --node NODE --ping ping8 --pong pong8 --payload 8 --cpu 0 --floor-shm /ccpp-1 --cycle-time --half --count 50000
   ```
   It prints ccomm's RTT/2 and, measured in blocks between the same two processes, the bare
   cache-line floor (`floor_p50_ns`) and the median block ratio (`paired_ratio`).

`scripts/bench` itself drives namespaces on one host; its building blocks
(`bench/benchlib/ccomm.py`: configuration generator, `Daemons`, `latency_argv`) take the
node names, addresses and CPUs as parameters.
"""
