"""Fixtures of the Python tests: the repository root and the ``crr`` command line they compare
against (``CRR_BIN``, else the release or debug build of the target folder, else built here with
``cargo build --release --bin crr``)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path
from typing import List

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _find_cli() -> Path:
    env = os.environ.get("CRR_BIN")
    if env:
        return Path(env)
    targets = [Path(os.environ["CARGO_TARGET_DIR"])] if "CARGO_TARGET_DIR" in os.environ else []
    targets.append(ROOT / "target")
    for t in targets:
        for profile in ("release", "debug"):
            exe = t / profile / "crr"
            if exe.is_file():
                return exe
    cargo = shutil.which("cargo")
    if cargo is None:
        raise RuntimeError("no crr binary: set CRR_BIN or build it with `cargo build --release`")
    subprocess.run([cargo, "build", "--release", "--bin", "crr"], cwd=ROOT, check=True)
    return _find_cli()


@pytest.fixture(scope="session")
def cli() -> Path:
    return _find_cli()


@pytest.fixture()
def in_root(monkeypatch: pytest.MonkeyPatch) -> Path:
    """Runs the test in the repository root, where the command line is run too, so that paths
    (echoed in summaries and rows) are the same strings."""
    monkeypatch.chdir(ROOT)
    return ROOT


def run_cli(cli: Path, args: List[str], expect: int = 0) -> subprocess.CompletedProcess:
    p = subprocess.run([str(cli), *args], cwd=ROOT, capture_output=True, text=True)
    assert p.returncode == expect, f"crr {args}: exit {p.returncode}\n{p.stderr}"
    return p
