#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: root has no known password on the image: passwd -S root says L (locked) or NP
# qemu-tests: (none), and an su to root with an empty password, from an unprivileged user on
# qemu-tests: a terminal, is refused (NP with PAM's nullok would let anyone in).
# qemu-tests: timeout=120
. "$(dirname "$0")/../lib/common.sh"

for b in $QT_BOARDS; do
	status=$(vm "$b" 'passwd -S root' | awk '{print $2}')
	note "$b: passwd -S root: ${status:-?}"
	check "$b: root's password is locked or empty, none known (passwd -S: L or NP; is '${status:-?}')" \
		eval "[ \"$status\" = L ] || [ \"$status\" = NP ]"
	# script(1) gives su the terminal it asks on; the empty line is the password. 'nobody'
	# is on every Debian root; runuser needs no password to become it.
	out=$(vm --timeout 60 "$b" 'printf "\n" | runuser -u nobody -- script -qec "su -c \"echo SU_GOT_ROOT\" root" /dev/null 2>&1; echo "rc=$?"')
	note "$b: su with an empty password: $(tr '\r\n' '  ' <<<"$out" | head -c 200)"
	check "$b: su to root with an empty password is refused" \
		eval "! grep -q SU_GOT_ROOT <<<\"\$out\" && ! grep -qx 'rc=0' <<<\"\$out\""
	# The same su must work when root is asked for nothing (the agent is root): the check
	# above must not pass only because su or script is missing.
	ok=$(vm "$b" 'script -qec "su -c \"echo SU_GOT_ROOT\" root" /dev/null </dev/null 2>&1')
	check "$b: (control) su as root itself works, so the refusal above is PAM's" grep -q SU_GOT_ROOT <<<"$ok"
done
finish
