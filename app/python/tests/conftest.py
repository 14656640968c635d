"""Shared fixtures for the sylva Python module tests.

CTest runs these from the repository root with PYTHONPATH pointing at the built
module, SYLVA_BINARY at the `sylva` command line and SYLVA_SOURCE_DIR at the repository.
Run by hand:  PYTHONPATH=build-py/python /usr/bin/python3 -m pytest -q app/python/tests
"""
import os
import pathlib
import shutil
import subprocess

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
