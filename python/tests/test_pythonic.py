"""Python-worded arguments: numpy values wherever numbers or lists go, ``jobs=-1`` for one
thread per core, direct construction of a Model refused with the constructors named, and every
key of ``[analysis]`` accepted as a keyword (the list comes from the engine's own table)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import crr

ROOT = Path(__file__).resolve().parents[2]
BLOCK = ROOT / "examples" / "models" / "single_block.toml"
AT_REST = {"angles": {"base": 0.0}}


def test_numpy_values_in_a_dict_model_and_tables() -> None:
    d = crr.Model.from_file(BLOCK).to_dict()
    d["body"][0]["density"] = np.float64(2500.0)
    d["body"][0]["box"]["size"] = np.array([0.4, 0.4, 2.0])
    model = crr.Model.from_dict(d)
    plain = crr.Model.from_file(BLOCK)
    assert model.to_dict() == plain.to_dict()
    a = crr.simulate(model, initial={"angles": {"base": np.float64(0.1)}}, duration=np.float64(2.0),
                     rtol=np.float64(1e-10))
    b = crr.simulate(plain, initial={"angles": {"base": 0.1}}, duration=2.0, rtol=1e-10)
    np.testing.assert_array_equal(a.q, b.q)


def test_jobs_minus_one_is_one_thread_per_core() -> None:
    study = crr.Study.from_file(ROOT / "examples" / "studies" / "block_spectrum.toml")
    ids = study.case_ids[:4]
    assert study.run_rows(ids, jobs=-1) == study.run_rows(ids, jobs=1)
    for bad in (0, -2, 1.5, True):
        with pytest.raises(crr.InputError, match="jobs must be a positive integer, or -1"):
            study.run_rows(ids, jobs=bad)


def test_a_model_is_built_by_its_constructors() -> None:
    with pytest.raises(TypeError, match="crr.Model.from_file"):
        crr.Model("examples/models/single_block.toml")  # type: ignore[arg-type]


def test_every_analysis_key_is_a_keyword() -> None:
    defaults = {"output_interval": 0.01, "rtol": 1e-10, "method": "dop853", "max_impacts": 1000}
    for key in crr._crr.ANALYSIS_KEYS:
        if key in defaults:
            crr.simulate(BLOCK, duration=0.5, **{key: defaults[key]})
    assert set(defaults) <= set(crr._crr.ANALYSIS_KEYS)
    assert "duration" in crr._crr.ANALYSIS_KEYS


def test_a_missing_file_is_a_file_not_found_error_with_its_name() -> None:
    import errno
    import pickle

    record = crr.Record.from_file("no/such.AT2", format="peer-at2")
    with pytest.raises(FileNotFoundError) as info:
        crr.simulate(BLOCK, ground_motion=record)
    e = info.value
    assert isinstance(e, crr.FileError) and isinstance(e, crr.MissingFileError)
    assert e.errno == errno.ENOENT
    assert e.filename == "no/such.AT2"
    assert str(e).startswith("no/such.AT2: cannot read the file")
    back = pickle.loads(pickle.dumps(e))
    assert type(back) is type(e) and str(back) == str(e)
    assert (back.errno, back.filename) == (e.errno, e.filename)
    with pytest.raises(FileNotFoundError) as model:
        crr.Model.from_file("no/such.toml")
    assert model.value.filename == "no/such.toml"
    # A record the model names, missing where its folder puts it: the same kind of error, with
    # the model and the item in its message (as `crr simulate` prints it).
    text = (ROOT / "examples" / "models" / "block_record.toml").read_text()
    named = crr.Model.from_toml(text, base_dir=ROOT / "no" / "folder", label="block_record.toml")
    with pytest.raises(FileNotFoundError) as info:
        crr.simulate(named)
    e = info.value
    assert isinstance(e, crr.MissingFileError) and e.errno == errno.ENOENT
    assert Path(e.filename) == ROOT / "no" / "folder" / ".." / "records" / "synthetic.AT2"
    assert str(e).startswith("block_record.toml: ground_motion.x.record: ")


def test_a_run_that_cannot_fit_in_memory_is_refused_before_it_starts() -> None:
    # Under a 3 GB address-space limit, 2e5 s at 0.01 s would need some 3.4 GB of samples: the
    # interpreter used to die in an allocation (exit 134); now a MemoryError says why, at once.
    import subprocess
    import sys

    code = (
        "import resource, crr\n"
        "resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))\n"
        "try:\n"
        f"    crr.simulate({str(BLOCK)!r}, duration=2e5)\n"
        "except MemoryError as e:\n"
        "    print(type(e).__name__, e)\n"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("OutOfMemoryError "), p.stdout
    assert "output_interval" in p.stdout


def test_a_control_groups_memory_limit_counts(tmp_path: Path) -> None:
    # A container's limit (cgroup v2) that MemAvailable does not see: the least of what the
    # group and the groups above it leave, their page cache (inactive_file) counted as free;
    # no limit ("max") and no file leave None.
    from crr import _cgroup_memory_left

    def group(root: Path, path: str, names: tuple, limit: str, used: int, cache: int = 0) -> None:
        folder = root / path
        folder.mkdir(parents=True, exist_ok=True)
        (folder / names[0]).write_text(limit + "\n")
        (folder / names[1]).write_text(f"{used}\n")
        (folder / "memory.stat").write_text(f"anon 1\n{names[2]} {cache}\nfile 2\n")

    v2 = ("memory.max", "memory.current", "inactive_file")
    group(tmp_path / "v2", "", v2, "max", 5 << 30)
    group(tmp_path / "v2", "jobs", v2, str(4 << 30), 3 << 30)
    group(tmp_path / "v2", "jobs/run", v2, str(2 << 30), 1 << 30, cache=512 << 20)
    membership = tmp_path / "cgroup"
    membership.write_text("0::/jobs/run\n")
    left = _cgroup_memory_left(str(tmp_path / "v2"), str(membership))
    assert left == float(1 << 30)  # the parent's 4 GiB − 3 GiB, below the job's 2 − 0.5 GiB
    membership.write_text("0::/\n")
    assert _cgroup_memory_left(str(tmp_path / "v2"), str(membership)) is None
    # At its limit with no cache: nothing left, which is a number, not "unknown".
    group(tmp_path / "full", "", v2, str(2 << 30), 2 << 30)
    assert _cgroup_memory_left(str(tmp_path / "full"), str(membership)) == 0.0
    # cgroup v1: the memory controller's group and the groups above it; an unset limit is a
    # huge number.
    v1 = ("memory.limit_in_bytes", "memory.usage_in_bytes", "total_inactive_file")
    group(tmp_path / "v1" / "memory", "batch", v1, str(3 << 30), 1 << 30)
    group(tmp_path / "v1" / "memory", "batch/step", v1, "9223372036854771712", 1 << 30)
    membership.write_text("12:cpu,cpuacct:/batch/step\n11:memory:/batch/step\n")
    assert _cgroup_memory_left(str(tmp_path / "v1"), str(membership)) == float(2 << 30)
    (tmp_path / "v1" / "memory" / "batch" / "memory.limit_in_bytes").write_text("9223372036854771712\n")
    assert _cgroup_memory_left(str(tmp_path / "v1"), str(membership)) is None
    assert _cgroup_memory_left(str(tmp_path / "none"), str(tmp_path / "missing")) is None
    # A membership file that is not UTF-8 is read, not raised.
    membership.write_bytes(b"0::/jobs/\xff\n")
    assert _cgroup_memory_left(str(tmp_path / "v2"), str(membership)) == float(1 << 30)


def test_a_sample_limit_stops_the_run_with_its_results() -> None:
    with pytest.raises(crr.SimulationError, match="more than 100 output samples") as info:
        crr.simulate(BLOCK, duration=20.0, max_samples=100)
    partial = info.value.result
    assert 100 < len(partial.t) <= 100 + 4096 + 2 * len(partial.impacts)
    full = crr.simulate(BLOCK, duration=20.0)
    n = len(partial.t) - 1
    np.testing.assert_array_equal(partial.q[:n], full.q[:n])
    with pytest.raises(crr.InputError, match="max_samples must be a positive integer"):
        crr.simulate(BLOCK, duration=1.0, max_samples=0)


def test_stop_at_violation_ends_the_run_at_its_first_violation() -> None:
    # The bundled drum column fails the hypotheses at 0.5028 s (a pull of bed_7 just after an
    # impact, measured to 0.50292 s); the run that stops there is the full run cut there.
    column = ROOT / "examples" / "models" / "drum_column.toml"
    full = crr.simulate(column, duration=1.0)
    with pytest.warns(crr.CrrWarning):
        cut = crr.simulate(column, duration=1.0, stop_at_violation=True)
    violation = cut.summary["hypothesis_violation"]
    assert violation == full.summary["hypothesis_violation"]
    assert cut.completed and cut.summary["solver"]["stop_at_violation"]
    end = cut.summary["end_time"]
    assert violation["time"] <= end < violation["time"] + 0.05
    assert full.summary["end_time"] == 1.0
    n = int(np.searchsorted(cut.t, end))
    assert n > 40
    np.testing.assert_array_equal(cut.t[:n], full.t[:n])
    np.testing.assert_array_equal(cut.q[:n], full.q[:n])


def test_a_dict_model_error_names_the_key_path() -> None:
    d = crr.Model.from_file(BLOCK).to_dict()
    d["body"][0]["densty"] = d["body"][0].pop("density")
    with pytest.raises(crr.InputError, match=r"body\[0\]\.densty: unknown field `densty`"):
        crr.Model.from_dict(d)


def test_a_record_column_vector_is_one_series() -> None:
    t = np.linspace(0.0, 0.5, 101)
    a = 4.0 * np.sin(4.0 * np.pi * t)
    flat = crr.simulate(BLOCK, ground_motion=(t, a), initial=AT_REST, duration=2.0)
    column = crr.simulate(
        BLOCK, ground_motion=(t.reshape(-1, 1), a.reshape(-1, 1)), initial=AT_REST, duration=2.0
    )
    np.testing.assert_array_equal(flat.q, column.q)
    with pytest.raises(crr.InputError, match=r"a must be one series of samples, got an array of shape \(101, 2\)"):
        crr.Record.from_arrays(t, np.stack([a, a], axis=1))


def test_record_argument_errors_name_the_python_arguments() -> None:
    at2 = str(ROOT / "examples" / "records" / "synthetic.AT2")
    cases = [
        (crr.Record.from_file(at2, format="xyz"), r"^record format: "),
        (crr.Record.from_file(at2, format="peer-at2", component="w"), r"^record component: "),
        (crr.Record.from_file(at2, format="peer-at2", scale=float("nan")), r"^record scale must be finite"),
        (
            crr.Record.from_file(at2, format=None),  # type: ignore[arg-type]
            r"^Record\.from_file needs format='peer-at2', 'csv' or 'text'$",
        ),
    ]
    for record, message in cases:
        with pytest.raises(crr.InputError, match=message):
            crr.simulate(BLOCK, ground_motion=record, duration=1.0)


def test_numbers_that_are_not_finite_are_named_where_they_are() -> None:
    """JSON has no NaN or infinity: a Python value holding one is refused naming its place, where
    the engine's parser would report a position in a text the user never wrote."""
    nan = float("nan")
    with pytest.raises(crr.InputError, match=r"^analysis\.rtol: nan is not a finite number$"):
        crr.simulate(BLOCK, rtol=nan, duration=1.0)
    with pytest.raises(crr.InputError, match=r"^initial\.angles\.base: inf is not a finite number$"):
        crr.simulate(BLOCK, initial={"angles": {"base": float("inf")}}, duration=1.0)
    d = crr.Model.from_file(BLOCK).to_dict()
    d["body"][0]["density"] = np.float64(nan)
    with pytest.raises(crr.InputError, match=r"^<dict>: body\[0\]\.density: nan is not a finite number$"):
        crr.Model.from_dict(d)
    d = crr.Model.from_file(BLOCK).to_dict()
    d["body"][0]["box"]["size"] = np.array([0.4, nan, 2.0])
    with pytest.raises(crr.InputError, match=r"^<dict>: body\[0\]\.box\.size\[1\]: nan is not a finite number$"):
        crr.Model.from_dict(d)
    # A 2-D array by its row and column; an array of Python objects as the lists it holds.
    polygon = np.array([[-0.2, 0.0, 0.0], [0.2, 0.0, 0.0], [0.2, 0.0, 2.0], [-0.2, 0.0, nan]])
    prism = {"name": "p", "body": [{"name": "b", "density": 2000.0,
                                    "prism": {"polygon": polygon, "extrude": [0.0, 0.4, 0.0]}}],
             "interface": []}
    with pytest.raises(crr.InputError, match=r"^<dict>: body\[0\]\.prism\.polygon\[3\]\[2\]: nan"):
        crr.Model.from_dict(prism)
    prism["body"][0]["prism"]["polygon"] = polygon.astype(object)
    with pytest.raises(crr.InputError, match=r"^<dict>: body\[0\]\.prism\.polygon\[3\]\[2\]: nan"):
        crr.Model.from_dict(prism)
    with pytest.raises(crr.InputError, match=r"^ground_motion\.x\.sine\.amplitude: nan"):
        crr.simulate(BLOCK, ground_motion={"x": {"sine": {"amplitude": nan, "period": 1.0}}}, duration=1.0)


def test_two_records_for_one_component_are_refused() -> None:
    """Each record replaces its component of the ground motion: a second record for the same
    component would silently replace the first (two files were already refused)."""
    t = np.linspace(0.0, 1.0, 101)
    a = np.sin(2.0 * np.pi * t)
    x1 = crr.Record.from_arrays(t, a, units="g")
    x2 = crr.Record.from_arrays(t, 2.0 * a, units="g")
    with pytest.raises(crr.InputError, match=r"^ground_motion: two records drive component 'x'"):
        crr.simulate(BLOCK, ground_motion=[x1, x2], duration=1.0)
    y = crr.Record.from_arrays(t, a, units="g", component="y")
    # The block is planar (hinge about y): the y record is carried bilaterally, and said so.
    with pytest.warns(crr.CrrWarning, match="part along the hinges' common axis"):
        both = crr.simulate(BLOCK, ground_motion=[x1, y], duration=1.0)
    assert both.summary["ground_motion"]["pga"][:2] == pytest.approx([9.80665, 9.80665], rel=1e-3)


def test_a_model_edited_through_its_dict_keeps_its_records() -> None:
    """``to_dict`` → edit → ``from_dict(d, base_dir=model.base_dir)``: the record the model names
    by a relative path is still found, and the edit takes effect (a denser block has the same
    angles under the same record: the rocking equation depends on the shape only)."""
    model = crr.Model.from_file(ROOT / "examples" / "models" / "block_record.toml")
    assert model.base_dir == ROOT / "examples" / "models"
    d = model.to_dict()
    d["body"][0]["density"] = 2.0 * d["body"][0]["density"]
    edited = crr.Model.from_dict(d, base_dir=model.base_dir)
    a = crr.simulate(model, duration=3.0)
    b = crr.simulate(edited, duration=3.0)
    np.testing.assert_allclose(b.q, a.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.kinetic, 2.0 * a.kinetic, rtol=1e-9, atol=1e-9)
