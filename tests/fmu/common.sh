# SPDX-License-Identifier: Apache-2.0
# Shared by tests/fmu/run and tests/fmu/bench (sourced after tests/reliability/lib.sh):
# FMPy pinned in a venv, and the test FMUs packed as source FMUs and built by ccomm-fmu build.
# ---- FMPy, pinned (with the versions of what it pulls in) -------------------------------
FMPY_PINS=(fmpy==0.3.32 attrs==26.1.0 cmake==4.4.5 fastjsonschema==2.22.3 Jinja2==3.1.6 jsonschema==4.26.0
           jsonschema-specifications==2025.9.1 jupyter_core==5.9.1 lark==1.3.1 lxml==6.1.3 MarkupSafe==3.0.4
           msgpack==1.2.4 nbformat==5.11.1 numpy==2.4.6 platformdirs==4.14.8 referencing==0.37.0 rpds-py==2026.9.1
           traitlets==5.16.1 typing_extensions==4.16.0)
venv=${FMPY_VENV:-$ROOT/.cache/fmpy-venv}
if ! "$venv/bin/python" -c 'import fmpy, sys; sys.exit(fmpy.__version__ != "0.3.32")' 2>/dev/null; then
  "$CCOMM_PYTHON" -m venv "$venv" &&
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps "${FMPY_PINS[@]}" ||
    skip_all "cannot install FMPy from PyPI into $venv"
fi
PY=$venv/bin/python
FMPY_DIR=$("$PY" -c 'import fmpy, os; print(os.path.dirname(fmpy.__file__))')
note "FMPy $("$PY" -c 'import fmpy; print(fmpy.__version__)') at $FMPY_DIR"
FMU=$BIN/ccomm-fmu

# ---- source FMUs, compiled by ccomm-fmu build ------------------------------------------
source_fmu() {  # source_fmu NAME MAJOR: $WORK/NAME.fmu with sources/ and no binaries/
  local name=$1 major=$2 d=$WORK/src-$1
  mkdir -p "$d/sources"
  cp "$FMU_TEST_DIR/$name/modelDescription.xml" "$d/"
  cp "$FMU_TEST_DIR/$name/$name.c" "$d/sources/"
  [[ $major == 3 ]] && cp "$FMU_TEST_DIR/fmi3_trivial.h" "$d/sources/"  # #included by the FMI 3.0 models
  [[ -f $FMU_TEST_DIR/$name/buildDescription.xml ]] && cp "$FMU_TEST_DIR/$name/buildDescription.xml" "$d/sources/"
  "$PY" "$FMU_TEST_DIR/gen_unsupported.py" "$FMPY_DIR/c-code" "$major" "$d/sources/$name.c" "$d/sources/unsupported.c"
  (cd "$d" && zip -q -r "$WORK/$name.fmu" .)
}
build_fmus() {  # build_fmus NAME:MAJOR...: each one a TAP line
  local spec name
  for spec in "$@"; do
    name=${spec%:*}
    source_fmu "$name" "${spec#*:}"
    if "$FMU" build "$WORK/$name.fmu" --fmi-include "$FMPY_DIR/c-code" 2>"$WORK/build-$name.log" &&
      [[ $(unzip -Z1 "$WORK/$name.fmu") == *binaries/*/$name.so* ]]; then
      ok "ccomm-fmu build $name (FMI ${spec#*:}.0 source FMU, host compiler) adds its binary"
    else
      not_ok "ccomm-fmu build $name (FMI ${spec#*:}.0 source FMU)"
      sed 's/^/#   /' "$WORK/build-$name.log"
    fi
  done
}

