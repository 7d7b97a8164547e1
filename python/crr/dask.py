"""Studies on a ``dask.distributed`` cluster.

:func:`run_study` splits a study's cases into chunks, runs each chunk as one task on a worker
(the worker reads the study once per process and runs the chunk's cases with the GIL released)
and joins the rows into the ``cases.csv`` that ``crr study`` writes, byte for byte: each case's
row depends on the case alone, never on where or with what else it ran.

Workers must import ``crr`` (the same version) and see the study's files at the same paths: on a
cluster, give the study as an absolute path (or as a mapping with an absolute ``model`` path),
on a shared file system.
"""

from __future__ import annotations

import functools
import os
import uuid
from pathlib import Path
from typing import TYPE_CHECKING, Any, List, Mapping, Optional, Sequence, Tuple, Union

from . import Study, _as_study, _load_study, _pandas, _warn_outside_model, cases_frame

if TYPE_CHECKING:  # pragma: no cover
    import pandas
    from distributed import Client

__all__ = ["run_study", "run_chunk"]


@functools.lru_cache(maxsize=8)
def _cached_study(source: Tuple[str, ...]) -> Study:
    return _load_study(source)


def run_chunk(source: Tuple[str, ...], ids: Sequence[str], jobs: Optional[int] = 1) -> List[str]:
    """The rows of ``cases.csv`` of the cases ``ids`` (one Dask task). ``source`` describes the
    study (``Study._source``); it is read once per worker process. ``jobs`` threads run the
    chunk (default 1: Dask's own worker threads already fill the cores)."""
    return _cached_study(tuple(source)).run_rows(list(ids), jobs)


def run_study(
    study: Union[Study, "os.PathLike[str]", str, Mapping[str, Any]],
    client: "Client",
    chunk_size: int = 64,
    jobs: Optional[int] = 1,
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
    progress: bool = False,
) -> "pandas.DataFrame":
    """Runs every case of ``study`` on the cluster of ``client`` and returns ``cases.csv`` as a
    pandas DataFrame (``frame.attrs["cases_csv"]`` holds the exact text).

    Args:
        study: a :class:`crr.Study`, the path of a study file, a mapping of its keys or the
            text of a study file (as :func:`crr.study`).
        client: a ``distributed.Client``.
        chunk_size: cases per task (≥ 1). Cases take from milliseconds (a pulse on a block) to
            seconds (a long record on an arch): aim for tasks of a second or more.
        jobs: threads per task (default 1; each Dask worker thread runs one task).
        out: when given, ``cases.csv`` is also written into this folder (created if needed).
        progress: show the tasks' progress with ``distributed.progress`` (a bar in a terminal,
            a widget in a notebook) while the cluster works.

    Warns:
        CrrWarning: when some cases' runs left crr's model, as :func:`crr.study`.
    """
    # Before the cluster works: a missing pandas must not cost the computed rows.
    _pandas("crr.dask.run_study")
    if chunk_size < 1:
        raise ValueError(f"chunk_size must be at least 1, got {chunk_size}")
    s = _as_study(study)
    s._warn_before_running(stacklevel=3)
    ids = s.case_ids
    chunks = [ids[i : i + chunk_size] for i in range(0, len(ids), chunk_size)]
    token = uuid.uuid4().hex[:12]
    futures = client.map(
        run_chunk,
        [s._source] * len(chunks),
        chunks,
        jobs=jobs,
        key=[f"crr-{s.name}-{token}-{c[0]}" for c in chunks],
    )
    if progress:
        from distributed import progress as show_progress

        show_progress(futures)
    rows = [r for chunk in client.gather(futures) for r in chunk]
    text = s.csv(rows)
    if out is not None:
        d = Path(out)
        d.mkdir(parents=True, exist_ok=True)
        with open(d / "cases.csv", "w", newline="") as f:
            f.write(text)
    return _warn_outside_model(cases_frame(text), stacklevel=2)
