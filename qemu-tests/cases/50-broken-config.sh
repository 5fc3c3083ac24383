#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: a broken /etc/ccomm/signals.xml (an XML syntax error, then a wrong type):
# qemu-tests: the service refuses to start and the journal names the file and line, at
# qemu-tests: error priority (journalctl -p err); the
# qemu-tests: fixed file starts again and signals flow.
# qemu-tests: timeout=300
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

B=planner
CFG=/etc/ccomm/signals.xml
orig=$(vm $B "cat /run/ccq/signals.xml.orig")
# Lines to break: the first signal the planner consumes, and the first it produces.
line_syntax=$(grep -n '<signal ' <<<"$orig" | grep 'consumers="[^"]*planner' | head -n1 | cut -d: -f1)
line_type=$(grep -n '<signal ' <<<"$orig" | grep 'producer="planner"' | head -n1 | cut -d: -f1)
[ -n "$line_syntax" ] && [ -n "$line_type" ] || bail "no signal lines to break in $CFG"

broken_cycle() {
	local what=$1 line=$2 sedexpr=$3
	note "$what: line $line becomes: $(sed -n "${line}p" <<<"$orig" | sed "$sedexpr")"
	local since
	since=$(vm $B 'date +%s')
	vm $B "sed '${line}$sedexpr' /run/ccq/signals.xml.orig >$CFG" || return 1
	local out rc
	out=$(vm $B "ccommd --check $CFG"); rc=$?
	note "$what: ccommd --check (exit $rc): $(head -n 3 <<<"$out")"
	check "$what: ccommd --check rejects it, naming $CFG:$line" \
		eval "[ $rc != 0 ] && grep -q '$CFG:$line\\b' <<<\"\$out\""
	# The restart fails (ccommd exits 1 on a bad file) and, with RestartPreventExitStatus,
	# the unit stays failed instead of retrying.
	vm $B 'systemctl restart ccommd' >/dev/null 2>&1
	check "$what: systemctl restart ccommd fails" eval "! vm $B 'systemctl is-active -q ccommd'"
	sleep 3
	local state
	state=$(vm $B 'systemctl show -p ActiveState,SubState,NRestarts ccommd | tr "\n" " "')
	note "$what: after 3 s: $state"
	check "$what: the service stays down" eval "! vm $B 'systemctl is-active -q ccommd'"
	local journal
	journal=$(vm $B "journalctl -u ccommd --since @$since --no-pager -o cat")
	grep -m 1 "$CFG:" <<<"$journal" | sed "s/^/  journal: /"
	check "$what: the journal shows $CFG:$line" grep -q "$CFG:$line\\b" <<<"$journal"
	# At error priority (ccommd(8): each line carries its syslog priority), so that
	# journalctl -p err, what an operator asks first, shows why the service failed.
	local errs
	errs=$(vm $B "journalctl -u ccommd -p err --since @$since --no-pager -o cat")
	grep -m 1 "$CFG:" <<<"$errs" | sed "s/^/  journal -p err: /"
	check "$what: journalctl -p err shows $CFG:$line" grep -q "$CFG:$line\\b" <<<"$errs"
	check "$what: the peer (control) sees planner down" \
		wait_until 10 eval "vm control 'ccomm stats --json' | jcheck 'not any(p[\"alive\"] for p in d[\"peers\"])'"

	# Fixed file: the service starts again, without a manual reset-failed: a systemctl
	# restart is what an operator does after fixing the file.
	vm $B "cp /run/ccq/signals.xml.orig $CFG"
	check "$what: fixed file: systemctl restart ccommd succeeds" vm $B 'systemctl restart ccommd'
	check "$what: fixed file: ccommd active" vm $B 'systemctl is-active -q ccommd'
	check "$what: fixed file: the peers see each other again" \
		wait_until 15 eval "vm control 'ccomm stats --json' | jcheck 'all(p[\"alive\"] for p in d[\"peers\"])'"
	local sig v
	sig=$(grep -o 'name="[^"]*"' <<<"$(sed -n "${line_syntax}p" <<<"$orig")" | cut -d'"' -f2)
	v=$((RANDOM % 1000)).5
	vm control "ccomm pub $sig $v" >/dev/null
	check "$what: fixed file: a value sent by control arrives ($sig = $v)" \
		wait_until 10 eval "[ \"\$(vm $B 'ccomm echo $sig --once' | awk '{print \$2}')\" = $v ]"
}

# An attribute value without quotes: malformed XML at that line.
broken_cycle "XML syntax error" "$line_syntax" 's/producer="\([a-z]*\)"/producer=\1/'
# Well-formed XML, wrong content: a type that does not exist.
broken_cycle "unknown type" "$line_type" 's/type="double"/type="doubel"/'
finish
