# SPDX-License-Identifier: Apache-2.0
# python.sh: sourced (bash) by every script that runs Python; sets and exports CCOMM_PYTHON,
# the one interpreter of the tests and tools: Debian's /usr/bin/python3, not the first
# python3 on PATH. scripts/setup installs the modules the tests import as Debian packages
# (python3-numpy, python3-pytest, ...), which only Debian's interpreter sees; a pyenv or
# venv python3 earlier on PATH does not (docs/testing.md, "Which Python"). A CCOMM_PYTHON
# the caller sets wins: a choice made on purpose, not by PATH. Not checked here: on a fresh
# machine scripts/setup installs python3 after this is read.
: "${CCOMM_PYTHON:=/usr/bin/python3}"
export CCOMM_PYTHON
# Packages installed with pip --user would be seen too and differ per machine.
export PYTHONNOUSERSITE=1
