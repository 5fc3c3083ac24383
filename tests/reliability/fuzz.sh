#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Bounded fuzzing: every libFuzzer target in scripts/fuzz (wire decoder, config parser),
# FUZZ_SECONDS each (default 20), built with clang + ASan/UBSan in FUZZ_BUILD_DIR
# (default build/fuzz). A crash, leak, timeout or sanitizer report fails the test; the
# reproducer is left in FUZZ_BUILD_DIR/fuzz-work/<target>/artifacts/. Long runs: see
# docs/reliability.md.
source "$(dirname "$0")/lib.sh"
command -v clang++ >/dev/null || skip_all "needs clang (libFuzzer)"
export FUZZ_SECONDS=${FUZZ_SECONDS:-20}
"$ROOT/scripts/fuzz" >"$WORK/fuzz.log" 2>&1
rc=$?
grep '^fuzz: ' "$WORK/fuzz.log" | sed 's/^fuzz: /# figure: fuzz: /'
for t in $(grep -o 'running [a-z0-9_]*' "$WORK/fuzz.log" | awk '{print $2}'); do
  if grep -q "FAILED:.*$t" "$WORK/fuzz.log" || ! grep -q "^fuzz: $t stat::number_of_executed_units" "$WORK/fuzz.log"; then
    not_ok "$t: ${FUZZ_SECONDS}s without a finding"
  else
    ok "$t: ${FUZZ_SECONDS}s without a finding ($(sed -n "s/^fuzz: $t stat::number_of_executed_units: *//p" "$WORK/fuzz.log") inputs)"
  fi
done
[[ $rc -eq 0 ]] || { tail -n 40 "$WORK/fuzz.log" | sed 's/^/# /'; not_ok "scripts/fuzz exit status $rc"; }
finish
