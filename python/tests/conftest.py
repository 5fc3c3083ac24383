# SPDX-License-Identifier: Apache-2.0
"""Starts a private ccommd for the tests: its own segment name (CCOMM_SHM_PREFIX) and UDP
port, so tests run beside a real ccommd and beside each other. Skips everything if no
ccomm build is found (set CCOMM_BUILD_DIR to choose one)."""
from __future__ import annotations

import os
import subprocess
import time
from pathlib import Path
from typing import Callable, Iterator, List, Optional

import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent


def find_build() -> Optional[Path]:
    if os.environ.get("CCOMM_BUILD_DIR"):
        cands = [Path(os.environ["CCOMM_BUILD_DIR"])]
    else:
        # Build trees are build/NAME/ (docs/testing.md); the newest one that has both.
        cands = sorted(REPO.glob("build/*"), key=lambda p: p.stat().st_mtime, reverse=True)
    for b in cands:
        if (b / "bin" / "ccommd").is_file() and (b / "lib" / "libccomm.so").exists():
            return b.resolve()
    return None


@pytest.fixture(scope="session")
def build_dir() -> Path:
    b = find_build()
    if b is None:
        pytest.skip("no ccomm build with bin/ccommd and lib/libccomm.so (set CCOMM_BUILD_DIR)")
    return b


@pytest.fixture(scope="session")
def node(build_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """Runs ccommd for node "pytest" during the session; yields the node name."""
    pid = os.getpid()
    prefix = f"/ccomm-pytest-{pid}."
    os.environ["CCOMM_SHM_PREFIX"] = prefix
    os.environ["CCOMM_LIBRARY"] = str(build_dir / "lib" / "libccomm.so")
    cfg = tmp_path_factory.mktemp("ccomm") / "signals.xml"
    cfg.write_text((HERE / "signals.xml").read_text().replace("UDP_PORT", str(40000 + pid % 20000)))
    log = open(cfg.parent / "ccommd.log", "w")
    proc = subprocess.Popen([str(build_dir / "bin" / "ccommd"), "--config", str(cfg), "--node", "pytest",
                             "--no-rt", "--transport", "udp", "--ptp-socket", "none"], stdout=log, stderr=subprocess.STDOUT)
    import ccomm

    deadline = time.monotonic() + 10
    while True:
        try:
            ccomm.Client("pytest").close()
            break
        except ccomm.NotFoundError:
            if proc.poll() is not None or time.monotonic() > deadline:
                proc.kill()
                raise RuntimeError(f"ccommd did not start; log: {(cfg.parent / 'ccommd.log').read_text()}")
            time.sleep(0.05)
    try:
        yield "pytest"
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
        log.close()
        for name in ("pytest", "pytest.view"):  # the segment and the system view
            seg = Path("/dev/shm") / (prefix.lstrip("/") + name)
            if seg.exists():
                seg.unlink()


@pytest.fixture
def client(node: str) -> Iterator["object"]:
    import ccomm

    with ccomm.Client(node) as c:
        yield c


@pytest.fixture
def own_ccommd(build_dir: Path, node: str, tmp_path: Path) -> Iterator[Callable[..., None]]:
    """A second ccommd for node "pytest" under a prefix and UDP port of its own (the session's
    ccommd is left alone; CCOMM_SHM_PREFIX points at it while the test runs), started on
    signals.xml. Yields restart(old=None, new=None): stops it and starts it again, on the
    same file or with `old` replaced by `new` in it."""
    saved = os.environ["CCOMM_SHM_PREFIX"]
    prefix = f"/ccomm-pytest-own-{os.getpid()}."
    os.environ["CCOMM_SHM_PREFIX"] = prefix
    base = (HERE / "signals.xml").read_text().replace("UDP_PORT", str(20000 + os.getpid() % 20000))
    cfg = tmp_path / "signals.xml"
    cfg.write_text(base)
    log = open(tmp_path / "ccommd.log", "w")
    cmd = [str(build_dir / "bin" / "ccommd"), "--config", str(cfg), "--node", "pytest", "--no-rt",
           "--transport", "udp", "--ptp-socket", "none"]
    procs: List["subprocess.Popen[bytes]"] = [subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)]

    def restart(old: Optional[str] = None, new: Optional[str] = None) -> None:
        procs[-1].terminate()
        procs[-1].wait(timeout=10)
        if old is not None and new is not None:
            cfg.write_text(base.replace(old, new))
        procs.append(subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT))

    try:
        yield restart
    finally:
        for p in procs:
            if p.poll() is None:
                p.terminate()
                p.wait(timeout=10)
        log.close()
        os.environ["CCOMM_SHM_PREFIX"] = saved
        for name in ("pytest", "pytest.view", "pytest.lock"):
            seg = Path("/dev/shm") / (prefix.lstrip("/") + name)
            if seg.exists():
                seg.unlink()
