"""Simulations and studies release the GIL: Python threads run them in parallel.

Two assertions. (1) Python code keeps running while a simulation runs in another thread: with
the GIL held for the whole run, the main thread could not execute a single bytecode until it
ended. (2) On two or more cores, two runs in two threads take about the time of one: we assert
less than 1.6 × the time of one run (the margin: with the GIL held the two runs would take 2 ×
at best; 1.6 leaves room for background processes, for memory bandwidth and caches shared by the
two cores and for the start-up of the threads, while staying well clear of the serial 2 ×). The
best of five attempts is taken for the same reason.

A wall-clock ratio says nothing on a machine whose second core is busy with other processes, and
the load average cannot tell (it counts this test's own work and the builds just before it). So
(2) has a control without a GIL: the same two runs in two processes, measured when the threads
take 1.6 × or more. On a partly busy machine both ratios rise together: the threads then pass
when they take at most 0.3 × more than the processes (a held GIL would take 2 ×, above the
processes' ratio by far more, and the threads' ratio must stay below 1.9 in any case; a CI run
measured 1.62 for the threads against 1.40 for the processes). When the processes do not run
in parallel at all (their ratio is above 1.6), the machine has no free core: the thread ratio is
skipped, with both values in the reason; (1) still holds.
"""

from __future__ import annotations

import multiprocessing
import os
import threading
import time

import pytest

import crr
from conftest import ROOT
from gil_work import one_run, one_run_samples


def test_python_runs_while_a_simulation_runs():
    done = threading.Event()
    results = []

    def work() -> None:
        # At least 4 runs and at least 0.5 s of them, whatever the machine's speed: the window
        # in which the main thread must keep ticking.
        begun = time.perf_counter()
        while len(results) < 4 or time.perf_counter() - begun < 0.5:
            results.append(one_run())
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
    assert len(results) >= 4 and all(r.completed for r in results)
    assert elapsed >= 0.5
    # A 1 ms sleep loop ticks hundreds of times a second when it can run at all.
    assert ticks > 50, f"{ticks} ticks in {elapsed:.2f} s: the GIL was held"


def _best_ratio(single_run, double_run) -> float:
    """The best of five: wall time of `double_run` / that of `single_run`."""
    best = float("inf")
    for _ in range(5):
        start = time.perf_counter()
        single_run()
        single = time.perf_counter() - start
        start = time.perf_counter()
        double_run()
        double = time.perf_counter() - start
        best = min(best, double / single)
        if best < 1.4:
            break
    return best


def _process_ratio() -> float:
    """Two runs in two processes / one run in one: the parallelism the machine offers now."""
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(2) as pool:
        pool.map(one_run_samples, [0, 1], chunksize=1)  # start-up and imports
        return _best_ratio(
            lambda: pool.map(one_run_samples, [0], chunksize=1),
            lambda: pool.map(one_run_samples, [0, 1], chunksize=1),
        )


def _assert_parallel(target, what: str) -> None:
    cores = os.cpu_count() or 1
    if cores < 2:
        pytest.skip("needs two cores")
    target()  # warm up
    best = _best_ratio(lambda: _threads(1, target), lambda: _threads(2, target))
    print(f"{what}: two threads / one = {best:.2f}")
    if best >= 1.6:
        control = _process_ratio()
        print(f"control: two processes / one = {control:.2f}")
        if control > 1.6:
            pytest.skip(
                f"no free core: two runs in two processes take {control:.2f} × one, in two "
                f"threads {best:.2f} ×"
            )
        assert best < min(1.9, control + 0.3), (
            f"two threads take {best:.2f} × one run, two processes {control:.2f} ×"
        )


def _threads(n: int, target) -> float:
    threads = [threading.Thread(target=target) for _ in range(n)]
    start = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return time.perf_counter() - start


def test_two_threads_take_about_the_time_of_one_run():
    _assert_parallel(one_run, "simulations")


def test_study_chunks_in_two_threads_run_in_parallel():
    study = crr.Study.from_file(ROOT / "examples/studies/housner_map.toml")
    chunk = study.case_ids[:150]
    _assert_parallel(lambda: study.run_rows(chunk, jobs=1), "study chunks")
