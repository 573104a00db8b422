"""The local backend: a pool of worker processes on this machine, surviving the death of a worker.

Each worker process imports the library once (the ``forkserver`` start method
preloads it, where the platform has it) and runs one trial at a time; at most
``workers`` trials are in flight, so when a worker process dies (killed, out of
memory, a crash in native code) the trials it may have been running are exactly
the ones in flight. Each of them is run again alone, in a fresh process; one that
kills that process too is marked failed.
"""

from __future__ import annotations

import multiprocessing
import os
from collections import deque
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from multiprocessing.context import BaseContext

from .record import TrialJob, TrialOutcome

__all__ = ["run_local"]

#: Environment of the worker processes: one BLAS thread each (the work is many small
#: matrix products; threads only fight over the cores the processes already use).
WORKER_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def run_local(
    func: Callable[[TrialJob], TrialOutcome],
    jobs: Iterable[TrialJob],
    *,
    workers: int,
    on_done: Callable[[TrialOutcome], None],
    retries: int = 1,
) -> None:
    """Run ``func`` on every job in ``workers`` processes; ``on_done`` gets each outcome as it comes.

    Args:
        func: a module-level function (it is pickled by name), never raising.
        jobs: the work.
        workers: number of worker processes (≥ 1).
        on_done: called in this process with each outcome, in completion order.
        retries: times a job in flight when a worker died is run again alone.
    """
    for name, value in WORKER_ENV.items():
        os.environ.setdefault(name, value)
    context = _context()
    pending = deque(jobs)
    suspects: list[TrialJob] = []
    while pending:
        with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
            suspects = _run_until_broken(pool, func, pending, workers, on_done)
        for job in suspects:
            _run_alone(func, job, context, on_done, retries)


def _run_until_broken(
    pool: ProcessPoolExecutor,
    func: Callable[[TrialJob], TrialOutcome],
    pending: deque[TrialJob],
    workers: int,
    on_done: Callable[[TrialOutcome], None],
) -> list[TrialJob]:
    """Feed the pool until the work is done or a worker dies; return the jobs then in flight."""
    inflight: dict[Future[TrialOutcome], TrialJob] = {}
    while pending or inflight:
        while pending and len(inflight) < workers:
            job = pending.popleft()
            inflight[pool.submit(func, job)] = job
        done, _ = wait(inflight, return_when=FIRST_COMPLETED)
        for future in done:
            try:
                outcome = future.result()
            except BrokenProcessPool:
                return list(inflight.values())
            del inflight[future]
            on_done(outcome)
    return []


def _run_alone(
    func: Callable[[TrialJob], TrialOutcome],
    job: TrialJob,
    context: BaseContext,
    on_done: Callable[[TrialOutcome], None],
    retries: int,
) -> None:
    """Run a job that was in flight when a worker died again, alone, up to ``retries`` times."""
    for attempt in range(2, retries + 2):
        retry = TrialJob(job.trial, job.params, job.out, job.digest, attempt)
        with ProcessPoolExecutor(max_workers=1, mp_context=context) as pool:
            try:
                on_done(pool.submit(func, retry).result())
                return
            except BrokenProcessPool:
                continue
    outcome = TrialOutcome.failed(
        job.trial,
        f"the worker process died while processing it, {retries + 1} times (killed, out of memory "
        f"or a crash); run 'lowerlimb calibrate' on it alone to see why",
        "died",
        job.digest,
    )
    outcome.attempts = retries + 1
    on_done(outcome)


def _context() -> BaseContext:
    """``forkserver`` preloading the worker module where available (fast, thread-safe), else spawn."""
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(["lowerlimb.batch.worker"])
        return context
    return multiprocessing.get_context("spawn")
