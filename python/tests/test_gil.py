"""Simulations and studies release the GIL: Python code runs beside them in other threads.

While a simulation (or a chunk of a study) runs in a worker thread, the main thread keeps
executing: a loop that sleeps 1 ms ticks hundreds of times a second when it can run at all. With
the GIL held for a whole run the main thread could not execute a single bytecode until that run
ended, and would tick only in the gaps between runs (a few times each). Each worker runs at least
4 times and for at least 0.5 s, whatever the machine's speed; more than 50 ticks in that window
shows the GIL released during the runs. What this says about speed (threads running on separate
cores) is a matter for benchmarks, not tests: no wall-clock ratio is asserted.
"""

from __future__ import annotations

import threading
import time

import crr
from conftest import ROOT
from gil_work import one_run


def _ticks_while(work_once, what: str) -> list:
    """Runs `work_once` in a worker thread at least 4 times and for at least 0.5 s while the main
    thread ticks, and checks the ticks; returns the worker's results."""
    done = threading.Event()
    results = []

    def work() -> None:
        begun = time.perf_counter()
        while len(results) < 4 or time.perf_counter() - begun < 0.5:
            results.append(work_once())
        done.set()

    worker = threading.Thread(target=work)
    start = time.perf_counter()
    worker.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    elapsed = time.perf_counter() - start
    assert len(results) >= 4
    assert elapsed >= 0.5
    assert ticks > 50, f"{what}: {ticks} ticks in {elapsed:.2f} s: the GIL was held"
    return results


def test_python_runs_while_a_simulation_runs():
    results = _ticks_while(one_run, "simulations")
    assert all(r.completed for r in results)


def test_python_runs_while_a_study_chunk_runs():
    study = crr.Study.from_file(ROOT / "examples/studies/housner_map.toml")
    chunk = study.case_ids[:150]
    results = _ticks_while(lambda: study.run_rows(chunk, jobs=1), "study chunks")
    # Every case's row, in the order asked, the same at every repetition.
    assert all(len(rows) == len(chunk) for rows in results)
    assert all(rows == results[0] for rows in results)
