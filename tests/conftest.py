"""Fixtures of the end-to-end suite: the `ronap` binary and the repository root."""

import os
import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def ronap_bin() -> str:
    """The `ronap` binary: $RONAP_BIN (scripts/test sets it), else the workspace's release build."""
    path = os.environ.get("RONAP_BIN") or str(ROOT / "target" / "release" / "ronap")
    if not pathlib.Path(path).is_file():
        found = shutil.which("ronap")
        if found is None:
            pytest.fail(f"no ronap binary at {path}: build it with `cargo build --release -p ronap-cli`")
        path = found
    return path


@pytest.fixture(scope="session")
def root() -> pathlib.Path:
    """The repository root (shipped policies and golden files are relative to it)."""
    return ROOT


@pytest.fixture(autouse=True)
def _sb3_logs_in_tmp_path(tmp_path, monkeypatch):
    """Stable-Baselines3 makes a log folder for every `learn()` (the guides' and README's blocks
    train), in the system's temporary folder unless $SB3_LOGDIR says otherwise: keep them in the
    test's own folder, which pytest clears."""
    monkeypatch.setenv("SB3_LOGDIR", str(tmp_path / "sb3-logs"))
