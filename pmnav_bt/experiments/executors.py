"""Run independent tasks in this process, in a process pool, or as Ray tasks.

``run_tasks(fn, tasks, jobs, ray)`` yields ``(index, result)`` as each task ends, in
completion order. ``fn`` must be a module-level function (pickled by reference) that
never raises for a task's own failure (it returns an errored row instead). Stopping
(Interrupted, KeyboardInterrupt, any exception) cancels what is left: pool workers are
terminated, Ray tasks cancelled, and a Ray runtime this call started is shut down.

Ray is optional (``pip install 'pmnav-bt[ray]'``): ``ray=None`` never imports it;
``ray="local"`` starts a private single-machine runtime with ``jobs`` CPUs on loopback;
any other string is a cluster address (``ray://head:10001`` or ``head:6379``, or
``auto`` for the cluster this machine belongs to).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from pmnav_bt.errors import PmNavError

LOCAL = "local"


class RayUnavailable(PmNavError):
    """--ray was asked for but Ray is not installed or cannot start."""


def run_tasks(
    fn: Callable[[Any], Any], tasks: Sequence[Any], jobs: int = 1, ray: str | None = None
) -> Iterator[tuple[int, Any]]:
    if not tasks:
        return
    if ray is not None:
        yield from _ray(fn, tasks, jobs, ray)
    elif jobs > 1:
        yield from _pool(fn, tasks, jobs)
    else:
        for i, t in enumerate(tasks):
            yield i, fn(t)


def _indexed(args: tuple[Callable, int, Any]) -> tuple[int, Any]:
    fn, i, task = args
    return i, fn(task)


def _pool(fn, tasks, jobs) -> Iterator[tuple[int, Any]]:
    import multiprocessing as mp

    from pmnav_bt.interrupts import quiet_worker

    pool = mp.get_context("spawn").Pool(
        min(jobs, len(tasks)), initializer=quiet_worker, initargs=(os.getpid(),)
    )
    try:
        yield from pool.imap_unordered(_indexed, [(fn, i, t) for i, t in enumerate(tasks)])
    finally:
        pool.terminate()
        pool.join()


def ray_init(address: str, jobs: int):
    """Connect to (or start) Ray; returns the module and whether this call started it.

    A local runtime stays on loopback: Ray otherwise resolves 127.0.0.1 to the machine's
    routable address (``resolve_ip_for_localhost``); its switch for that is the (oddly
    named) RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0, read when Ray is first imported."""
    if address == LOCAL and "ray" not in sys.modules:
        os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
    try:
        import ray
    except ImportError:
        raise RayUnavailable(
            "--ray needs Ray: pip install 'pmnav-bt[ray]' (or pip install 'ray==2.60.*')"
        ) from None
    if ray.is_initialized():
        return ray, False
    kw: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
    try:
        if address == LOCAL:
            ray.init(num_cpus=jobs, _node_ip_address="127.0.0.1", **kw)
        else:
            ray.init(address=address, **kw)
    except Exception as err:  # noqa: BLE001 - Ray raises many kinds; one line for the user
        msg = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise RayUnavailable(f"--ray {address}: cannot start or reach Ray: {msg}") from None
    return ray, True


class TaskCrash:
    """What a Ray task that died (its worker killed, out of memory) yields instead."""

    def __init__(self, message: str):
        self.message = message

    def __repr__(self) -> str:
        return f"TaskCrash({self.message!r})"


def _call(fn, i: int, task):
    return i, fn(task)


@contextmanager
def _signals_through_ray():
    """A signal handler's exception (Interrupted) raised while Ray's Cython code waits
    comes out as a SystemError caused by it: raise the exception itself."""
    try:
        yield
    except SystemError as err:
        cause = err.__cause__ or err.__context__
        if isinstance(cause, BaseException) and not isinstance(cause, Exception):
            raise cause from None
        raise


def _ray(fn, tasks, jobs, address) -> Iterator[tuple[int, Any]]:
    ray, started = ray_init(address, jobs)
    remote = ray.remote(num_cpus=1, max_retries=0)(_call)
    pending: dict = {}
    try:
        pending = {remote.remote(fn, i, t): i for i, t in enumerate(tasks)}
        while pending:
            with _signals_through_ray():
                ready, _ = ray.wait(list(pending), num_returns=1)
            i = pending.pop(ready[0])
            try:
                with _signals_through_ray():
                    row = ray.get(ready[0])
            except ray.exceptions.RayError as err:
                row = i, TaskCrash(f"{type(err).__name__}: {str(err).splitlines()[0]}")
            yield row
    finally:
        if started:  # our own runtime: shutting it down stops its workers
            ray.shutdown()
        else:  # a cluster's: ask it to drop what is left of this run
            # (no force: killing workers while their tasks complete can abort the
            # driver in Ray's task manager, seen on Ctrl-C with a local runtime)
            for r in pending:
                ray.cancel(r)
