"""The Python package computes what the command line computes, to the last digit: every bundled
model's history, impact log and summary; records from files and from arrays; check and inspect
reports; and the command line's error messages."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest

import crr
from conftest import ROOT, run_cli

MODELS = sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "examples/models").glob("*.toml"))


def read_history(path: Path, dof: int, interfaces: int):
    """history.csv parsed back: the numbers (exact: the file holds shortest round-trip text) and
    the state columns."""
    lines = path.read_text().splitlines()
    numbers = np.array(
        [[float(x) for x in line.split(",")[: 1 + 2 * dof + 4]] for line in lines[1:]]
    ).reshape(len(lines) - 1, 1 + 2 * dof + 4)
    states = [line.split(",")[1 + 2 * dof + 4 :] for line in lines[1:]]
    assert all(len(s) == interfaces for s in states)
    return lines[0], numbers, states


def assert_same_run(result: crr.Result, out: Path) -> None:
    history = (out / "history.csv").read_text()
    assert result.history_csv() == history
    assert result.impacts_csv() == (out / "impacts.csv").read_text()
    assert result.openings_csv() == (out / "openings.csv").read_text()
    assert result.hops_csv() == (out / "hops.csv").read_text()
    summary = json.loads((out / "summary.json").read_text())
    assert result.summary == summary
    dof = len(result.coordinates)
    header, numbers, states = read_history(out / "history.csv", dof, len(result.interfaces))
    assert header.split(",")[: 1 + dof] == ["t", *result.coordinates]
    # The arrays equal the file's numbers exactly (np.array_equal, no tolerance).
    assert np.array_equal(result.t, numbers[:, 0])
    assert np.array_equal(result.q, numbers[:, 1 : 1 + dof])
    assert np.array_equal(result.qdot, numbers[:, 1 + dof : 1 + 2 * dof])
    for k, name in enumerate(["kinetic", "potential", "work_in", "dissipated"]):
        assert np.array_equal(result.energies[name], numbers[:, 1 + 2 * dof + k])
    assert result.states.tolist() == states
    assert len(result.impacts) == summary["impacts"]
    lines = (out / "impacts.csv").read_text().splitlines()[1:]
    for record, line in zip(result.impacts, lines):
        t, interfaces, before, after, lost, opened = line.split(",")
        assert record["t"] == float(t)
        assert record["interfaces"] == interfaces.split(";")
        assert record["rates_before"] == [float(x) for x in before.split(";")]
        assert record["rates_after"] == [float(x) for x in after.split(";")]
        assert record["energy_lost"] == float(lost)
        assert record["opened"] == [s for s in opened.split(";") if s]


@pytest.mark.parametrize("model", MODELS)
def test_every_bundled_model_runs_as_the_command_line(model, cli, in_root, tmp_path):
    out = tmp_path / "cli"
    if model.endswith("temple.toml"):
        # The temple's run stops when the entablature lifts off a capital (outside the CRR chain): the
        # command line writes the partial results and exits with 1, Python raises
        # SimulationError holding the same partial run.
        run_cli(cli, ["simulate", model, "--out", str(out), "--quiet"], expect=1)
        with pytest.raises(crr.SimulationError, match="lift") as failure:
            crr.simulate(crr.Model.from_file(model))
        result = failure.value.result
        assert not result.completed
    else:
        run_cli(cli, ["simulate", model, "--out", str(out), "--quiet"])
        result = crr.simulate(crr.Model.from_file(model))
        assert result.completed
    assert len(result.t) > 10
    assert_same_run(result, out)


def test_a_record_file_as_the_record_option(cli, in_root, tmp_path):
    out = tmp_path / "cli"
    args = ["--record", "examples/records/synthetic.AT2", "--format", "peer-at2", "--scale", "1.5"]
    model = "examples/models/single_block.toml"
    run_cli(cli, ["simulate", model, "--out", str(out), "--quiet", "--duration", "8", *args])
    record = crr.Record.from_file(
        "examples/records/synthetic.AT2", format="peer-at2", scale=1.5
    )
    result = crr.simulate(model, ground_motion=record, duration=8)
    assert result.summary["record"]["scale"] == 1.5
    assert len(result.impacts) > 0
    assert_same_run(result, out)


def test_a_record_from_arrays_equals_the_same_numbers_in_a_csv_file(cli, in_root, tmp_path):
    # A decaying 2 Hz ground shaking in cm/s², written with Python's shortest round-trip repr.
    t = np.arange(0, 401) * 0.01
    a = 600.0 * np.sin(2 * np.pi * 2.0 * t) * np.exp(-0.5 * t)
    csv = tmp_path / "record.csv"
    csv.write_text("t,a\n" + "".join(f"{x!r},{y!r}\n" for x, y in zip(t.tolist(), a.tolist())))
    out = tmp_path / "cli"
    model = "examples/models/two_block_stack.toml"
    run_cli(
        cli,
        ["simulate", model, "--out", str(out), "--quiet", "--record", str(csv), "--format",
         "csv", "--units", "cm/s2", "--component", "x", "--scale", "0.8"],
    )
    result = crr.simulate(
        model, ground_motion=crr.Record.from_arrays(t, a, units="cm/s2", scale=0.8)
    )
    assert len(result.impacts) > 0
    history = (out / "history.csv").read_text()
    assert result.history_csv() == history
    assert result.impacts_csv() == (out / "impacts.csv").read_text()
    summary = json.loads((out / "summary.json").read_text())
    # Only the echo of the record file differs: the arrays have none.
    assert summary.pop("record")["file"] == str(csv)
    got = dict(result.summary)
    assert got.pop("record") is None
    assert got == summary


def test_the_offsets_of_open_faces_are_those_of_the_command_line(cli, in_root, tmp_path):
    # The bundled wall under a pulse of 10 m/s²: faces lift off, and openings.csv lists them.
    model = crr.Model.from_file("examples/models/wall.toml")
    d = model.to_dict()
    d["ground_motion"] = {"x": {"one_sine_pulse": {"amplitude": 10.0, "period": 0.5}}}
    path = tmp_path / "wall_pulse.json"
    path.write_text(json.dumps(d))
    out = tmp_path / "cli"
    run_cli(cli, ["simulate", str(path), "--out", str(out), "--quiet", "--duration", "1"])
    result = crr.simulate(model, ground_motion=d["ground_motion"], duration=1.0)
    text = result.openings_csv()
    assert text == (out / "openings.csv").read_text()
    assert result.history_csv() == (out / "history.csv").read_text()
    # Result.write writes the same files as the command line.
    result.write(tmp_path / "py")
    for name in ("history.csv", "impacts.csv", "hops.csv", "openings.csv"):
        assert (tmp_path / "py" / name).read_text() == (out / name).read_text()
    # summary.json in the command line's own text (numbers as 1e-6, not Python's 1e-06), but for
    # the integrator's counts, which differ between the two ways of running, and the file the
    # command line read (this test's copy of the model).
    def without_stats(text: str) -> list:
        lines = text.splitlines()
        start = lines.index('  "solver_stats": {')
        end = lines.index("  },", start)
        kept = lines[:start] + lines[end + 1:]
        return [line for line in kept if not line.startswith('  "model_file": ')]

    py_summary = (tmp_path / "py" / "summary.json").read_text()
    assert without_stats(py_summary) == without_stats((out / "summary.json").read_text())
    assert "1e-06" not in py_summary and py_summary.endswith("}\n")
    rows = text.splitlines()
    assert rows[0] == "row,t,interface,dx,dy,dz"
    assert len(rows) > 10
    # Each row names a face that history.csv reports open at that row.
    history = (out / "history.csv").read_text().splitlines()
    header = history[0].split(",")
    for line in rows[1:]:
        row, t, interface, *_ = line.split(",")
        fields = history[int(row)].split(",")
        assert float(fields[0]) == float(t)
        assert fields[header.index(f"{interface}_state")] == "open"


def test_a_model_as_text_or_dict_runs_as_its_file(in_root):
    path = ROOT / "examples/models/trilithon.toml"
    a = crr.simulate(crr.Model.from_file(path))
    b = crr.simulate(crr.Model.from_toml(path.read_text()))
    c = crr.simulate(crr.Model.from_dict(crr.Model.from_file(path).to_dict()))
    for r in (b, c):
        assert r.history_csv() == a.history_csv()
        assert r.impacts_csv() == a.impacts_csv()


def test_tables_replaced_from_python_match_a_model_file_with_them(cli, in_root, tmp_path):
    # The same changes written into a model file and run by the command line.
    model = crr.Model.from_file("examples/models/single_block.toml")
    d = model.to_dict()
    d["initial"] = {"angles": {"base": 0.05}, "rates": {"base": 0.3}}
    d["analysis"] = dict(d.get("analysis") or {}, rtol=1e-9, output_interval=0.02)
    d["ground_motion"] = {"x": {"sine": {"amplitude": 1.5, "frequency": 1.0}}}
    path = tmp_path / "changed.json"
    path.write_text(json.dumps(d))
    out = tmp_path / "cli"
    run_cli(cli, ["simulate", str(path), "--out", str(out), "--quiet", "--duration", "6"])
    result = crr.simulate(
        model,
        ground_motion=d["ground_motion"],
        initial=d["initial"],
        duration=6.0,
        rtol=1e-9,
        output_interval=0.02,
    )
    assert result.history_csv() == (out / "history.csv").read_text()
    assert result.impacts_csv() == (out / "impacts.csv").read_text()
    summary = json.loads((out / "summary.json").read_text())
    assert summary.pop("model_file") == str(path)
    got = dict(result.summary)
    assert got.pop("model_file") == "examples/models/single_block.toml"
    assert got == summary


@pytest.mark.parametrize("model", ["examples/models/trilithon.toml", "examples/models/arch.toml"])
def test_check_is_the_command_lines_json(model, cli, in_root):
    p = run_cli(cli, ["check", model, "--json"])
    report = crr.Model.from_file(model).check()
    assert report == json.loads(p.stdout)
    assert report["mechanism"] is not None


def test_inspect_is_the_command_lines_json_with_numpy_arrays(cli, in_root):
    model = "examples/models/arch.toml"
    m = crr.Model.from_file(model)
    name = m.coordinates[0]
    p = run_cli(cli, ["inspect", model, "--json", "--q", f"{name}=0.01"])
    expected = json.loads(p.stdout)
    got = m.inspect({name: 0.01})
    assert isinstance(got["mass_matrix"], np.ndarray)
    n = len(m.coordinates)
    assert got["mass_matrix"].shape == (n, n)
    assert "constraint_jacobian" in got  # the arch is a closed chain
    for key, value in got.items():
        if isinstance(value, np.ndarray):
            assert np.array_equal(value, np.array(expected[key])), key
        else:
            assert value == expected[key], key
    # The same configuration as a vector.
    q = np.zeros(n)
    q[0] = 0.01
    assert np.array_equal(m.inspect(q)["mass_matrix"], got["mass_matrix"])


def cli_error(p) -> str:
    """The command line's message: stderr after `crr: error: `."""
    assert p.stderr.startswith("crr: error: "), p.stderr
    return p.stderr[len("crr: error: ") :].rstrip("\n")


def test_bad_inputs_raise_with_the_command_lines_message(cli, in_root, tmp_path):
    bad = tmp_path / "bad.toml"
    text = (ROOT / "examples/models/single_block.toml").read_text()
    bad.write_text(text.replace('name = "', 'nmae = "', 1))
    p = run_cli(cli, ["simulate", str(bad), "--out", str(tmp_path / "o")], expect=2)
    with pytest.raises(crr.InputError) as e:
        crr.Model.from_file(bad)
    assert str(e.value) == cli_error(p)
    assert isinstance(e.value, ValueError) and isinstance(e.value, crr.CrrError)

    missing = tmp_path / "missing.toml"
    p = run_cli(cli, ["check", str(missing)], expect=2)
    with pytest.raises(crr.FileError) as f:
        crr.Model.from_file(missing)
    assert str(f.value) == cli_error(p)
    assert isinstance(f.value, OSError)

    model = "examples/models/single_block.toml"
    p = run_cli(cli, ["inspect", model, "--q", "nope=0.1"], expect=2)
    with pytest.raises(crr.InputError) as g:
        crr.Model.from_file(model).inspect({"nope": 0.1})
    assert str(g.value) == cli_error(p)

    # Argument errors name the Python argument, not the command line's option.
    p = run_cli(cli, ["simulate", model, "--duration=-1", "--out", str(tmp_path / "o")], expect=2)
    assert "--duration must be a positive number of seconds" in cli_error(p)
    with pytest.raises(crr.InputError) as h:
        crr.simulate(model, duration=-1)
    assert str(h.value) == "duration must be a positive number of seconds, got -1"

    args = ["--record", "examples/records/synthetic.AT2", "--format", "peer-at2"]
    args += ["--units", "cm/s2"]
    p = run_cli(cli, ["simulate", model, "--out", str(tmp_path / "o"), *args], expect=2)
    rec = crr.Record.from_file("examples/records/synthetic.AT2", format="peer-at2", units="cm/s2")
    with pytest.raises(crr.InputError) as r:
        crr.simulate(model, ground_motion=rec)
    assert str(r.value) == cli_error(p)

    with pytest.raises(TypeError, match="unexpected keyword argument 'rtoll'.*rtol"):
        crr.simulate(model, rtoll=1e-9)
    with pytest.raises(TypeError, match="unexpected keyword argument 'groundmotion'"):
        crr.simulate(model, groundmotion=None)
    with pytest.raises(crr.InputError, match="strictly increasing"):
        crr.simulate(model, ground_motion=([0.0, 0.0, 1.0], [0.0, 1.0, 0.0]))


def test_a_run_that_fails_part_way_raises_with_its_partial_results(cli, in_root, tmp_path):
    d = crr.Model.from_file("examples/models/single_block.toml").to_dict()
    d["analysis"] = dict(d.get("analysis") or {}, max_impacts=5)
    path = tmp_path / "few_impacts.json"
    path.write_text(json.dumps(d))
    out = tmp_path / "cli"
    p = run_cli(cli, ["simulate", str(path), "--out", str(out), "--quiet"], expect=1)
    with pytest.raises(crr.SimulationError) as e:
        crr.simulate(crr.Model.from_file(path))
    assert isinstance(e.value, RuntimeError)
    assert cli_error(p) == f'{e.value} (partial results written to {out}, "completed": false)'
    partial = e.value.result
    assert not partial.completed
    assert_same_run(partial, out)


def test_a_model_pickles_and_runs_the_same(in_root):
    import pickle

    model = crr.Model.from_file("examples/models/two_block_stack.toml")
    copy = pickle.loads(pickle.dumps(model))
    assert copy.source == model.source and copy.coordinates == model.coordinates
    assert crr.simulate(copy).history_csv() == crr.simulate(model).history_csv()


def test_the_exceptions_are_the_packages_and_pickle():
    import pickle

    with pytest.raises(crr.InputError) as e:
        crr.Model.from_toml('name = "x"\n[[body]]\nname = "b"\n')
    assert type(e.value).__qualname__ == "InputError" and type(e.value).__module__ == "crr"
    assert str(e.value).startswith("<string>: ")
    copy = pickle.loads(pickle.dumps(e.value))
    assert type(copy) is crr.InputError and str(copy) == str(e.value)


def test_summary_warnings_are_python_warnings_with_the_command_lines_text(cli, in_root, tmp_path):
    import warnings

    # rtol = 1e-3 is loose: the command line warns, and so does Python, with the same text.
    model = "examples/models/single_block.toml"
    d = crr.Model.from_file(model).to_dict()
    d["analysis"] = dict(d.get("analysis") or {}, rtol=1e-3)
    path = tmp_path / "loose.json"
    path.write_text(json.dumps(d))
    p = run_cli(cli, ["simulate", str(path), "--out", str(tmp_path / "o"), "--quiet", "--duration", "2"])
    printed = [line[len("crr: warning: ") :] for line in p.stderr.splitlines() if line.startswith("crr: warning: ")]
    assert printed and any("rtol" in w for w in printed), p.stderr
    with pytest.warns(crr.CrrWarning) as caught:
        result = crr.simulate(model, duration=2.0, rtol=1e-3)
    assert [str(w.message) for w in caught] == printed == result.summary["warnings"]
    # A clean run warns nothing; warnings can be made errors.
    with warnings.catch_warnings():
        warnings.simplefilter("error", crr.CrrWarning)
        crr.simulate(model, duration=2.0)
        with pytest.raises(crr.CrrWarning, match="rtol"):
            crr.simulate(model, duration=2.0, rtol=1e-3)


def test_check_warnings_are_python_warnings_with_the_command_lines_text(cli, in_root, tmp_path):
    import math
    import warnings

    # The single block turned by 0.3 rad about x: its hinge axis rises 17.2° from the horizontal,
    # which `crr check` warns about; Python issues the same text as a CrrWarning.
    c, s = math.cos(0.3), math.sin(0.3)

    def turn(x, y, z):
        return [x, y * c - z * s, y * s + z * c]

    text = (
        'name = "tilted_block"\ngravity = 9.81\n[[body]]\nname = "block"\ndensity = 2500.0\n'
        f"box = {{ center = {turn(0.0, 0.0, 1.0)}, size = [0.4, 0.4, 2.0], rotation = [0.3, 0.0, 0.0] }}\n"
        '[[interface]]\nname = "base"\nparent = "ground"\nchild = "block"\n'
        f"axis = [0.0, {c!r}, {s!r}]\n"
        f"pivot_positive = [{turn(0.2, -0.2, 0.0)}, {turn(0.2, 0.2, 0.0)}]\n"
        f"pivot_negative = [{turn(-0.2, -0.2, 0.0)}, {turn(-0.2, 0.2, 0.0)}]\n"
    )
    path = tmp_path / "tilted.toml"
    path.write_text(text)
    printed = json.loads(run_cli(cli, ["check", str(path), "--json"]).stdout)["warnings"]
    assert len(printed) == 1 and "17.2° from the horizontal" in printed[0]
    with pytest.warns(crr.CrrWarning) as caught:
        report = crr.Model.from_file(str(path)).check()
    assert [str(w.message) for w in caught] == printed == report["warnings"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", crr.CrrWarning)
        assert crr.Model.from_file("examples/models/single_block.toml").check()["warnings"] == []


def test_an_assembly_is_the_model_the_command_line_writes(cli, in_root, tmp_path):
    """``Model.from_assembly`` is ``crr assemble``: the bundled segmental arch between its fixed
    skewbacks gives the written model's coordinates, interfaces and ``crr check --json`` report,
    λ = 0.754085 along ±x; a ``fixed`` name that is no block is the command line's error."""
    source = "examples/assemblies/segmental_arch.toml"
    written = tmp_path / "segmental_arch_model.toml"
    run_cli(cli, ["assemble", source, "--all-contacts", "--planar", "--out", str(written)])
    model = crr.Model.from_assembly(source, planar=True, all_contacts=True)
    from_file = crr.Model.from_file(written)
    assert model.coordinates == from_file.coordinates
    assert model.interfaces == from_file.interfaces
    report = model.check()
    assert report == json.loads(run_cli(cli, ["check", str(written), "--json"]).stdout)
    along_x = [s for s in report["static_multipliers"] if abs(s["direction"][0]) == 1.0]
    assert len(along_x) == 2
    for side in along_x:
        assert abs(side["lambda"] - 0.754085) < 5e-7
    wrong = tmp_path / "wrong_fixed.toml"
    wrong.write_text(
        Path(source).read_text().replace('"skewback_left"]', '"skewback_west"]'), encoding="utf-8"
    )
    p = run_cli(cli, ["assemble", str(wrong), "--planar", "--all-contacts"], expect=2)
    with pytest.raises(crr.InputError) as error:
        crr.Model.from_assembly(wrong, planar=True, all_contacts=True)
    assert str(error.value) == p.stderr.strip().removeprefix("crr: error: ")
    assert 'fixed: no block is named "skewback_west"' in str(error.value)


def test_an_assemblys_near_miss_is_the_command_lines_warning(cli, in_root, tmp_path):
    """A column of the bundled trilithon of stones drawn 0.5 mm short is no support of the
    architrave: ``Model.from_assembly`` issues the warning ``crr assemble`` prints, with the gap
    and the tolerance that joins them, and with that tolerance none."""
    import warnings

    source = Path("examples/assemblies/trilithon.toml").read_text(encoding="utf-8")
    short = source.replace(
        "box = { center = [1.5, 0.0, 2.0], size = [0.5, 0.5, 4.0] }",
        "box = { center = [1.5, 0.0, 1.99975], size = [0.5, 0.5, 3.9995] }",
    ).replace("../records/", (ROOT / "examples/records").as_posix() + "/")
    assert short != source
    path = tmp_path / "short.toml"
    path.write_text(short, encoding="utf-8")
    p = run_cli(cli, ["assemble", str(path), "--out", str(tmp_path / "model.toml")])
    printed = [
        line.removeprefix("crr: warning: ")
        for line in p.stderr.splitlines()
        if line.startswith("crr: warning: ")
    ]
    with pytest.warns(crr.CrrWarning) as caught:
        model = crr.Model.from_assembly(path)
    assert [str(w.message) for w in caught] == printed
    assert len(printed) == 1 and "5.000e-4 m apart" in printed[0]
    assert len(model.interfaces) == 3
    with warnings.catch_warnings():
        warnings.simplefilter("error", crr.CrrWarning)
        assert len(crr.Model.from_assembly(path, tolerance=5.5e-4).interfaces) == 4


def test_check_takes_the_command_line_s_options(cli, in_root):
    """``Model.check(direction=…, friction=…, exhaustive_sets=…)`` is ``crr check --json
    --direction … --friction … --exhaustive-sets …``. The bundled trilithon is planar (hinges
    about y): along d = (1, 1, 0)/√2 its multiplier is the in-plane one over the in-plane part
    of d, λ_x/cos 45° = 0.125 √2 (docs/outputs.md, ``out_of_plane``)."""
    path = "examples/models/trilithon.toml"
    model = crr.Model.from_file(path)
    for kwargs, args in [
        ({"direction": "1,1,0"}, ["--direction", "1,1,0"]),
        ({"direction": (1, 1, 0)}, ["--direction", "1,1,0"]),
        ({"direction": ["+x", "-y"], "exhaustive_sets": 16}, ["--direction", "+x", "--direction", "-y", "--exhaustive-sets", "16"]),
        ({"friction": 0.6}, ["--friction", "0.6"]),
    ]:
        printed = json.loads(run_cli(cli, ["check", path, "--json", *args]).stdout)
        assert model.check(**kwargs) == printed, kwargs
    along = model.check(direction=np.array([1.0, 1.0, 0.0]))["static_multipliers"]
    assert len(along) == 1
    assert along[0]["lambda"] == pytest.approx(0.125 * np.sqrt(2.0), rel=1e-9)
    for bad, message in [
        ({"friction": 1e300}, r"^friction must be a number from 0 to 1000"),
        ({"friction": float("nan")}, r"^friction must be a number from 0 to 1000"),
        ({"direction": "0,0,0"}, r"^direction: "),
        ({"direction": "up"}, r"^direction: 'up' is neither"),
        ({"direction": [1, 2]}, r"^direction: expected a name such as '\+x' or three numbers"),
        ({"exhaustive_sets": 0}, r"exhaustive_sets must be a positive integer"),
    ]:
        with pytest.raises(crr.InputError, match=message):
            model.check(**bad)
