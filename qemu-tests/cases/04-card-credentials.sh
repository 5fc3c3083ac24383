#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: the way into a board that docs/yocto.md ("First boot") gives a user: an SSH
# qemu-tests: public key put on the card's FAT partition before the first boot. The board
# qemu-tests: booted from the card mounted that partition (whenever udev announced it: an
# qemu-tests: emulated board does seconds after the boot began), installed the key once
# qemu-tests: (authorized_keys.installed) and takes a login with it from the other board,
# qemu-tests: while a login without it is refused; a board without the partition waited for
# qemu-tests: nothing and logged no error about it.
# qemu-tests: timeout=180
. "$(dirname "$0")/../lib/common.sh"

[ -n "${QT_CARD_BOARD:-}" ] && [ -n "${QT_CARD_KEY:-}" ] && [ -f "$QT_CARD_KEY" ] ||
	skip "no board booted from the SD card (qemu-tests/run --card)"
card=$QT_CARD_BOARD
other=
for b in $QT_BOARDS; do [ "$b" != "$card" ] && other=$b; done

for b in $QT_BOARDS; do
	mapfile -t f < <(vm "$b" 'findmnt -n -o FSTYPE,SOURCE /boot/firmware || echo none
systemctl show ccomm-first-boot-credentials.service -p Result,ExecMainStatus,ExecMainStartTimestampMonotonic | tr "\n" " "; echo
journalctl -b -p err --no-pager -o cat | grep -ci "CCOMM-BOOT\|boot-firmware\|first-boot-credentials" || true
journalctl -b -u ccomm-first-boot-credentials --no-pager -o cat | grep -c "SSH keys for root installed" || true
ls /boot/firmware/authorized_keys /boot/firmware/authorized_keys.installed 2>/dev/null | tr "\n" " "; echo')
	note "$b: /boot/firmware: ${f[0]}; credentials unit: ${f[1]}; files: ${f[4]:-}"
	check "$b: no error about the boot partition or its credentials in the journal (${f[2]})" [ "${f[2]}" = 0 ]
	if [ "$b" = "$card" ]; then
		check "$b: the card's FAT partition is mounted on /boot/firmware (${f[0]})" eval "[[ \"\${f[0]}\" == vfat* ]]"
		check "$b: ccomm-first-boot-credentials ran and succeeded (${f[1]})" \
			eval "grep -q 'Result=success' <<<\"\${f[1]}\" && grep -q 'ExecMainStatus=0' <<<\"\${f[1]}\" && ! grep -q 'ExecMainStartTimestampMonotonic=0 ' <<<\"\${f[1]}\""
		check "$b: it says it installed the keys (journal)" [ "${f[3]}" = 1 ]
		check "$b: the card's authorized_keys renamed .installed, applied once (${f[4]:-})" \
			eval "[ \"\${f[4]}\" = '/boot/firmware/authorized_keys.installed ' ]"
		key=$(cut -d' ' -f2 "$QT_CARD_KEY.pub")
		check "$b: root's authorized_keys holds the key from the card" \
			eval "vm $b 'grep -c -- $key /root/.ssh/authorized_keys' | grep -qx 1"
	else
		check "$b: no boot partition, so nothing mounted and the credentials unit never ran (${f[0]}; ${f[1]})" \
			eval "[ \"\${f[0]}\" = none ] && grep -q 'ExecMainStartTimestampMonotonic=0 ' <<<\"\${f[1]}\""
	fi
done

if [ -n "$other" ]; then
	# The private key to the other board, as a user's PC would hold it.
	vm "$other" "install -d -m 700 /root/.ccq-key && echo $(base64 -w0 "$QT_CARD_KEY") | base64 -d >/root/.ccq-key/id && chmod 600 /root/.ccq-key/id" >/dev/null
	ip=$(board_ip "$card")
	opts="-o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null -o BatchMode=yes -o ConnectTimeout=30 -o LogLevel=ERROR"
	out=$(vm --timeout 90 "$other" "ssh $opts -i /root/.ccq-key/id root@$ip 'hostname; id -u' 2>&1; echo rc=\$?")
	note "$other -> $card: ssh with the card's key: $(tr '\n' ' ' <<<"$out")"
	check "$other -> $card: root logs in over SSH with the key put on the card" \
		eval "grep -qx '$card' <<<\"\$out\" && grep -qx 0 <<<\"\$out\" && grep -qx rc=0 <<<\"\$out\""
	out=$(vm --timeout 90 "$other" "ssh $opts -o PubkeyAuthentication=no -o PreferredAuthentications=password,keyboard-interactive root@$ip true 2>&1; echo rc=\$?")
	note "$other -> $card: ssh without a key: $(tr '\n' ' ' <<<"$out")"
	check "$other -> $card: without the key SSH refuses (keys only: no password asked)" \
		eval "grep -q 'Permission denied' <<<\"\$out\" && ! grep -qx rc=0 <<<\"\$out\""
	vm "$other" "rm -rf /root/.ccq-key" >/dev/null
fi
finish
