"""``crr.poincare``: the sections, sweeps and basins of ``crr poincare``, from Python.

The data files are the command line's to the byte (the same library functions write them), and a
free-rocking block's crossing section is checked against Housner's closed form: between two
upward crossings of θ = 0 the block impacts twice, each impact multiplying |θ̇| by
r = 1 − (3/2) sin²α (the angular momentum about the new edge, I_O = (4/3) m R²), and the first
crossing's rate follows from the energy of the fall from θ₀."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

import crr
from conftest import ROOT, run_cli

BLOCK = "examples/models/single_block.toml"


def test_a_section_is_the_command_lines_to_the_byte(cli, in_root, tmp_path):
    out = tmp_path / "cli"
    args = ["--amplitude", "4", "--frequency", "2", "--periods", "20", "--transient", "10", "--rest"]
    run_cli(cli, ["poincare", BLOCK, *args, "--out", str(out), "--quiet"])
    section = crr.poincare(BLOCK, 4.0, 2.0, periods=20, transient=10, rest=True)
    assert section.kind == "section"
    assert section.csv == (out / "poincare.csv").read_text()
    cli_summary = json.loads((out / "poincare.json").read_text())
    assert section.summary == cli_summary
    frame = section.frame()
    assert list(frame["k"]) == list(range(11, 31))
    assert frame["base_state"].dtype == object
    assert set(frame["base_state"]) <= {"seated", "+", "-"}
    written = tmp_path / "py"
    section.write(written)
    assert (written / "poincare.csv").read_text() == section.csv
    assert json.loads((written / "poincare.json").read_text()) == cli_summary


def test_a_sweep_given_as_numbers_or_as_text_is_the_same_and_the_command_lines(cli, in_root, tmp_path):
    out = tmp_path / "cli"
    run_cli(
        cli,
        ["poincare", BLOCK, "--frequency", "2", "--amplitudes", "0.3g:0.5g:3", "--periods", "5",
         "--transient", "5", "--rest", "--jobs", "2", "--out", str(out), "--quiet"],
    )
    as_text = crr.poincare(BLOCK, frequency=2.0, amplitudes="0.3g:0.5g:3", periods=5, transient=5, rest=True)
    g = 9.80665
    as_numbers = crr.poincare(
        BLOCK, frequency=2.0, amplitudes=(0.3 * g, 0.5 * g, 3), periods=5, transient=5, rest=True, jobs=1
    )
    assert as_text.kind == "bifurcation"
    assert as_text.csv == (out / "bifurcation.csv").read_text()
    assert as_numbers.frame()["amplitude"].unique() == pytest.approx([0.3 * g, 0.4 * g, 0.5 * g], rel=1e-15)
    assert as_numbers.frame()["base"].to_numpy() == pytest.approx(as_text.frame()["base"].to_numpy(), rel=1e-12)
    assert len(as_text.summary["cases"]) == 3


def test_basins_read_their_outcomes_as_text(in_root):
    basins = crr.poincare(
        BLOCK, 2.0, 1.0, periods=2, transient=0, grid=((-0.1, 0.1, 2), (0.0, 0.5, 2)), jobs=1
    )
    assert basins.kind == "basins"
    frame = basins.frame()
    assert len(frame) == 4
    assert frame["outcome"].dtype == object
    assert set(frame["outcome"]) <= {"settles", "orbits", "overturns", "fails"}
    # A case that did not overturn has no overturning time: NaN, not the text "".
    bounded = frame[frame["outcome"] != "overturns"]
    assert bounded["overturn_time"].isna().all()


def test_a_free_rocking_blocks_crossings_lose_r_squared_at_each_return(in_root):
    """The bundled block (b = 0.2 m, h = 1 m) released at rest from θ₀ = 0.1 rad."""
    b, h, theta0, gravity = 0.2, 1.0, 0.1, 9.81
    alpha = math.atan(b / h)
    radius = math.hypot(b, h)
    r = 1.0 - 1.5 * math.sin(alpha) ** 2
    fall = math.sqrt(1.5 * gravity / radius * (math.cos(alpha - theta0) - math.cos(alpha)))
    section = crr.poincare(BLOCK, amplitude=0.0, periods=6, transient=0)
    assert section.summary["settings"]["section"] == {"kind": "crossing", "coordinate": "base"}
    frame = section.frame()
    assert len(frame) == 6
    # The first upward crossing comes after two impacts (down on +, back on −).
    expected = [fall * r ** (2 * k) for k in range(1, 7)]
    # The integrator's rtol (1e-10) on each flight and the located impact instants.
    assert frame["base_rate"].to_numpy() == pytest.approx(expected, rel=1e-8)
    assert frame["base"].abs().max() < 1e-12  # at θ = 0, after the impact
    assert (frame["t"].diff().dropna() > 0).all()


def test_wrong_arguments_are_named_as_pythons_keywords(in_root):
    with pytest.raises(crr.InputError, match=r"^frequency must be a frequency > 0 \(Hz\), got -1"):
        crr.poincare(BLOCK, 4.0, -1.0)
    with pytest.raises(crr.InputError, match=r"amplitude and amplitudes cannot be given together"):
        crr.poincare(BLOCK, 4.0, 2.0, amplitudes=(1, 2, 3))
    with pytest.raises(crr.InputError, match=r"give one of amplitudes, frequencies and grid"):
        crr.poincare(BLOCK, frequency=2.0, amplitudes=(1, 2, 3), grid="0:0.1:2,0:1:2")
    with pytest.raises(crr.InputError, match=r"section: no coordinate named \"nope\""):
        crr.poincare(BLOCK, 4.0, 2.0, section="nope")
    with pytest.raises(crr.InputError, match=r"periods must be an integer ≥ 1, got 0"):
        crr.poincare(BLOCK, 4.0, 2.0, periods=0)
    with pytest.raises(crr.InputError, match=r"amplitudes must be \(start, end, count\)"):
        crr.poincare(BLOCK, frequency=2.0, amplitudes=(1, 2))
    with pytest.raises(crr.MissingFileError):
        crr.poincare(Path(ROOT) / "examples" / "models" / "no_such_model.toml", 4.0, 2.0)
