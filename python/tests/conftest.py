# pytest fixtures for pyrcb4: the in-process virtual board, `rcb4 serve --pty`, and the stand-in
# boards of tests/integration (silent, NACK, bad checksums) for the failures.
# SPDX-License-Identifier: BSL-1.0
import os
import subprocess
import sys

import pytest

# Under ASan the sanitizer runtime is preloaded into this Python (python.pytest_asan); the rcb4 tool
# it starts carries its own: the preload is for this process only.
PRELOAD = os.environ.pop("LD_PRELOAD", None)  # for a test's own Python subprocess (test_services.py)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "integration"))


def pytest_addoption(parser):
    parser.addoption("--rcb4", default=os.environ.get("RCB4", "rcb4"), help="the rcb4 tool (for rcb4 serve)")


@pytest.fixture(autouse=True)
def _in_a_temporary_directory(tmp_path, monkeypatch):
    """Every test runs in its own directory: a backup a call makes (motion-N-DATE.bin) lands there, never in the tree."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("RCB4_SLOT_NAMES", str(tmp_path / "slot-names.yaml"))  # names a push keeps, per test


@pytest.fixture(scope="session")
def rcb4_tool(request):
    return request.config.getoption("--rcb4")


@pytest.fixture
def served(rcb4_tool):
    """A device path: `rcb4 serve --pty` for the duration of the test."""
    srv = subprocess.Popen([rcb4_tool, "serve", "--pty"], stdout=subprocess.PIPE, text=True)
    try:
        yield srv.stdout.readline().strip()
    finally:
        srv.terminate()
        srv.wait(timeout=10)


@pytest.fixture(params=["in-process", "served"])
def board(request, rcb4_tool):
    """Every API test runs twice: on the in-process virtual board, and on `rcb4 serve --pty` by its path."""
    import pyrcb4
    if request.param == "in-process":
        with pyrcb4.Board() as b:
            yield b
        return
    srv = subprocess.Popen([rcb4_tool, "serve", "--pty"], stdout=subprocess.PIPE, text=True)
    try:
        with pyrcb4.Board(srv.stdout.readline().strip()) as b:
            yield b
    finally:
        srv.terminate()
        srv.wait(timeout=10)
