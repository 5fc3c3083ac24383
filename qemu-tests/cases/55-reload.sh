#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: systemctl reload ccommd under the image's systemd: a broken
# qemu-tests: /etc/ccomm/signals.xml is refused (reload fails, the service stays active
# qemu-tests: on the old file, systemctl status and journalctl -p err name FILE:LINE,
# qemu-tests: values keep flowing); a local-only change applies with the segment kept;
# qemu-tests: the original file reloads again.
# qemu-tests: timeout=300
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

B=planner
CFG=/etc/ccomm/signals.xml
orig=$(vm $B "cat /run/ccq/signals.xml.orig")
line=$(grep -n '<signal ' <<<"$orig" | grep 'producer="planner"' | head -n1 | cut -d: -f1)
sig=$(grep '<signal ' <<<"$orig" | grep 'consumers="[^"]*planner' | head -n1 | grep -o 'name="[^"]*"' | cut -d'"' -f2)
[ -n "$line" ] && [ -n "$sig" ] || bail "no signal lines in $CFG"
segment_inode() { vm $B 'stat -c %i /dev/shm/ccomm.planner'; }
flows() {  # a value control publishes reaches the planner's application
	local v=$((RANDOM % 1000)).25
	vm control "ccomm pub $sig $v" >/dev/null
	wait_until 10 eval "[ \"\$(vm $B 'ccomm echo $sig --once' | awk '{print \$2}')\" = $v ]"
}
check "before: a value of $sig arrives" flows
inode=$(segment_inode)
pid=$(vm $B 'systemctl show -p MainPID --value ccommd')

# 1. A wrong type on line $line: the reload fails, the service keeps running on the old file.
since=$(vm $B 'date +%s')
vm $B "sed '${line}s/type=\"[a-z0-9]*\"/type=\"doubel\"/' /run/ccq/signals.xml.orig >$CFG"
out=$(vm $B 'systemctl reload ccommd 2>&1'); rc=$?
note "broken file: systemctl reload (exit $rc): $(head -n 2 <<<"$out")"
check "broken file: systemctl reload ccommd fails" test "$rc" != 0
check "broken file: ccommd still active, same process" \
	eval "vm $B 'systemctl is-active -q ccommd' && [ \"\$(vm $B 'systemctl show -p MainPID --value ccommd')\" = $pid ]"
status=$(vm $B 'systemctl status --no-pager -l ccommd' 2>&1)
grep -m 2 "$CFG:$line\|reload failed" <<<"$status" | sed 's/^/  status: /'
check "broken file: systemctl status names $CFG:$line" grep -q "$CFG:$line\\b" <<<"$status"
errs=$(vm $B "journalctl -u ccommd -p err --since @$since --no-pager -o cat")
check "broken file: journalctl -p err names $CFG:$line" grep -q "$CFG:$line\\b" <<<"$errs"
check "broken file: values still flow (old configuration)" flows
check "broken file: segment unchanged" eval "[ \"\$(segment_inode)\" = $inode ]"

# 2. Only a local setting (peer_timeout_ms is in neither the hash nor the layout).
vm $B "sed 's/peer_timeout_ms=\"[0-9]*\"/peer_timeout_ms=\"400\"/' /run/ccq/signals.xml.orig >$CFG"
check "local change: grep finds the edit" vm $B "grep -q 'peer_timeout_ms=\"400\"' $CFG"
check "local change: systemctl reload ccommd succeeds" vm $B 'systemctl reload ccommd'
check "local change: same process, segment kept" \
	eval "[ \"\$(vm $B 'systemctl show -p MainPID --value ccommd')\" = $pid ] && [ \"\$(segment_inode)\" = $inode ]"
check "local change: the journal says the segment was kept" \
	eval "vm $B \"journalctl -u ccommd --since @$since --no-pager -o cat\" | grep -q 'segment kept'"
check "local change: values flow" flows

# 3. The original file again.
vm $B "cp /run/ccq/signals.xml.orig $CFG"
check "original file: systemctl reload ccommd succeeds" vm $B 'systemctl reload ccommd'
check "original file: the peers see each other" \
	wait_until 10 eval "vm control 'ccomm stats --json' | jcheck 'all(p[\"alive\"] for p in d[\"peers\"])'"
check "original file: values flow" flows
finish
