"""The Dask backend: the same jobs and worker function on a ``dask.distributed`` cluster.

Needs the optional extra ``lowerlimb[cluster]``. The study's input and output folders
must be visible at the same paths on every worker (a shared file system). A worker
that dies is handled by the scheduler: it re-runs the trial on another worker and
gives up after ``distributed.scheduler.allowed-failures`` deaths (set it to 1 on
your scheduler for "retried once"; the clusters made here use 1); the trial is then
marked failed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import replace
from typing import Any

from lowerlimb.errors import InputError

from .record import TrialJob, TrialOutcome

__all__ = ["absolute_paths", "check_scheduler_address", "run_dask"]

#: Protocols of a Dask address (``distributed.comm``) and whether they need ``HOST:PORT``.
_PROTOCOLS: dict[str, bool] = {
    "tcp": True,
    "tls": True,
    "ws": True,
    "wss": True,
    "ucx": True,
    "inproc": False,
}


def check_scheduler_address(address: object) -> None:
    """Refuse a scheduler address Dask cannot parse (before anything is read or written).

    An address is ``[PROTOCOL://]HOST:PORT`` (``tcp`` when none is given; PORT a whole
    number 1–65535), or an ``inproc://`` address of a cluster in this process. A
    ``distributed.Client`` or cluster object is not checked here.

    Raises:
        InputError: a string that is not such an address.
    """
    if not isinstance(address, str):
        return
    protocol, sep, rest = address.partition("://")
    if not sep:
        protocol, rest = "tcp", address
    needs_port = _PROTOCOLS.get(protocol.lower())
    host, colon, port = rest.rpartition(":")
    if needs_port is None:  # an unknown protocol
        ok = False
    elif not needs_port:
        ok = bool(rest)
    else:
        ok = bool(colon and host.strip("[]")) and port.isdigit() and 0 < int(port) < 65536
    if not ok:
        raise InputError(f"--scheduler needs an address tcp://HOST:PORT, got {address!r}")


def run_dask(
    func: Callable[[TrialJob], TrialOutcome],
    jobs: Iterable[TrialJob],
    *,
    scheduler: Any,
    on_done: Callable[[TrialOutcome], None],
) -> None:
    """Run ``func`` on every job on a Dask cluster; ``on_done`` gets each outcome as it comes.

    Args:
        func: a module-level function, never raising.
        jobs: the work.
        scheduler: the scheduler's address (``tcp://host:8786``), or a
            ``distributed.Client`` or cluster object (``LocalCluster``…).
        on_done: called in this process with each outcome, in completion order.

    The jobs' paths (trial, reused calibration, output folder) are made absolute first:
    a worker runs in its own working directory, where a relative path means another file.

    Raises:
        InputError: dask.distributed is not installed, or the scheduler cannot be reached.
    """
    try:
        from distributed import Client, as_completed
        from distributed.scheduler import KilledWorker
    except ImportError:
        raise InputError(
            "--scheduler needs dask.distributed; install it with pip install 'lowerlimb[cluster]'"
        ) from None
    own = not isinstance(scheduler, Client)
    try:
        client = Client(scheduler) if own else scheduler
    except OSError as e:
        raise InputError(f"cannot reach the Dask scheduler {scheduler}: {e}; check the address") from None
    try:
        jobs = [absolute_paths(job) for job in jobs]
        futures = {
            client.submit(func, job, key=f"lowerlimb-{job.trial.name}-{job.digest[:12]}", pure=False): job
            for job in jobs
        }
        for future in as_completed(futures):
            job = futures[future]
            try:
                outcome = future.result()
            except KilledWorker:
                outcome = TrialOutcome.failed(
                    job.trial,
                    "the worker process died while processing it, on every retry the scheduler "
                    "allowed (killed, out of memory or a crash); run 'lowerlimb calibrate' on it alone",
                    "died",
                    job.digest,
                )
            except Exception as e:  # the cluster lost it (cancelled, communication): recorded
                outcome = TrialOutcome.failed(
                    job.trial, f"internal error ({type(e).__name__}): {e}", "internal", job.digest
                )
            on_done(outcome)
    finally:
        if own:
            client.close()


def absolute_paths(job: TrialJob) -> TrialJob:
    """``job`` with its trial, reused calibration and output folder as absolute paths (from this cwd)."""
    trial = job.trial
    calibration = None if trial.calibration is None else trial.calibration.absolute()
    return replace(
        job, trial=replace(trial, path=trial.path.absolute(), calibration=calibration), out=job.out.absolute()
    )
