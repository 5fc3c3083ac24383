# SPDX-License-Identifier: Apache-2.0
"""ccomm deploy FILE: one signals.xml onto every board it names, switched at one instant.

Two phases, the way a distributed commit is done (docs/man/ccomm-deploy.1.md):
  1. prepare, every board at once: the file goes to CONFIG.staged there, that board's own
     ccommd checks it (`ccommd -c STAGED --check`) and says which node it is in it
     (`--which-node`); the board's clock is read three times for its offset from ours.
     Nothing running changes; the old file stays in place.
  2. switch: only when every board said yes, each board's ccommd is given one instant
     (ours + its offset): it reads and checks the staged file at once and says armed, and
     at the instant it switches inside itself (nothing left to parse then); the staged
     file then replaces CONFIG. A board that refused, could not be reached or could not be
     armed in time aborts the switch on every board (staged files removed: an armed ccommd
     cancels), and this tool says which board and why.

The boards are reached by one command per step through a transport command that runs a
shell command line on the board: by default `ssh -o BatchMode=yes {host}`; {host} is the
node's ip= (or --host NODE=ADDR, else the node's name), {node} its name. Only the Python
standard library is used, so a board with python3 can deploy as well as a PC."""
from __future__ import annotations

import argparse
import base64
import getpass
import hashlib
import json
import os
import shlex
import socket
import subprocess
import sys
import threading
import time
from typing import Any, Callable, Optional

EXIT_OK, EXIT_REFUSED, EXIT_USAGE, EXIT_UNREACHABLE = 0, 1, 2, 3
# The board's ccommd under systemd (dist/ccommd.service): its main PID, asked to switch.
SWITCH_DEFAULT = 'ccommd -c {config} --reload "$(systemctl show -p MainPID --value ccommd)" --at {at}'
TAG = "ccomm-deploy:"

# Phase 1 on a board. $1 the config path, $2 ccommd, $3 the file in base64, $4 the node
# this board must be, $5 its interface= (checked here: ccommd --check cannot see the board),
# $6 the ccomm CLI (its stats: the peers' clock floors, for the offsets between boards). Every line the tool reads starts with TAG; others are ccommd's words.
PREPARE = r'''
f=$1 d=$2 s=$1.staged
umask 022
if ! printf '%s' "$3" | base64 -d >"$s.tmp" 2>/dev/null || ! mv -f "$s.tmp" "$s"; then
  rm -f "$s.tmp"; echo "ccomm-deploy: refused: cannot write $s (need write access to $(dirname "$f"))"; exit 1
fi
t0=$(date +%s%N)
if ! out=$("$d" -c "$s" --check 2>&1); then
  printf '%s\n' "$out"; rm -f "$s"; echo "ccomm-deploy: refused: ccommd --check failed"; exit 1
fi
echo "ccomm-deploy: check-took $(( $(date +%s%N) - t0 ))"
if ! who=$("$d" -c "$s" --which-node 2>&1); then
  printf '%s\n' "$who"; rm -f "$s"; echo "ccomm-deploy: refused: this board is no node of the file"; exit 1
fi
case "$who" in "$4 "*) ;; *)
  rm -f "$s"; echo "ccomm-deploy: refused: this board is node '${who%% *}' in the file, not '$4' ($who)"; exit 1;;
esac
if [ -n "$5" ] && [ -d /sys/class/net ] && [ ! -e "/sys/class/net/$5" ]; then
  rm -f "$s"; echo "ccomm-deploy: refused: the file puts node '$4' on interface $5, which this board does not have ($(ls /sys/class/net | tr '\n' ' '))"; exit 1
fi
echo "ccomm-deploy: which-node $who"
echo "ccomm-deploy: sha256 $(sha256sum "$s" | cut -d' ' -f1)"
echo "ccomm-deploy: stats $("$6" --node "$4" stats --json 2>/dev/null | tr -d '\n')"
for i in 1 2 3; do echo "ccomm-deploy: clock $(date +%s%N)"; done
'''

# Phase 2 on a board: a detached job runs the switch command (by default `ccommd --reload
# PID --at AT`: ccommd checks the staged file at once, answers "armed", switches inside
# itself at AT on the board's CLOCK_REALTIME and the command then moves the staged file over
# CONFIG). Its stdout ("armed AT", "switched AT APPLIED") and "done RC TIME" go to
# CONFIG.deploy-out, its log to CONFIG.deploy-log. $1 config, $2 the command, $3 the
# deployer record.
SWITCH_JOB = r"""
f=$1
sh -c "$2" >"$f.deploy-out" 2>"$f.deploy-log"; rc=$?
[ $rc -eq 0 ] && printf '%s\n' "$3" >"$f.deployed"
echo "done $rc $(date +%s%N)" >>"$f.deploy-out"
"""

# Starts the job and waits until the board's ccommd said "armed" (or the job ended: refused).
SCHEDULE = r"""
f=$1
rm -f "$f.deploy-out" "$f.deploy-log"
[ -e "$f.staged" ] || { echo "ccomm-deploy: refused: $f.staged is gone"; exit 1; }
setsid sh -c "$2" ccomm-deploy-switch "$f" "$3" "$4" </dev/null >/dev/null 2>&1 &
i=0
while [ $i -lt "$5" ]; do
  if grep -q '^armed ' "$f.deploy-out" 2>/dev/null; then echo "ccomm-deploy: scheduled now $(date +%s%N)"; exit 0; fi
  if grep -q '^done ' "$f.deploy-out" 2>/dev/null; then
    echo "ccomm-deploy: refused: $(grep -v '^ *$' "$f.deploy-log" 2>/dev/null | tail -n 3 | tr '\n' ' ')"; exit 1; fi
  sleep 0.1; i=$((i + 1))
done
echo "ccomm-deploy: refused: the switch command did not say armed within $(( $5 / 10 )) s"; exit 1
"""

ABORT = r'''rm -f "$1.staged"; echo "ccomm-deploy: aborted"'''
STATUS = r'''cat "$1.deploy-out" 2>/dev/null; cat "$1.deploy-log" 2>/dev/null | sed 's/^/log: /' '''


def sh_line(script: str, *args: str) -> str:
    """A command line for a remote POSIX shell that runs SCRIPT with ARGS as $1.."""
    return "sh -c " + shlex.quote(script) + " ccomm-deploy-board " + " ".join(shlex.quote(a) for a in args)


class Board:
    def __init__(self, node: dict[str, Any], host: str, args: argparse.Namespace) -> None:
        self.name: str = node["name"]
        self.interface: str = node.get("interface") or ""
        self.host = host
        self.config: str = args.remote_config.replace("{node}", self.name)
        self.via = [p.replace("{host}", host).replace("{node}", self.name) for p in shlex.split(args.via)]
        self.switch_command: str = args.switch_command.replace("{node}", self.name).replace("{config}", self.config)
        self.ccommd: str = args.remote_ccommd
        self.ccomm: str = args.remote_ccomm
        self.timeout: float = args.timeout
        self.state = "new"     # prepared, refused, unreachable, scheduled, switched, aborted, failed
        self.why = ""
        self.offset_ns = 0     # board clock - our clock
        self.offset_err_ns = 0  # half the round trip of the best clock reading
        self.agree_err_ns = 0   # how well its offset is known against the other boards'
        self.clock_source = "transport"  # or "ccomm": from the frames between the boards
        self.stats: dict[str, Any] = {}  # its `ccomm stats --json` at prepare
        self.which = ""
        self.check_ns = 0      # how long the board's ccommd took to check the file
        self.sha256 = ""
        self.switch: Optional[tuple[int, int, int]] = None  # (agreed instant, applied, rc), our clock

    def run(self, line: str, timeout: Optional[float] = None) -> tuple[int, list[str], str, int, int]:
        """Runs LINE on the board; (exit status, stdout lines, stderr text, t_sent, t_back)."""
        t_sent = time.time_ns()
        try:
            p = subprocess.run(self.via + [line], capture_output=True, text=True,
                               timeout=timeout or self.timeout, stdin=subprocess.DEVNULL)
        except FileNotFoundError:
            return 255, [], "cannot run the transport %r" % self.via[0], t_sent, time.time_ns()
        except subprocess.TimeoutExpired:
            return 255, [], "no answer within %.0f s" % (timeout or self.timeout), t_sent, time.time_ns()
        return p.returncode, p.stdout.splitlines(), p.stderr.strip(), t_sent, time.time_ns()


def tagged(lines: list[str], key: str) -> list[str]:
    return [ln[len(TAG) + 1 + len(key):].strip() for ln in lines if ln.startswith(TAG + " " + key)]


def prepare(b: Board, b64: str, want_sha: str) -> None:
    rc, out, err, t_sent, t_back = b.run(sh_line(PREPARE, b.config, b.ccommd, b64, b.name, b.interface, b.ccomm))
    refusal = tagged(out, "refused:")
    if refusal:
        b.state, b.why = "refused", refusal[0]
        detail = [ln for ln in out if not ln.startswith(TAG)]
        if detail:
            b.why += ": " + "; ".join(detail[:5])
        return
    if rc != 0:
        b.state = "unreachable"
        b.why = (err.splitlines()[-1] if err else "exit status %d" % rc)
        return
    b.which = (tagged(out, "which-node") or [""])[0]
    b.sha256 = (tagged(out, "sha256") or [""])[0]
    b.check_ns = int((tagged(out, "check-took") or ["0"])[0] or 0)
    if b.sha256 != want_sha:
        b.state, b.why = "refused", "the staged file's sha256 %s is not the file's %s" % (b.sha256[:12], want_sha[:12])
        return
    try:
        b.stats = json.loads((tagged(out, "stats") or ["{}"])[0] or "{}")
    except ValueError:
        b.stats = {}
    clocks = [int(c) for c in tagged(out, "clock")]
    if not clocks:
        b.state, b.why = "unreachable", "the board did not say its time"
        return
    # The readings lie between sending and answer; the middle of that window is our best
    # guess (a one-shot transport's start-up makes the window wide, see --margin).
    mid = (t_sent + t_back) // 2
    b.offset_ns = clocks[len(clocks) // 2] - mid
    b.offset_err_ns = (t_back - t_sent) // 2
    b.state = "prepared"


def probe_offset(b: Board, rounds: int = 3) -> None:
    """Narrows the clock offset with short round trips of `date` alone."""
    best: Optional[tuple[int, int]] = None
    for _ in range(rounds):
        rc, out, _err, t_sent, t_back = b.run("date +%s%N")
        if rc != 0 or not out:
            continue
        rtt = t_back - t_sent
        if best is None or rtt < best[0]:
            best = (rtt, int(out[0]) - (t_sent + t_back) // 2)
    if best and best[0] // 2 < b.offset_err_ns:
        b.offset_err_ns, b.offset_ns = best[0] // 2, best[1]
    # An offset smaller than what the round trip lets us see is no offset: the clocks agree
    # (PTP, NTP, or one machine) better than we could correct them, so none is applied.
    if abs(b.offset_ns) <= b.offset_err_ns:
        b.offset_ns = 0


def relate_clocks(boards: list[Board]) -> None:
    """The offsets between the boards from ccomm's own frames, where every board hears the
    others: each frame carries its sender's CLOCK_MONOTONIC send time, and a board's floor
    for peer P (`ccomm stats`: offset_floor_ns, the smallest arrival - send) is its clock
    minus P's plus the fastest one-way delay. Half the difference of the two directions'
    floors is the offset of the two monotonic clocks, to within half the fastest round trip
    (asymmetry); each board's realtime_offset_ns maps it to CLOCK_REALTIME. One board, the
    best known over the transport, is the reference; the others' offsets follow from it.
    Where some board lacks the floors, the transport's offsets stand (agreement within the
    sum of two boards' round-trip errors)."""
    for b in boards:
        b.agree_err_ns = 2 * max(x.offset_err_ns for x in boards)
    if len(boards) < 2:
        return
    def floor(x: Board, peer: str) -> Optional[int]:
        for p in x.stats.get("peers", []):
            if p.get("name") == peer and p.get("clock", {}).get("known"):
                return int(p["clock"]["offset_floor_ns"])
        return None
    ref = min(boards, key=lambda x: x.offset_err_ns)
    found = {}
    for b in boards:
        if b is ref:
            continue
        f_b, f_r = floor(b, ref.name), floor(ref, b.name)  # mono_b - mono_r + d, mono_r - mono_b + d'
        if f_b is None or f_r is None or "realtime_offset_ns" not in b.stats or "realtime_offset_ns" not in ref.stats:
            return
        mono = (f_b - f_r) // 2
        err = max(0, (f_b + f_r) // 2)
        rt = mono + int(b.stats["realtime_offset_ns"]) - int(ref.stats["realtime_offset_ns"])
        found[b.name] = (rt, err)
    for b in boards:
        if b is ref:
            b.agree_err_ns, b.clock_source = 0, "ccomm (the reference)"
        else:
            rt, err = found[b.name]
            b.offset_ns, b.agree_err_ns, b.clock_source = ref.offset_ns + rt, err, "ccomm (against %s)" % ref.name


def parallel(fn: Callable[..., object], boards: list[Board], *a: object) -> None:
    ts = [threading.Thread(target=fn, args=(b,) + a) for b in boards]
    for t in ts:
        t.start()
    for t in ts:
        t.join()


def load(path: str, ccommd: str) -> dict[str, Any]:
    """Checks the file here with the one parser (ccommd --check --json)."""
    try:
        p = subprocess.run([ccommd, "-c", path, "--check", "--json"], capture_output=True, text=True)
    except FileNotFoundError:
        sys.exit("ccomm deploy: cannot run %s to check %s (install ccommd, or --ccommd PATH)" % (ccommd, path))
    if p.returncode != 0:
        sys.stderr.write(p.stderr)
        sys.exit(EXIT_REFUSED)
    cfg: dict[str, Any] = json.loads(p.stdout)
    return cfg


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(
        prog="ccomm deploy",
        description="Put one signals.xml on every board it names, check it there with each board's "
                    "ccommd, and switch all boards to it at one instant (two phases: any refusal or "
                    "unreachable board aborts the switch everywhere; the old file stays until then).",
        epilog="Exit status: 0 every board switched; 1 the file was refused (here or by a board) or a "
               "board's reload failed; 2 usage; 3 a board could not be reached (nothing switched). "
               "See ccomm-deploy(1).")
    ap.add_argument("file", help="the new signals.xml")
    ap.add_argument("--host", action="append", default=[], metavar="NODE=ADDR",
                    help="where to reach NODE (default: its ip=, else its name)")
    ap.add_argument("--only", action="append", default=[], metavar="NODE",
                    help="deploy to these nodes only (default: every node of the file that has a board)")
    ap.add_argument("--via", default=os.environ.get("CCOMM_DEPLOY_VIA", "ssh -o BatchMode=yes -o ConnectTimeout=5 {host}"),
                    help="the command that runs a shell command line on a board ({host}, {node}); "
                         "default: $CCOMM_DEPLOY_VIA, else 'ssh -o BatchMode=yes -o ConnectTimeout=5 {host}'")
    ap.add_argument("--remote-config", default="/etc/ccomm/signals.xml",
                    help="the file on the boards ({node} allowed; default /etc/ccomm/signals.xml)")
    ap.add_argument("--switch-command", default=SWITCH_DEFAULT,
                    help="how a board's ccommd is asked to switch to {config}.staged at {at} (its clock, "
                         "seconds.nanoseconds); {config}, {node}, {at}; default %r" % SWITCH_DEFAULT)
    ap.add_argument("--arm-timeout", type=float, default=30.0,
                    help="seconds a board's ccommd may take to check the staged file and say armed (default 30)")
    ap.add_argument("--ccommd", default="ccommd", help="ccommd here, for the first check (default: from PATH)")
    ap.add_argument("--remote-ccommd", default="ccommd", help="ccommd on the boards (default: from PATH)")
    ap.add_argument("--remote-ccomm", default="ccomm",
                    help="the ccomm CLI on the boards, for the clock offsets between them (default: from PATH)")
    ap.add_argument("--margin", type=float, default=2.0,
                    help="seconds from the last board scheduled to the switch (default 2)")
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds per step on a board (default 30)")
    ap.add_argument("--dry-run", action="store_true", help="prepare and check everywhere, then abort: switch nothing")
    ap.add_argument("--json", action="store_true", help="the outcome as one JSON object on stdout")
    args = ap.parse_args(argv)

    if not os.path.isfile(args.file):
        ap.error("%s: no such file" % args.file)
    data = open(args.file, "rb").read()
    cfg = load(args.file, args.ccommd)
    hosts = {}
    for h in args.host:
        node, sep, addr = h.partition("=")
        if not sep or not addr:
            ap.error("--host takes NODE=ADDR, not %r" % h)
        hosts[node] = addr
    names = [n["name"] for n in cfg["nodes"]]
    for n in list(hosts) + args.only:
        if n not in names:
            ap.error("%s is no node of %s (nodes: %s)" % (n, args.file, ", ".join(names)))
    picked = [n for n in cfg["nodes"] if not args.only or n["name"] in args.only]
    boards = [Board(n, hosts.get(n["name"]) or n.get("ip") or n["name"], args) for n in picked]
    sha = hashlib.sha256(data).hexdigest()
    b64 = base64.b64encode(data).decode()
    if len(b64) > 128 * 1024:  # one command-line argument holds at most 128 KiB on Linux
        sys.exit("ccomm deploy: %s is %d bytes; at most 96 KiB travels in a command line" % (args.file, len(data)))
    deployer = "%s@%s %s %s" % (getpass.getuser(), socket.gethostname(),
                                time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), sha)
    def say(*a: object) -> None:
        print(*a, file=sys.stderr if args.json else sys.stdout)
    say("deploy %s (config hash %s, sha256 %s) to %d boards: %s" %
        (args.file, cfg["hash"], sha[:12], len(boards), ", ".join("%s (%s)" % (b.name, b.host) for b in boards)))

    parallel(prepare, boards, b64, sha)
    parallel(probe_offset, [b for b in boards if b.state == "prepared"])
    if all(b.state == "prepared" for b in boards):
        relate_clocks(boards)
    for b in boards:
        say("  %-12s %-11s %s" % (b.name, b.state, b.why or "is %s; clock offset %+.1f ms (+-%.1f), against the "
                                  "other boards +-%.2f ms (%s)" % (b.which, b.offset_ns / 1e6, b.offset_err_ns / 1e6,
                                                                  b.agree_err_ns / 1e6, b.clock_source)))
    bad = [b for b in boards if b.state != "prepared"]
    outcome = {"file": args.file, "hash": cfg["hash"], "sha256": sha, "deployer": deployer}
    if bad or args.dry_run:
        parallel(lambda b: b.state == "prepared" and b.run(sh_line(ABORT, b.config)), boards)
        for b in boards:
            if b.state == "prepared":
                b.state = "aborted" if bad else "checked"
        rc = EXIT_OK if not bad else (EXIT_UNREACHABLE if any(b.state == "unreachable" for b in bad) else EXIT_REFUSED)
        if bad:
            say("not switched: %s; no board changed (staged files removed)" %
                "; ".join("%s %s: %s" % (b.name, b.state, b.why) for b in bad))
        else:
            say("dry run: every board accepts the file; nothing switched")
        return finish(args, outcome, boards, rc, None)

    # Phase 2. One instant on our clock, far enough ahead for every board to be told and
    # for its ccommd to check the staged file once more before it says armed (as long as
    # its check took in phase 1; twice that, for a loaded board).
    worst = max(b.offset_err_ns for b in boards)
    arm_ns = 2 * max(b.check_ns for b in boards)
    at = time.time_ns() + max(int(args.margin * 1e9), arm_ns) + 2 * worst
    def schedule(b: Board) -> None:
        sec, ns = divmod(at + b.offset_ns, 1000000000)
        cmd = b.switch_command.replace("{at}", "%d.%09d" % (sec, ns))
        rc, out, err, _s, _t = b.run(sh_line(SCHEDULE, b.config, SWITCH_JOB, cmd, deployer,
                                             str(int(args.arm_timeout * 10))), timeout=b.timeout + args.arm_timeout)
        if rc == 0 and tagged(out, "scheduled"):
            b.state = "armed"
        else:
            b.state, b.why = "unreachable" if rc == 255 else "refused", (tagged(out, "refused:") or [err or "exit %d" % rc])[0]
    parallel(schedule, boards)
    late = time.time_ns() > at - int(0.1e9)
    bad = [b for b in boards if b.state != "armed"]
    if bad or late:
        # Removing the staged file cancels an armed switch (ccommd checks it at the instant).
        parallel(lambda b: b.run(sh_line(ABORT, b.config)), boards)
        why = "; ".join("%s: %s" % (b.name, b.why) for b in bad) or \
            "arming took past the switch instant (raise --margin)"
        for b in boards:
            if b.state == "armed":
                b.state = "aborted"
        still = time.time_ns() < at
        say("not switched: %s; aborted on every board%s" % (why, "" if still else " (too late to be sure: check each board)"))
        return finish(args, outcome, boards, EXIT_UNREACHABLE if any(b.state == "unreachable" for b in bad) else EXIT_REFUSED, at)
    say("every board armed; switching at %s (in %.1f s)" % (
        time.strftime("%H:%M:%S", time.localtime(at / 1e9)), (at - time.time_ns()) / 1e9))
    time.sleep(max(0.0, (at - time.time_ns()) / 1e9))

    def collect(b: Board) -> None:
        end = time.time() + b.timeout
        while time.time() < end:
            rc, out, err, _s, _t = b.run(sh_line(STATUS, b.config))
            done = [ln.split() for ln in out if ln.startswith("done ")]
            if done:
                code = int(done[0][1])
                sw = [ln.split() for ln in out if ln.startswith("switched ")]
                log = "; ".join(ln[5:] for ln in out if ln.startswith("log: ") and ln[5:].strip())
                if code == 0 and sw:
                    b.switch = (int(sw[0][1]) - b.offset_ns, int(sw[0][2]) - b.offset_ns, 0)
                    b.state = "switched"
                else:
                    b.state, b.why = "failed", (log or "the switch command exited %d" % code)[:400]
                return
            time.sleep(0.3)
        b.state, b.why = "unknown", "no outcome within %.0f s" % b.timeout
    parallel(collect, boards)
    for b in boards:
        if b.switch:
            say("  %-12s %-11s switched, its ccommd answered %+.1f ms after the instant" %
                (b.name, b.state, (b.switch[1] - at) / 1e6))
        else:
            say("  %-12s %-11s %s" % (b.name, b.state, b.why))
    ok = all(b.state == "switched" for b in boards)
    switches = [b.switch for b in boards if b.switch]
    if ok and switches:
        ends = [sw[1] for sw in switches]
        say("every board switched; the answers %.1f ms apart on this clock (offsets here +-%.1f ms; "
            "the boards' clocks against each other +-%.2f ms)" %
            ((max(ends) - min(ends)) / 1e6, worst / 1e6, max(b.agree_err_ns for b in boards) / 1e6))
    return finish(args, outcome, boards, EXIT_OK if ok else EXIT_REFUSED, at)


def finish(args: argparse.Namespace, outcome: dict[str, Any], boards: list[Board], rc: int, at: Optional[int]) -> int:
    if args.json:
        outcome.update(exit=rc, at_ns=at, boards=[{
            "node": b.name, "host": b.host, "state": b.state, "why": b.why, "which_node": b.which,
            "offset_ns": b.offset_ns, "offset_error_ns": b.offset_err_ns,
            "agree_error_ns": b.agree_err_ns, "clock_source": b.clock_source,
            "check_ns": b.check_ns,
            "at_ns": b.switch[0] if b.switch else None, "applied_ns": b.switch[1] if b.switch else None,
        } for b in boards])
        print(json.dumps(outcome))
    return rc


if __name__ == "__main__":
    sys.exit(main())
