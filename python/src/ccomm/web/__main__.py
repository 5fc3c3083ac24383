# SPDX-License-Identifier: Apache-2.0
"""python -m ccomm.web: the same as ccomm-web."""
import sys

from .cli import main

sys.exit(main())
