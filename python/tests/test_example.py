"""The walkthrough example runs to its end and draws its figures."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from conftest import ROOT


def test_the_walkthrough_runs(tmp_path):
    pytest.importorskip("matplotlib")
    pytest.importorskip("distributed")
    env = dict(os.environ, CRR_EXAMPLE_OUT=str(tmp_path), MPLBACKEND="Agg")
    p = subprocess.run(
        [sys.executable, str(ROOT / "python/examples/walkthrough.py")],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert p.returncode == 0, p.stderr
    assert "peak |θ|/α" in p.stdout
    for figure in ("theta_over_alpha.png", "fragility.png"):
        assert (tmp_path / figure).stat().st_size > 10_000
    cases = (tmp_path / "fragility" / "cases.csv").read_text().splitlines()
    assert len(cases) == 1 + 30
    assert cases[0].startswith("id,record,pga_g,factor,status,collapse")
