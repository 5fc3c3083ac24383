# SPDX-License-Identifier: Apache-2.0
# Helpers for the two-board QEMU test cases (sourced by qemu-tests/cases/*.sh, which
# qemu-tests/run starts with the boards up and the QT_* variables set).
#
# Exit codes follow kselftest: 0 pass, 1 fail, 4 skip.

KSFT_PASS=0
KSFT_FAIL=1
KSFT_SKIP=4

: "${QT_VMCTL:?run the cases through qemu-tests/run}"
: "${CCOMM_PYTHON:?run the cases through qemu-tests/run (it sets the Python: scripts/python.sh)}"

QT_FAILED=0
QT_CHECKS=0

note() { echo "$*"; }

# vm [--timeout S] BOARD COMMAND...: runs COMMAND with bash on BOARD, prints its output,
# returns its exit status (125: the board did not answer). Every process started on a
# board costs 0.1-0.5 s under emulation: prefer one request doing several things, and
# shell builtins; `nap SECONDS` is a builtin sleep there.
vm() {
	local t=60
	if [ "$1" = --timeout ]; then t=$2; shift 2; fi
	local b=$1
	shift
	local sock_var=QT_CTL_$b
	"$CCOMM_PYTHON" "$QT_VMCTL" run "${!sock_var}" --timeout "$t" -- "$*"
}

# vm_bg BOARD NAME COMMAND...: starts COMMAND as transient unit ccq-NAME on BOARD (so
# it outlives the control request); its output and exit status go to /run/ccq-NAME.*.
vm_bg() {
	local b=$1 n=$2
	shift 2
	local cmd
	cmd=$(printf '%s' "$*" | base64 -w0)
	# /run/ccq-NAME.unit tells qemu-tests/run that there is a unit to stop after the case.
	vm "$b" "rm -f /run/ccq-$n.out /run/ccq-$n.rc; : >/run/ccq-$n.unit; systemctl reset-failed ccq-$n.service 2>/dev/null; \
systemd-run --quiet --unit=ccq-$n --service-type=exec -p KillMode=mixed \
bash -c 'echo $cmd | base64 -d | bash >/run/ccq-$n.out 2>&1; echo \$? >/run/ccq-$n.rc'"
}

# vm_bg_wait BOARD NAME [TIMEOUT]: waits for ccq-NAME, prints its output, returns its status.
vm_bg_wait() {
	local b=$1 n=$2 t=${3:-60}
	vm --timeout $((t + 5)) "$b" "i=0; while [ ! -e /run/ccq-$n.rc ] && [ \$i -lt $((t * 5)) ]; do nap 0.2; i=\$((i+1)); done; \
cat /run/ccq-$n.out 2>/dev/null; [ -e /run/ccq-$n.rc ] || { echo 'ccq-$n: still running after ${t}s'; exit 124; }; exit \$(cat /run/ccq-$n.rc)"
}

# vm_bg_stop BOARD NAME: stops ccq-NAME (SIGTERM), prints its output so far.
vm_bg_stop() {
	vm "$1" "systemctl stop ccq-$2.service 2>/dev/null; cat /run/ccq-$2.out 2>/dev/null; true"
}

# link_down BOARD [tap|carrier] / link_up BOARD [tap|carrier]: cut or restore the
# board's cable. tap (default with the bridge, netns mode): the host side tap goes
# down; the board keeps its carrier, like a cable cut behind a switch, so only
# timeouts can tell. carrier (the only way in dgram mode): QEMU sets the board's link
# down, which the board sees as carrier loss.
link_set() {
	local b=$1 state=$2 how=${3:-}
	[ -n "$how" ] || how=$([ "$QT_NET" = netns ] && echo tap || echo carrier)
	if [ "$how" = tap ]; then
		[ "$QT_NET" = netns ] || { echo "link_set: tap needs --net netns" >&2; return 2; }
		local tap_var=QT_TAP_$b
		ip -n "$QT_NS" link set "${!tap_var}" "$state"
	else
		local qmp_var=QT_QMP_$b up=true
		[ "$state" = down ] && up=false
		"$CCOMM_PYTHON" "$QT_VMCTL" qmp "${!qmp_var}" set_link "{\"name\": \"n0\", \"up\": $up}"
	fi
}
link_down() { link_set "$1" down "${2:-}"; }
link_up() { link_set "$1" up "${2:-}"; }

board_ip() { local v=QT_IP_$1; echo "${!v%/*}"; }
board_mac() { local v=QT_MAC_$1; echo "${!v}"; }

# check DESCRIPTION COMMAND...: one sub-result, printed as a TAP-like line; the case
# fails at `finish` if any check failed.
check() {
	local d=$1
	shift
	QT_CHECKS=$((QT_CHECKS + 1))
	if "$@"; then
		echo "ok $QT_CHECKS - $d"
	else
		echo "not ok $QT_CHECKS - $d"
		QT_FAILED=$((QT_FAILED + 1))
	fi
}
fail() { echo "not ok - $*"; QT_FAILED=$((QT_FAILED + 1)); }
# known DESCRIPTION REASON COMMAND...: a check of a known gap (an open issue): ok when it
# holds, else "not ok ... # TODO REASON" (TAP), which does not fail the case.
known() {
	local d=$1 why=$2
	shift 2
	QT_CHECKS=$((QT_CHECKS + 1))
	if "$@"; then echo "ok $QT_CHECKS - $d"; else echo "not ok $QT_CHECKS - $d # TODO $why"; fi
}
skip() { echo "SKIP: $*"; exit $KSFT_SKIP; }
bail() { echo "FAIL: $*"; exit $KSFT_FAIL; }
finish() {
	[ "$QT_FAILED" = 0 ] && exit $KSFT_PASS
	echo "$QT_FAILED of $QT_CHECKS checks failed"
	exit $KSFT_FAIL
}

# need_ccomm: skip the case unless both boards have ccommd and the ccomm CLI.
need_ccomm() {
	local b
	for b in $QT_BOARDS; do
		vm "$b" 'command -v ccommd >/dev/null && command -v ccomm >/dev/null' >/dev/null 2>&1 ||
			skip "ccommd/ccomm not installed on $b (image built with --no-ccomm, or the core is not there yet)"
	done
}

# wait_until TIMEOUT COMMAND...: polls COMMAND (host side) every 0.5 s until it succeeds.
wait_until() {
	local t=$1
	shift
	local end=$(($(date +%s) + t))
	until "$@"; do
		[ "$(date +%s)" -ge "$end" ] && return 1
		sleep 0.5
	done
}

# jcheck PYTHON-EXPRESSION < JSON: true if the expression, with the JSON document as d,
# holds (e.g. the output of `ccomm stats --json`).
jcheck() { "$CCOMM_PYTHON" -c 'import json, sys; d = json.load(sys.stdin); sys.exit(0 if eval(sys.argv[1]) else 1)' "$1"; }
# jget PYTHON-EXPRESSION < JSON: prints the expression's value.
jget() { "$CCOMM_PYTHON" -c 'import json, sys; d = json.load(sys.stdin); print(eval(sys.argv[1]))' "$1"; }
# sig_summary NAME < JSON: one signal's counters from `ccomm stats --json`.
sig_summary() {
	jget "(lambda s: 'writes=%d tx=%d rx=%d lost=%d coalesced=%d stale=%s stale_transitions=%d' % (s['writes'], s['tx'], s['rx'], s['lost'], s['coalesced'], s['stale'], s['stale_transitions']))([s for s in d['signals'] if s['name'] == '$1'][0])"
}
# peer_summary < JSON: the peers' counters from `ccomm stats --json`.
peer_summary() {
	jget "' '.join('%s: alive=%s frames_rx=%d lost=%d down_transitions=%d last_rx_age_ms=%.0f' % (p['name'], p['alive'], p['frames_rx'], p['frames_lost'], p['down_transitions'], p['last_rx_age_ms']) for p in d['peers'])"
}
# arrives_fresh BOARD SIGNAL VALUE [TIMEOUT]: new updates of SIGNAL reach an
# application on BOARD, fresh, with VALUE. Arrival-driven (ccomm echo waits for the
# next update) rather than sampling "is it fresh now": on a loaded emulated board a
# 100 Hz writer's gaps often exceed a 20 ms stale_after_ms, arrivals are fresh.
arrives_fresh() {
	local t=${4:-15} out
	out=$(vm --timeout $((t + 10)) "$1" "ccomm echo $2 -n 3 --timeout $t") || return 1
	tail -n 2 <<<"$out" | awk -v want="$3 fresh" '$2 " " $3 == want {ok = 1} END {exit !ok}'
}
