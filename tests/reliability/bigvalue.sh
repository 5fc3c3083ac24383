#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Large values under loss: control writes a 64 KiB uint32 array ("path", 47 fragments a
# value) at 100 Hz to planner through tests/reliability/impair.c dropping BIGVALUE_LOSS %
# of the frames (default 1: about 38% of the values lose a fragment). A reader on planner
# checks every value it reads is whole (all elements equal the value's write number and
# its seq: a mix of two values, or a value under the wrong seq, fails). Then the link is
# cleaned and one last value written, and planner's counters must add up exactly:
# rx + lost == values written, with lost > 0 and values_incomplete <= lost, no fragment
# refused (loss is not bad input). Raw Ethernet, then UDP, each with unicast and with
# multicast fan-out (fragments in the producer's group stream, dest 0xFFFF). With the
# allocation counter built (non-sanitizer builds), both ccommd must also make no heap
# allocation in steady state: fragmenting and reassembling use preallocated buffers.
#
#   BIGVALUE_SECONDS (default 5): seconds of writing under loss per transport
#   BIGVALUE_LOSS (default 1): percent of frames dropped
source "$(dirname "$0")/lib.sh"
require_root
require_build
build_tool impair
build_tool bigvalue -I"$ROOT/src/include" -L"$BUILD/lib" -lccomm -Wl,-rpath,"$BUILD/lib"
SECS=${BIGVALUE_SECONDS:-5}
LOSS=${BIGVALUE_LOSS:-1}
RATE=100
COUNT=$((SECS * RATE))
DAEMON_CONFIG=$WORK/bigvalue.xml
COUNTER=$BUILD/lib/ccomm_alloc_counter.so

# sig NODE FIELD: a field of signal "path" from the last `stats NODE`
sig() {
  "$CCOMM_PYTHON" -c 'import json,sys; s=[x for x in json.load(open(sys.argv[1]))["signals"] if x["name"]=="path"][0]
print(s[sys.argv[2]])' "$WORK/stats-$1.json" "$2"
}
jfield() { "$CCOMM_PYTHON" -c 'import json,sys; print(json.loads(sys.argv[1])[sys.argv[2]])' "$1" "$2"; }
imp_dropped() { "$CCOMM_PYTHON" -c 'import json,sys; j=json.loads(sys.argv[1]); print(j["a2b"]["dropped"] + j["b2a"]["dropped"])' "$1"; }

make_impaired_pair
imp_start 11

for mode in raw udp raw-multicast udp-multicast; do
  transport=${mode%%-*}
  fanout=unicast
  [[ $mode = *-multicast ]] && fanout=multicast
  sed -e "s/transport=\"raw\"/transport=\"$transport\"/" -e "s/<network /<network fanout=\"$fanout\" /" \
    "$REL_DIR/bigvalue.xml" >"$DAEMON_CONFIG"
  rm -f /dev/shm/"$TAG".* 2>/dev/null
  for node in control planner; do
    if [[ -f $COUNTER ]]; then
      LD_PRELOAD=$COUNTER CCOMM_ALLOC_REPORT=$WORK/alloc-$mode-$node start_daemon $node
    else
      start_daemon $node
    fi || { not_ok "$mode: ccommd $node starts"; continue 2; }
  done
  spawn "$WORK/reader-$mode.json" planner "$WORK/bigvalue" read planner path --duration $((SECS + 30))
  READER=$!
  # The first value crosses a clean link: it is where the receiver starts counting
  # (rule 6); nothing before it can be known lost.
  w0=$(in_ns control "$WORK/bigvalue" write control path --first 1 --count 1 --rate $RATE)
  sleep 0.2
  imp_before=$(imp stats)
  imp "set loss=$LOSS" >/dev/null
  w1=$(in_ns control "$WORK/bigvalue" write control path --first 2 --count "$COUNT" --rate $RATE)
  sleep 0.2
  imp "set loss=0" >/dev/null
  # So does the last one: every value before it is then received or counted lost.
  w2=$(in_ns control "$WORK/bigvalue" write control path --first $((COUNT + 2)) --count 1 --rate $RATE)
  written=$(( $(jfield "$w0" written) + $(jfield "$w1" written) + $(jfield "$w2" written) ))
  for i in $(seq 100); do
    stats planner
    (( $(sig planner rx) + $(sig planner lost) >= written )) && break
    sleep 0.05
  done
  imp_after=$(imp stats)
  sleep 0.1
  kill -TERM "$READER" 2>/dev/null
  wait "$READER"
  reader_rc=$?
  reader=$(tail -n1 "$WORK/reader-$mode.json")
  stats planner
  stats control
  rx=$(sig planner rx) lost=$(sig planner lost) inc=$(sig planner values_incomplete)
  refused=$(sig planner fragments_refused)
  dropped=$(( $(imp_dropped "$imp_after") - $(imp_dropped "$imp_before") ))
  tx=$(sig control tx) coalesced=$(sig control coalesced)
  sockdrops=$(counter planner socket_drops) senderr=$(counter control send_errors)
  figure "bigvalue $mode: written=$written rx=$rx lost=$lost values_incomplete=$inc" \
         "fragments_refused=$refused frames_dropped=$dropped tx=$tx coalesced=$coalesced" \
         "socket_drops=$sockdrops send_errors=$senderr reader=$reader"
  check "$mode: reader saw only whole values (no torn or mismatched read)" test "$reader_rc" -eq 0
  check "$mode: reader read values" test "$(jfield "$reader" distinct)" -gt 0
  check "$mode: every value written was sent or replaced before sending (tx $tx + coalesced $coalesced == $written)" \
    test $((tx + coalesced)) -eq "$written"
  check "$mode: rx + lost == written exactly ($rx + $lost == $written)" test $((rx + lost)) -eq "$written"
  check "$mode: loss happened (lost > 0, impair dropped $dropped frames)" test "$lost" -gt 0 -a "$dropped" -gt 0
  # Incomplete values and values replaced before sending are both missing at planner.
  check "$mode: values_incomplete + coalesced <= lost ($inc + $coalesced <= $lost)" test $((inc + coalesced)) -le "$lost"
  # A value is lost by a frame impair dropped, one the kernel dropped at a full socket
  # or could not send, or it was replaced at the sender before it left (coalesced: a
  # busy host can delay ccommd by more than the 10 ms period).
  check "$mode: no value lost without a dropped frame or coalescing" \
    test "$lost" -le $((dropped + sockdrops + senderr + coalesced))
  check "$mode: no fragment refused (losses are not bad input)" test "$refused" -eq 0
  check "$mode: the last value arrived" test "$(jfield "$reader" last)" -eq "$written"
  stop_daemon control
  stop_daemon planner
  if [[ -f $COUNTER ]]; then
    for node in control planner; do
      report=$(tr "\n" " " <"$WORK/alloc-$mode-$node" 2>/dev/null)
      check "$mode: ccommd $node allocated nothing in steady state ($report)" \
        test "$(awk '{print $2}' <<<"$report")" = 0 -a "$(awk '{print $4}' <<<"$report")" -gt 10
    done
  fi
done
finish
