"""Results, studies and errors pickle, so that ``ProcessPoolExecutor.map`` and Dask's
``client.submit`` can return them: a round trip keeps every array, the summary, the impacts and
the exact text of both CSV files; a study comes back with the same cases and runs to the same
rows; a ``SimulationError`` keeps its message and its partial result."""

from __future__ import annotations

import pickle
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import crr

ROOT = Path(__file__).resolve().parents[2]
BLOCK = ROOT / "examples" / "models" / "block_record.toml"


def _same_result(a: crr.Result, b: crr.Result) -> None:
    for name in ("t", "q", "qdot", "kinetic", "potential", "work_in", "dissipated"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    np.testing.assert_array_equal(a.states, b.states)
    assert a.impacts == b.impacts
    assert a.summary == b.summary
    assert a.coordinates == b.coordinates and a.interfaces == b.interfaces
    assert a.history_csv() == b.history_csv()
    assert a.impacts_csv() == b.impacts_csv()
    assert a.openings_csv() == b.openings_csv()
    assert a.hops_csv() == b.hops_csv()
    # Result.write's summary.json text survives the round trip too.
    assert a._run.summary_json == b._run.summary_json


def _simulate(duration: float) -> crr.Result:
    return crr.simulate(BLOCK, duration=duration)


def test_a_result_pickles_with_its_arrays_and_files() -> None:
    result = crr.simulate(BLOCK, duration=3.0)
    back = pickle.loads(pickle.dumps(result))
    _same_result(result, back)
    # Pickled again after a round trip, it is still the same.
    _same_result(result, pickle.loads(pickle.dumps(back)))


def test_a_process_pool_returns_results() -> None:
    with ProcessPoolExecutor(max_workers=2) as pool:
        remote = list(pool.map(_simulate, [1.0, 2.0]))
    for duration, r in zip([1.0, 2.0], remote):
        _same_result(crr.simulate(BLOCK, duration=duration), r)


def test_a_study_pickles_to_the_same_cases_and_rows(tmp_path: Path) -> None:
    study = crr.Study.from_file(ROOT / "examples" / "studies" / "block_spectrum.toml")
    back = pickle.loads(pickle.dumps(study))
    assert back.case_ids == study.case_ids
    ids = study.case_ids[:5]
    assert back.run_rows(ids, jobs=1) == study.run_rows(ids, jobs=1)
    text = (ROOT / "examples" / "studies" / "block_spectrum.toml").read_text()
    from_text = crr.Study.from_toml(text, base_dir=ROOT / "examples" / "studies")
    assert pickle.loads(pickle.dumps(from_text)).case_ids == study.case_ids


def test_a_simulation_error_pickles_with_its_partial_result() -> None:
    with pytest.raises(crr.SimulationError) as info:
        crr.simulate(BLOCK, duration=5.0, max_impacts=3)
    back = pickle.loads(pickle.dumps(info.value))
    assert str(back) == str(info.value)
    assert isinstance(back, crr.SimulationError)
    _same_result(info.value.result, back.result)


def test_history_columns_are_contiguous_numpy_arrays_equal_to_history_csv(in_root) -> None:
    # The columns cross as bytes read in place: contiguous, float64, equal to the CSV's numbers
    # (printed in the shortest form that reads back to the same f64).
    r = crr.simulate(crr.Model.from_file("examples/models/baldachin.toml"), duration=1.0)
    lines = r.history_csv().splitlines()
    rows = [line.split(",") for line in lines[1:]]
    dof = len(r.coordinates)
    numbers = np.array([[float(v) for v in row[: 1 + 2 * dof + 4]] for row in rows])
    for name, column in (("t", r.t), ("q", r.q), ("qdot", r.qdot), ("kinetic", r.kinetic)):
        assert column.dtype == np.float64 and column.flags.c_contiguous, name
    np.testing.assert_array_equal(r.t, numbers[:, 0])
    np.testing.assert_array_equal(r.q, numbers[:, 1 : 1 + dof])
    np.testing.assert_array_equal(r.qdot, numbers[:, 1 + dof : 1 + 2 * dof])
    np.testing.assert_array_equal(r.dissipated, numbers[:, 1 + 2 * dof + 3])
    # Rocking bases: two slots per interface, joined by "/" (e.g. "seated/+").
    states = [row[1 + 2 * dof + 4 :] for row in rows]
    assert r.states.tolist() == states
    assert any("/" in s for s in r.states[:, 0])
