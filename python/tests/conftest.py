"""Shared fixtures of the Python tests."""

import signal
import subprocess
import sys
import time

import pytest


@pytest.fixture
def interrupted():
    """``run(code, after=0.5)``: runs the program ``code`` (which prints "start" when ready) in
    a fresh interpreter, sends it SIGINT ``after`` seconds later, and returns (its stdout after
    "start", its stderr, its return code, the seconds from SIGINT to its end). A program started
    in the background ignores SIGINT unless it installs Python's handler: ``code`` must."""
    def run(code, after=0.5, timeout=60):
        p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        try:
            assert p.stdout.readline().strip() == "start"
            time.sleep(after)
            sent = time.perf_counter()
            p.send_signal(signal.SIGINT)
            out, err = p.communicate(timeout=timeout)
            return out, err, p.returncode, time.perf_counter() - sent
        finally:
            if p.poll() is None:
                p.kill()
    return run
