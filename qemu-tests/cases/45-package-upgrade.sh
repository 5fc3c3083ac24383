#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: reinstalling the image's own ccommd package (dpkg -i, as an upgrade does) while
# qemu-tests: values flow: ccommd is running afterwards (try-restart on the new binary, no
# qemu-tests: stop left behind), the values flow again, and the gap is measured.
# qemu-tests: timeout=420
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

B=planner
deb=$(vm $B 'ls /var/cache/ccomm/ccommd_*.deb 2>/dev/null | head -n1')
[ -n "$deb" ] || skip "no ccommd .deb kept on the image (/var/cache/ccomm/ccommd_*.deb)"
sig=$(vm control 'ccomm list' | awk 'NR > 1 && $5 == "control" && $3 == "double" {print $2; exit}')
[ -n "$sig" ] || bail "cannot read the signals"

vm_bg control pub "ccomm pub $sig 3.5 --rate 100 --count 100000" >/dev/null
check "before: $B reads $sig fresh" arrives_fresh $B "$sig" 3.5 15
vm_bg $B mon "ccomm echo $sig --interval 20" >/dev/null
sleep 2
before=$(vm $B 'systemctl show -p MainPID --value ccommd')
out=$(vm --timeout 300 $B "DEBIAN_FRONTEND=noninteractive dpkg -i $deb 2>&1; echo rc=\$?")
tail -n 4 <<<"$out" | sed 's/^/  dpkg: /'
check "dpkg -i $(basename "$deb") (a reinstall) succeeds" grep -qx 'rc=0' <<<"$out"
after=$(vm $B 'systemctl is-active ccommd; systemctl show -p MainPID --value ccommd')
note "ccommd before: pid $before; after: $(tr '\n' ' ' <<<"$after")"
check "ccommd is active after the reinstall" [ "$(head -n1 <<<"$after")" = active ]
check "ccommd was restarted on the new binary (try-restart: a new pid)" [ "$(tail -n1 <<<"$after")" != "$before" ]
check "after: $B reads $sig fresh" arrives_fresh $B "$sig" 3.5 15
check "ccomm-board-net was left alone (still active)" vm $B 'systemctl is-active -q ccomm-board-net'
sleep 1
check "the writer and the reader application are still running" \
	eval "vm control 'systemctl is-active -q ccq-pub' && vm $B 'systemctl is-active -q ccq-mon'"
mon=$(vm_bg_stop $B mon)
vm_bg_stop control pub >/dev/null

# The gap: the oldest age a stale sample showed (the daemon restart), and whether the
# reader ever lost the signal ('never': the segment must survive the restart).
gap=$(awk '$3 ~ /^stale/ { a = $5; sub(/age_us=/, "", a); if (a + 0 > m) m = a + 0 } END { printf "%d\n", m / 1000 }' <<<"$mon")
note "$B's reader: $(wc -l <<<"$mon") samples; longest gap (oldest stale sample) ${gap} ms"
check "the reader never saw 'never' (the segment survived)" eval "! grep -q ' never ' <<<\"\$mon\""
check "the gap is bounded: under 15 s (${gap} ms)" [ "$gap" -lt 15000 ]
finish
