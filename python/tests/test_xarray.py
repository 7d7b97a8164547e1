"""``Result.to_xarray()``: the history on its time index with units, the duplicate rows at impacts
documented and removable, and the same numbers as the arrays and ``history.csv``."""

from __future__ import annotations

import json

import numpy as np
import pytest

import crr
from conftest import ROOT

xr = pytest.importorskip("xarray")


def test_the_dataset_holds_the_history_with_units_and_the_impacts_twice():
    result = crr.simulate(crr.Model.from_file(ROOT / "examples/models/trilithon.toml"), duration=4.0)
    ds = result.to_xarray()
    assert list(ds["q"].dims) == ["t", "coordinate"]
    assert list(ds["coordinate"].values) == result.coordinates
    assert list(ds["interface"].values) == result.interfaces
    np.testing.assert_array_equal(ds["t"].values, result.t)
    np.testing.assert_array_equal(ds["q"].values, result.q)
    np.testing.assert_array_equal(ds["qdot"].values, result.qdot)
    np.testing.assert_array_equal(ds["dissipated"].values, result.dissipated)
    assert ds["state"].values.tolist() == result.states.tolist()
    units = {name: ds[name].attrs["units"] for name in ("t", "q", "qdot", "kinetic", "work_in")}
    assert units == {"t": "s", "q": "rad", "qdot": "rad/s", "kinetic": "J", "work_in": "J"}
    assert json.loads(ds.attrs["summary_json"]) == result.summary
    assert ds.attrs["impacts"] == len(result.impacts) > 0
    assert np.isnan(ds.attrs["outside_model_from_s"]), "the trilithon keeps the hypotheses"
    # Each impact is two rows at one time (rates before, then after): exactly the duplicates.
    duplicated = ds.indexes["t"].duplicated(keep="last")
    assert duplicated.sum() == len(result.impacts)
    unique = ds.isel(t=~duplicated)
    assert unique.indexes["t"].is_unique and unique.sizes["t"] == len(result.t) - len(result.impacts)
    # The kept row of an impact carries the rates after it; the dropped one those before.
    for impact in result.impacts:
        rows = np.flatnonzero(result.t == impact["t"])
        assert len(rows) == 2
        kept = unique.sel(t=impact["t"])
        np.testing.assert_array_equal(kept["qdot"].values, result.qdot[rows[1]])
        assert not np.array_equal(result.qdot[rows[0]], result.qdot[rows[1]])


def test_the_dataset_says_from_when_a_run_is_outside_the_model():
    # The bundled drum column: a bed would pull at 0.5028 s (the drums above hop), which the
    # run warns about; the dataset carries that time.
    with pytest.warns(crr.CrrWarning, match="would need tension"):
        result = crr.simulate(crr.Model.from_file(ROOT / "examples/models/drum_column.toml"))
    ds = result.to_xarray()
    t = result.summary["hypothesis_violation"]["time"]
    assert abs(t - 0.5028) < 1e-4
    assert ds.attrs["outside_model_from_s"] == t
    # The part of the history inside the model, by that time.
    inside = ds.sel(t=slice(None, t))
    assert inside["t"].values.max() == t
