#!/bin/bash
. "$(dirname "$0")/../lib/common.sh"
s=$(date +%s%N); for i in 1 2 3 4 5; do vm control true; done; e=$(date +%s%N); echo "5 x vm true: $(( (e-s)/1000000 )) ms"
s=$(date +%s%N); vm control 'for i in 1 2 3 4 5 6 7 8 9 10; do /bin/true; done'; e=$(date +%s%N); echo "10 execs in guest: $(( (e-s)/1000000 )) ms"
vm control 'systemd-analyze blame | head -12; systemd-analyze critical-chain | tail -12'
vm --timeout 5 control 'sleep 20'; echo "timeout rc=$?"
vm control 'echo -n no-newline'; vm control 'printf "a\0b\n"'; vm control 'exit 7'; echo "rc=$?"
