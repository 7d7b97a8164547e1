"""The work of the GIL tests."""

from __future__ import annotations

import crr
from conftest import ROOT

MODEL = str(ROOT / "examples/models/arch.toml")
RECORD = crr.Record.from_file(ROOT / "examples/records/synthetic.AT2", format="peer-at2")


def one_run(_: object = None) -> crr.Result:
    """The arch under the 20 s synthetic record: a fraction of a second to a second of work."""
    return crr.simulate(MODEL, ground_motion=RECORD, duration=25.0)
