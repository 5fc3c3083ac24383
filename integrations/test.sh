#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds and runs every tool integration against a real ccommd from BUILD_DIR:
#   20-sim C-code target and 4C component (20sim/test.sh), Simulink S-functions
#   (simulink/test.sh), and the Python package (pip install ./python, mypy, pytest).
# Usage: integrations/test.sh BUILD_DIR   (a configured ccomm CMake build directory)
# If BUILD_DIR was configured without integrations/ (no add_subdirectory yet), the C
# pieces are built standalone in BUILD_DIR/integrations-standalone against its libccomm.
# Needs python3 with venv, and PyPI for the Python test dependencies (cached in
# BUILD_DIR/integrations-venv). Exit status 0 only if every part passed.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../scripts/python.sh"  # Debian's Python, not PATH's (docs/testing.md, "Which Python")
repo=$(cd "$here/.." && pwd)
B=$(cd "${1:?usage: integrations/test.sh BUILD_DIR}" && pwd)
jobs=${JOBS:-2}
passed=0
failed=0
failed_parts=()

part() {  # part NAME CMD...: runs one part, counts it
  local name=$1
  shift
  echo
  echo "######## $name"
  if "$@"; then
    passed=$((passed + 1))
    echo "######## $name: PASS"
  else
    failed=$((failed + 1))
    failed_parts+=("$name")
    echo "######## $name: FAIL"
  fi
}

build() {
  local core=(ccomm ccommd ccomm_cli)
  local integ=(ccomm_20sim_pdcontroller ccomm_20sim_vectorgain ccomm_20sim_steporder ccomm_20sim_pd_check
               ccomm_20sim_4c_harness ccomm_simulink_harness)
  if cmake --build "$B" --target help 2>/dev/null | grep -q ccomm_simulink_harness; then
    cmake --build "$B" -j "$jobs" --target "${core[@]}" "${integ[@]}" || return 1
    ibin=$B/bin
  else
    echo "(BUILD_DIR has no integration targets: building them standalone)"
    cmake --build "$B" -j "$jobs" --target "${core[@]}" || return 1
    cmake -S "$here" -B "$B/integrations-standalone" -DCCOMM_BUILD_DIR="$B" >/dev/null || return 1
    cmake --build "$B/integrations-standalone" -j "$jobs" || return 1
    ibin=$B/integrations-standalone/bin
  fi
}

python_tests() {
  local venv=$B/integrations-venv
  if [ ! -x "$venv/bin/python" ]; then
    "$CCOMM_PYTHON" -m venv "$venv" || { echo "python3 -m venv failed (Debian: apt-get install python3-venv)"; return 1; }
  fi
  "$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$repo/python/requirements-test.txt" || return 1
  # Exactly what the docs tell users: pip install ./python (a fresh copy each run).
  (cd "$repo" && "$venv/bin/python" -m pip install -q --disable-pip-version-check --force-reinstall --no-deps ./python) || return 1
  rm -rf "$repo/python/build" "$repo/python/src/ccomm.egg-info"
  (cd "$repo/python" && "$venv/bin/python" -m mypy src/ccomm examples/centroid_setpoints.py) || return 1
  (cd "$repo/python" && CCOMM_BUILD_DIR=$B "$venv/bin/python" -m pytest -q -p no:cacheprovider tests) || return 1
}

ibin=""
part "build" build
if [ -n "$ibin" ]; then
  part "20-sim (C-code target, 4C component)" bash "$here/20sim/test.sh" "$B/bin" "$ibin"
  part "Simulink S-functions (harness)" bash "$here/simulink/test.sh" "$B/bin" "$ibin"
fi
part "Python package" python_tests

echo
[ "$failed" = 0 ] || echo "failed: ${failed_parts[*]}"
echo "integrations: $passed passed, $failed failed"
[ "$failed" = 0 ]
