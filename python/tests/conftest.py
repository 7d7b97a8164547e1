"""Fixtures of the Python tests: the repository root and the ``crr`` command line they compare
against (``CRR_BIN``, else the release or debug build of the target folder, else built here with
``cargo build --release --bin crr``, which is announced before it starts). The report header names
the command line and the ``crr`` package imported."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import List, Optional, Tuple

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _find_cli() -> Tuple[Path, str]:
    """The command line and where it came from."""
    env = os.environ.get("CRR_BIN")
    if env:
        return Path(env), "CRR_BIN"
    targets = [Path(os.environ["CARGO_TARGET_DIR"])] if "CARGO_TARGET_DIR" in os.environ else []
    targets.append(ROOT / "target")
    for t in targets:
        for profile in ("release", "debug"):
            exe = t / profile / "crr"
            if exe.is_file():
                return exe, f"the {profile} build in {t}"
    cargo = shutil.which("cargo")
    if cargo is None:
        raise RuntimeError("no crr binary: set CRR_BIN or build it with `cargo build --release`")
    # Said before it starts: a first build takes minutes.
    print(
        "crr tests: no crr command line found (CRR_BIN, target/release, target/debug): building "
        "it with `cargo build --release --bin crr`",
        file=sys.__stderr__,
        flush=True,
    )
    subprocess.run([cargo, "build", "--release", "--bin", "crr"], cwd=ROOT, check=True)
    exe, _ = _find_cli()
    return exe, "built now with `cargo build --release --bin crr`"


_CLI: Optional[Tuple[Path, str]] = None


def _cli() -> Tuple[Path, str]:
    global _CLI
    if _CLI is None:
        _CLI = _find_cli()
    return _CLI


def pytest_report_header(config: pytest.Config) -> str:
    """The first lines of the run say which command line the tests compare against, and which
    ``crr`` package they import (the installed wheel, not the source folder)."""
    import crr

    exe, origin = _cli()
    return f"crr command line: {exe} ({origin}); crr package: {Path(crr.__file__).parent}"


@pytest.fixture(scope="session")
def cli() -> Path:
    return _cli()[0]


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
