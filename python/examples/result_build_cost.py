"""How long a ``Result`` of a million samples takes to build, against the run itself.

Runs a bundled model for 10 s with ``output_interval = 1e-5`` (10⁶ samples) three times and
prints the best times of the run (``_crr.simulate``) and of building the ``Result`` with its
``states``. Usage: ``python python/examples/result_build_cost.py [MODEL]`` (default: the
trilithon), from the repository root.
"""

from __future__ import annotations

import sys
import time

import crr
from crr import _crr

model = crr.Model.from_file(sys.argv[1] if len(sys.argv) > 1 else "examples/models/trilithon.toml")
best = {"run": float("inf"), "build": float("inf")}
for _ in range(3):
    t0 = time.perf_counter()
    run = _crr.simulate(
        model._native,
        ground_motion=None,
        initial=None,
        analysis=crr._json({"output_interval": 1e-5, "duration": 10.0}),
        record_file=None,
        records=[],
        duration=None,
        max_samples=None,
        memory=None,
    )
    t1 = time.perf_counter()
    result = crr.Result(run, model.coordinates, model.interfaces)
    _ = result.states
    t2 = time.perf_counter()
    best["run"] = min(best["run"], t1 - t0)
    best["build"] = min(best["build"], t2 - t1)
print(
    f"{model.name}: {len(result.t)} samples, run {best['run']:.3f} s, Result with states "
    f"{best['build']:.3f} s ({100 * best['build'] / best['run']:.1f} % of the run)"
)
