#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Simulink without MATLAB:
#   - the harness calls the mdl* callbacks of the MEX and code-generation builds against a
#     real ccommd and checks the blocks' outputs (double, typed ports, timeout, status);
#   - check_mdl.py parses the block library ccomm_lib.mdl and checks its masks against the
#     S-functions' parameters; it refuses broken copies with FILE:LINE and survives a
#     mutation fuzz run.
# Usage: test.sh CCOMM_BIN_DIR [INTEGRATION_BIN_DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=$(cd "${1:?usage: test.sh CCOMM_BIN_DIR [INTEGRATION_BIN_DIR]}" && pwd)
ibin=$(cd "${2:-$1}" && pwd)
source "$here/../lib.sh"
out=$(mktemp -d)
trap 'it_cleanup; rm -rf "$out"' EXIT
fail=0

echo "== S-functions in the harness (MEX and code-generation builds)"
it_start_ccommd "$bin" "$here/harness/signals.xml" sim
"$ibin/ccomm_simulink_harness" sim || fail=1

echo "== block library ccomm_lib.mdl"
"$CCOMM_PYTHON" "$here/check_mdl.py" "$here/ccomm_lib.mdl" || fail=1
# Broken copies must be refused, each with the line and the reason.
refuse() {  # refuse WHAT SED-EXPRESSION EXPECTED-MESSAGE
  sed "$2" "$here/ccomm_lib.mdl" >"$out/broken.mdl"
  local got
  if got=$("$CCOMM_PYTHON" "$here/check_mdl.py" "$out/broken.mdl" --common "$here/sfun_ccomm_common.h"); then
    echo "FAIL $1: accepted"; fail=1
  elif grep -q -- "$3" <<<"$got"; then
    echo "PASS $1 refused: $(grep -m1 -- "$3" <<<"$got" | sed "s|$out/||")"
  else
    echo "FAIL $1: $got (want $3)"; fail=1
  fi
}
refuse "parameters out of order" '0,/signal,ts,width,node,dtype,timeout,status/s//signal,width,ts,node,dtype,timeout,status/' \
  "differ from the mask variables"
refuse "no timeout parameter" 's/signal,ts,width,node,dtype,timeout,status/signal,ts,width,node,dtype,status/' \
  "no parameter named timeout"
refuse "unclosed section" '$d' "is never closed"
refuse "missing prompt" '0,/Data type|Timeout (s, 0 = only signals.xml decides)|Status output/s//Data type|Status output/' \
  "MaskPromptString has 6 entries for 7 variables"
refuse "unknown data type in the popup" '0,/popup(double|single|int32|uint32|boolean)/s//popup(double|int16)/' \
  "data type popup"
mkdir -p "$out/fuzz"
"$CCOMM_PYTHON" "$here/check_mdl.py" "$here/ccomm_lib.mdl" --fuzz 300 --seed "${CCOMM_FUZZ_SEED:-$RANDOM}" --work "$out/fuzz" || fail=1

if [ "$fail" = 0 ]; then echo "Simulink integration: all checks passed"; else echo "Simulink integration: FAILED"; fi
exit "$fail"
