"""Shared fixtures for the sylva Python module tests.

CTest runs these from the repository root with PYTHONPATH pointing at the built
module, SYLVA_BINARY at the `sylva` command line and SYLVA_SOURCE_DIR at the repository.
Run by hand:  PYTHONPATH=build-py/python /usr/bin/python3 -m pytest -q app/python/tests
"""
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time

import pytest

REPO = pathlib.Path(os.environ.get("SYLVA_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[3]))


@pytest.fixture(scope="session")
def repo():
    """The repository root (presets/, scripts/)."""
    return REPO


@pytest.fixture(autouse=True)
def _at_repo_root(monkeypatch):
    """Relative preset paths (recorded verbatim in skeletons) resolve from the repo root."""
    monkeypatch.chdir(REPO)


@pytest.fixture(scope="session")
def sylva_binary():
    """The `sylva` CLI: required when CTest names it, else skipped."""
    path = os.environ.get("SYLVA_BINARY")
    if not path:
        pytest.skip("SYLVA_BINARY is not set (CTest sets it)")
    assert os.access(path, os.X_OK), f"SYLVA_BINARY={path} is not an executable (build the `sylva` target)"
    return path


@pytest.fixture(scope="session")
def validate_gltf(repo):
    """A function that runs the Khronos validator (scripts/validate_gltf.mjs) on a file."""
    script = repo / "scripts" / "validate_gltf.mjs"
    node = shutil.which("node")
    if not script.exists() or node is None:
        pytest.skip("scripts/validate_gltf.mjs or node is missing")

    def run(path):
        done = subprocess.run([node, str(script), str(path)], capture_output=True, text=True)
        assert done.returncode == 0, done.stdout + done.stderr

    return run


@pytest.fixture
def interrupted(tmp_path):
    """A function that runs `setup` then `call` (Python source) in a child interpreter,
    sends it SIGINT `after_s` seconds into `call`, and asserts that `call` raised
    KeyboardInterrupt (the child exits 7 saying so) rather than finishing or crashing."""

    def run(setup, call, after_s):
        script = tmp_path / "interrupted.py"
        script.write_text(f"import sys, sylva\n{setup}\nprint('started', flush=True)\ntry:\n    {call}\n"
                          "except KeyboardInterrupt:\n    print('interrupted', flush=True)\n    sys.exit(7)\n")
        child = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
        try:
            assert child.stdout.readline().strip() == "started"
            time.sleep(after_s)
            child.send_signal(signal.SIGINT)
            out, _ = child.communicate(timeout=600)  # a hang guard, not a time budget
        finally:
            if child.poll() is None:
                child.kill()
                child.wait()
        assert child.returncode == 7, out
        assert "interrupted" in out

    return run
