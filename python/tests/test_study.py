"""Studies from Python equal `crr study`'s cases.csv byte for byte: run locally (in memory or
into a folder), from a file or a dict, and spread over a Dask LocalCluster of two processes."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pandas as pd
import pytest

import crr
from conftest import ROOT, run_cli


def small_map(folder: Path) -> Path:
    """A 6 × 6 overturning map of Housner's block (36 cases, 4 s each)."""
    text = (
        'name = "small_map"\n'
        f'model = "{(ROOT / "examples/models/single_block.toml").as_posix()}"\n'
        "duration = 4.0\n\n[pulses]\nkind = \"one_sine_pulse\"\n"
        "amplitude_ratios = { from = 1.5, to = 6.0, count = 6 }\n"
        "frequency_ratios = { from = 1.0, to = 8.0, count = 6 }\n"
    )
    path = folder / "small_map.toml"
    path.write_text(text)
    return path


def records_study() -> dict:
    """Two synthetic records × three PGA levels on the drum column (6 cases), as a dict."""
    return {
        "name": "drums",
        "model": (ROOT / "examples/models/drum_column.toml").as_posix(),
        "duration": 6.0,
        "records": {"synthetic": {"seeds": [1, 2]}},
        "intensity": {"pga": [0.1, 0.25, 0.4]},
    }


def cli_cases(cli, study: Path, out: Path) -> str:
    run_cli(cli, ["study", str(study), "--out", str(out), "--quiet"])
    return (out / "cases.csv").read_text()


def test_a_study_equals_the_command_lines_cases_csv(cli, tmp_path):
    study = small_map(tmp_path)
    expected = cli_cases(cli, study, tmp_path / "cli")
    # Housner's block keeps every hypothesis on this map: no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error", crr.CrrWarning)
        frame = crr.study(study, jobs=2)
    assert frame["violation_time_s"].isna().all()
    assert frame.attrs["cases_csv"] == expected
    assert list(frame.columns) == expected.splitlines()[0].split(",")
    assert len(frame) == 36
    assert set(frame["status"]) == {"ok"}
    assert frame["collapse"].sum() > 0 and (frame["collapse"] == 0).sum() > 0
    # Its text columns are text though every case ran cleanly (all empty: read alone, a float64
    # of NaN that refuses `.str`), and `collapse` a nullable integer.
    assert frame["error"].isna().all() and frame["violation_interface"].isna().all()
    assert not frame["error"].str.contains("failed").fillna(False).any()
    assert frame["error"].dtype == object and frame["violation"].dtype == object
    assert str(frame["collapse"].dtype) == "Int64"
    # The DataFrame holds the file's numbers exactly.
    again = crr.cases_frame((tmp_path / "cli" / "cases.csv").read_text())
    for column in ("amplitude_m_s2", "peak_base_rad", "dissipated_j"):
        exact = [float(line.split(",")[again.columns.get_loc(column)]) for line in
                 expected.splitlines()[1:]]
        assert again[column].tolist() == exact
    pd.testing.assert_frame_equal(frame, again, check_exact=True)
    # Into a folder, as `crr study --out` (study.json too).
    out = tmp_path / "py"
    folder = crr.study(study, out=out)
    assert (out / "cases.csv").read_text() == expected
    assert json.loads((out / "study.json").read_text())["cases_run"] == 36
    assert folder.attrs["cases_csv"] == expected


def test_a_study_as_a_dict_and_its_rows_in_chunks(cli, tmp_path):
    d = records_study()
    path = tmp_path / "drums.toml"
    path.write_text(
        f'name = "drums"\nmodel = "{d["model"]}"\nduration = 6.0\n'
        "[records]\nsynthetic = { seeds = [1, 2] }\n[intensity]\npga = [0.1, 0.25, 0.4]\n"
    )
    expected = cli_cases(cli, path, tmp_path / "cli")
    s = crr.Study.from_dict(d)
    assert len(s) == 6 and s.name == "drums"
    rows = s.run_rows(s.case_ids[3:], jobs=1) + s.run_rows(s.case_ids[:3], jobs=1)
    assert s.csv(rows) == expected
    # Both records make a bed of the column pull at 0.4 g, and the first at 0.25 g too (the
    # drums above fly): the rows say so, and the frame comes with the command line's warning.
    with pytest.warns(crr.CrrWarning, match="3 of the 6 case\\(s\\) left crr's model") as told:
        frame = crr.study(d)
    # With it the warning that duration = 6 s cuts the 20 s records: every one points at the
    # caller.
    assert len(told) == 2 and all(w.filename == __file__ for w in told), [str(w.message) for w in told]
    assert any("before their ground motion does" in str(w.message) for w in told)
    with pytest.warns(crr.CrrWarning) as told:
        s.run()
    assert told and all(w.filename == __file__ for w in told)
    assert frame.attrs["cases_csv"] == expected
    outside = frame[frame["violation_time_s"].notna()]
    assert sorted(outside["pga_g"].round(9).tolist()) == [0.25, 0.4, 0.4]
    assert set(outside["violation"]) == {"tension"}
    # The file's text, read as if it were tmp_path/study.toml (the model path is absolute).
    with pytest.warns(crr.CrrWarning, match="left crr's model"):
        assert crr.study(path.read_text()).attrs["cases_csv"] == expected


def test_bad_studies_raise_with_the_command_lines_message(cli, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        f'model = "{(ROOT / "examples/models/single_block.toml").as_posix()}"\n'
        "[pulses]\nkind = \"one_sine_pulse\"\namplitudes = [1.0]\nperiods = [0.0]\n"
    )
    p = run_cli(cli, ["study", str(bad), "--out", str(tmp_path / "o")], expect=2)
    with pytest.raises(crr.InputError) as e:
        crr.study(bad)
    assert p.stderr == f"crr: error: {e.value}\n"
    with pytest.raises(crr.InputError, match="no case"):
        crr.Study.from_file(small_map(tmp_path)).run_rows(["c999999"])


def test_a_dask_local_cluster_reproduces_the_study(cli, tmp_path):
    distributed = pytest.importorskip("distributed")
    import crr.dask

    study = small_map(tmp_path)
    expected = cli_cases(cli, study, tmp_path / "cli")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        frame = crr.dask.run_study(study, client, chunk_size=5, out=tmp_path / "dask")
        workers = client.run(lambda: __import__("os").getpid())
        assert len(set(workers.values())) == 2
        with pytest.warns(crr.CrrWarning, match="3 of the 6 case"):
            by_dict = crr.dask.run_study(records_study(), client, chunk_size=2)
        # distributed.progress draws its bar while the tasks run and changes no row.
        shown = crr.dask.run_study(study, client, chunk_size=5, progress=True)
    assert shown.attrs["cases_csv"] == expected
    assert frame.attrs["cases_csv"] == expected
    assert (tmp_path / "dask" / "cases.csv").read_text() == expected
    assert len(frame) == 36
    with pytest.warns(crr.CrrWarning, match="left crr's model"):
        local = crr.study(records_study())
    assert by_dict.attrs["cases_csv"] == local.attrs["cases_csv"]


def test_progress_shows_on_stderr_and_changes_no_row(tmp_path, capfd):
    spec = Path(__file__).resolve().parents[2] / "examples" / "studies" / "block_spectrum.toml"
    study = crr.Study.from_file(spec)
    plain = crr.study(study, jobs=2)
    capfd.readouterr()
    shown = crr.study(study, jobs=2, progress=True)
    err = capfd.readouterr().err
    assert shown.attrs["cases_csv"] == plain.attrs["cases_csv"]
    assert "100/100" in err, err
    folder = crr.study(study, jobs=2, out=tmp_path / "s", progress=True)
    err = capfd.readouterr().err
    assert "crr: study [" in err and "100/100 cases" in err, err
    assert folder.attrs["cases_csv"] == plain.attrs["cases_csv"]


def test_without_pandas_the_frames_say_which_extra_installs_it(monkeypatch, tmp_path):
    # pandas made unimportable: every DataFrame says so, naming the extra, and crr.dask.run_study
    # says it before any case runs (no client is needed to get there).
    import builtins

    real_import = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas" or name.startswith("pandas."):
            raise ImportError("No module named 'pandas'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_pandas)
    import crr.dask

    result = crr.simulate(
        crr.Model.from_file(Path(__file__).resolve().parents[2] / "examples/models/single_block.toml"),
        duration=0.1,
    )
    for call, what in (
        (result.history_frame, "Result.history_frame"),
        (result.impacts_frame, "Result.impacts_frame"),
        (lambda: crr.dask.run_study(small_map(tmp_path), client=None), "crr.dask.run_study"),
        (lambda: crr.cases_frame("id\n"), "a study's DataFrame"),
    ):
        with pytest.raises(ImportError, match=f"{what} needs pandas.*crr-rocking\\[pandas\\]"):
            call()


def test_a_study_without_pandas_is_refused_before_any_case_runs(monkeypatch, tmp_path):
    """``crr.study`` returns a DataFrame: without pandas it used to run every case and then raise
    ImportError, losing the rows. Now it raises before any runs (the rows without pandas are
    :meth:`Study.run_rows`)."""
    import builtins

    study = crr.Study.from_file(small_map(tmp_path))
    real_import = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas" or name.startswith("pandas."):
            raise ImportError("No module named 'pandas'")
        return real_import(name, *args, **kwargs)

    ran = []
    monkeypatch.setattr(type(study), "run_rows", lambda self, *a, **k: ran.append(1) or [])
    monkeypatch.setattr(builtins, "__import__", no_pandas)
    with pytest.raises(ImportError, match="needs pandas"):
        crr.study(study)
    assert ran == []


def test_a_study_cut_short_and_its_failed_cases_are_warnings(tmp_path):
    """A `duration` shorter than a record is warned before any case runs (the case is cut
    there: 1.5 × the bundled 20 s record overturns the block at 6.93 s, and cut at 5 s it
    stands), and a case that stopped with an error is warned with the count, as `crr study`
    prints both on stderr."""
    study = {
        "model": (ROOT / "examples/models/block_record.toml").as_posix(),
        "duration": 5.0,
        "records": {
            "files": [(ROOT / "examples/records/synthetic.AT2").as_posix(), "missing.AT2"],
            "format": "peer-at2",
        },
        "intensity": {"factors": [1.5]},
    }
    with pytest.warns(crr.CrrWarning) as caught:
        frame = crr.study(crr.Study.from_dict(study, base_dir=tmp_path))
    messages = [str(w.message) for w in caught]
    assert any(
        "duration = 5 s ends 1 of the 2 case(s) before their ground motion does (the latest ends "
        "at t = 20 s)" in m
        for m in messages
    ), messages
    assert any("1 of the 2 case(s) stopped with an error" in m for m in messages), messages
    assert list(frame.columns[:4]) == ["id", "record", "factor", "status"]
    assert list(frame["status"]) == ["ok", "error"]
    assert int(frame["collapse"].iloc[0]) == 0
    study.pop("duration")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        full = crr.study(crr.Study.from_dict(study, base_dir=tmp_path))
    messages = [str(w.message) for w in caught]
    assert not any("before their ground motion" in m for m in messages), messages
    assert int(full["collapse"].iloc[0]) == 1
    assert 5.0 < float(full["collapse_time_s"].iloc[0]) < 20.0
