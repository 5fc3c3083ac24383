# SPDX-License-Identifier: Apache-2.0
"""Only for the wheel that carries libccomm (scripts/package puts the library at
src/ccomm/_lib/libccomm.so.0 in a copy of this directory): that wheel is tagged
py3-none-<platform> because it holds native code, though it works with any Python 3.
Without the library this is the plain pure-Python build; metadata is in pyproject.toml."""
from pathlib import Path

from setuptools import setup
from setuptools.dist import Distribution

BUNDLED = Path(__file__).resolve().parent / "src" / "ccomm" / "_lib" / "libccomm.so.0"
cmdclass = {}
distclass = Distribution
if BUNDLED.is_file():
    from wheel.bdist_wheel import bdist_wheel

    class BinaryDistribution(Distribution):
        """Native code inside: the files go to platlib, at the wheel's root."""

        def has_ext_modules(self) -> bool:
            return True

    distclass = BinaryDistribution

    class PlatformWheel(bdist_wheel):  # type: ignore[misc]
        def finalize_options(self) -> None:
            super().finalize_options()
            self.root_is_pure = False

        def get_tag(self) -> "tuple[str, str, str]":
            _, _, platform = super().get_tag()
            return "py3", "none", platform

    cmdclass["bdist_wheel"] = PlatformWheel

setup(cmdclass=cmdclass, distclass=distclass)
