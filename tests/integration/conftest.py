# SPDX-License-Identifier: Apache-2.0
import os
import shutil

import pytest

from harness import BIN


def pytest_collection_modifyitems(config, items):
    reason = None
    if os.geteuid() != 0:
        reason = "needs root (network namespaces, raw sockets)"
    elif not shutil.which("ip"):
        reason = "needs iproute2"
    elif not os.path.exists(os.path.join(BIN, "ccommd")):
        reason = "no build at " + BIN + " (set CCOMM_BUILD_DIR)"
    if reason:
        for item in items:
            item.add_marker(pytest.mark.skip(reason=reason))
