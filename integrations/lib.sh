# SPDX-License-Identifier: Apache-2.0
# Helpers for the integration test scripts (sourced). Every test runs its own ccommd on a
# private segment name (CCOMM_SHM_PREFIX) and stops exactly the processes it started.
. "$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/scripts/python.sh"  # Debian's Python, not PATH's (docs/testing.md, "Which Python")

export CCOMM_SHM_PREFIX="/ccomm-it-$$-"
_it_pids=()
_it_nodes=()

it_cleanup() {
  local p n
  for p in "${_it_pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${_it_pids[@]}"; do wait "$p" 2>/dev/null || true; done
  for n in "${_it_nodes[@]}"; do rm -f "/dev/shm/${CCOMM_SHM_PREFIX#/}$n"; done
  _it_pids=()
}
trap it_cleanup EXIT

# it_start_ccommd BIN_DIR CONFIG NODE: starts ccommd, waits until its segment answers.
it_start_ccommd() {
  local bin=$1 config=$2 node=$3 i
  "$bin/ccommd" --config "$config" --node "$node" --no-rt --transport udp -q &
  _it_pids+=($!)
  _it_nodes+=("$node")
  for i in $(seq 100); do
    "$bin/ccomm" --node "$node" list >/dev/null 2>&1 && return 0
    sleep 0.1
  done
  echo "ccommd for node $node did not start" >&2
  return 1
}

# it_bg CMD...: starts CMD in the background, remembered for cleanup; sets IT_PID.
it_bg() {
  "$@" &
  IT_PID=$!
  _it_pids+=("$IT_PID")
}

# it_stop PID: SIGTERM and wait; sets IT_RC to the exit code.
it_stop() {
  kill -TERM "$1" 2>/dev/null || true
  IT_RC=0
  wait "$1" || IT_RC=$?
}
