#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Simulink S-functions without MATLAB: the harness calls the mdl* callbacks of the MEX
# and code-generation builds against a real ccommd and checks the blocks' outputs.
# Usage: test.sh CCOMM_BIN_DIR [INTEGRATION_BIN_DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=$(cd "${1:?usage: test.sh CCOMM_BIN_DIR [INTEGRATION_BIN_DIR]}" && pwd)
ibin=$(cd "${2:-$1}" && pwd)
source "$here/../lib.sh"
it_start_ccommd "$bin" "$here/harness/signals.xml" sim
"$ibin/ccomm_simulink_harness" sim
