"""Running the points on Dask: a local cluster of worker processes, or an existing scheduler.

Each task runs one point, or one group of a point's batches, with simulate() in a worker. On a
local cluster the worker writes the point's results file into the store's folder itself (the
writing, 17-50 ms a point, then runs in parallel) and hands back the estimates; on another
scheduler it hands back the Result and this process stores it (dataset.PointStore), so remote
workers need no access to the output folder. The kernel is compiled (or loaded) here before the
points are checked, which fills the on-disk cache the workers of a local cluster then load from
(0.3 s instead of a 10-14 s compilation each); every worker loads it once before its first point.

Dask reschedules the tasks of a worker that dies (a lost worker's points run elsewhere; after
`distributed.scheduler.allowed-failures` + 1 deaths with the same task, 4 by default, that
point is recorded as failed). A point whose task raises is recorded with its error and the others go
on. Ctrl-C (KeyboardInterrupt), or a stop asked by the caller's should_stop() (the command's
SIGINT and SIGTERM handler), cancels what is left; the caller then writes what is done.
"""
from __future__ import annotations

import os
import time
import uuid
from contextlib import contextmanager
from typing import Callable

from tqdm import tqdm

from ..kernel.variants import Variant
from .dataset import PointStore, Summary
from .points import Point

POLL_S = 0.2


def load_kernel(variant: Variant) -> float:
    """Compiles the photon loop's variant or loads it from the on-disk cache (run in every
    worker once, so that the first point's run time is its own); returns the seconds it
    took."""
    from ..run.compiling import ready
    t0 = time.perf_counter()
    _no_process_lock_for_tqdm()
    ready(variant)
    return time.perf_counter() - t0


def _no_process_lock_for_tqdm() -> None:
    """tqdm's first bar (simulate makes one, hidden, in a worker too) creates a multiprocessing
    lock, a named semaphore that a worker killed mid-point (a cluster closed on Ctrl-C or
    SIGTERM) leaves behind: Python then warns of leaked semaphores at exit. A worker's bars are
    never shown, so a thread lock serves."""
    import threading

    from tqdm import tqdm as bar
    if not isinstance(getattr(bar, "_lock", None), type(threading.RLock())):
        bar.set_lock(threading.RLock())


def run_part(scene_yaml: str, first_batch: int, threads: int | None, save_to: str | None):
    """A Dask task: runs batches first_batch .. batches-1 of a scene given as YAML (an absolute
    path for every table file). With save_to (a worker that sees the output folder) it writes
    the results file there itself and returns its Summary (the writing is then done in parallel
    and only the estimates travel back); else it returns the Result. An error comes back as one
    line of text."""
    import yaml

    from ..config import load_config
    from ..run.simulation import simulate
    _no_process_lock_for_tqdm()   # a worker started after the others (one that died) too
    try:
        config = load_config(yaml.safe_load(scene_yaml))
        result = simulate(config, threads=threads, first_batch=first_batch)
        if save_to is None:
            return result
        result.save(save_to)
        return Summary.of(result)
    except Exception as exc:  # recorded against the point; the other points go on
        return f"{type(exc).__name__}: {exc}"


@contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None, client=None):
    """A distributed.Client: the one given, one connected to `scheduler` (tcp://HOST:PORT), or
    one with its own local cluster (local_client) of `workers` processes (default: the number
    of cores)."""
    from distributed import Client
    if client is not None:
        yield client
        return
    if scheduler is not None:
        with Client(scheduler, timeout="30s") as connected:
            yield connected
        return
    with local_client(workers or os.cpu_count() or 1) as local:
        yield local


@contextmanager
def local_client(workers: int):
    """A Client of a local cluster of `workers` processes with one task at a time each,
    listening on 127.0.0.1 only. Its dashboard is off; the scheduler's other HTTP routes
    (health, metrics) listen on a free port of 127.0.0.1: left to distributed, they took port
    8787 of every interface, and where a user's own Dask dashboard held it, distributed warned
    'Port 8787 is already in use' (a UserWarning, which `-W error` makes a failed start).
    Its processes log only CRITICAL: at ERROR, a worker whose heartbeat met the scheduler
    already closing printed 'Failed to communicate with scheduler during heartbeat' and a
    25-line CommClosedError traceback after a sweep that had finished (a fresh clone's CI, and
    a user's SIGTERM); a point that fails is reported by the sweep itself (status, error)."""
    import logging

    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      host="127.0.0.1", dashboard_address=None,
                      scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                      silence_logs=logging.CRITICAL) as cluster, Client(cluster) as client:
        yield client


def run_points(client, store: PointStore, todo: list[Point], groups: int, threads: int | None,
               on_done: Callable[[Point, Summary | None, str | None], None],
               progress: bool, total: int, skipped: int, workers_write: bool,
               variant: Variant, should_stop: Callable[[], bool] | None = None) -> None:
    """Submits every point (or its unfinished batch groups) and calls on_done(point, summary,
    None) or on_done(point, None, error) as each point ends, whatever the order. workers_write:
    the workers see the store's folder (a local cluster) and write the results files.
    should_stop() is asked every POLL_S: when it says so, the points not finished are
    cancelled and this returns (as on a KeyboardInterrupt, which is raised again)."""
    from distributed.client import FutureCancelledError

    def stopping() -> bool:
        return should_stop is not None and should_stop()

    if stopping():
        return
    client.run(load_kernel, variant)
    task_of = {}       # future -> (point, batch range)
    remaining = {}     # point key -> batch ranges still running
    ranges_of = {}
    for point in todo:
        ranges = point.batch_ranges(groups)
        ranges_of[point.key] = ranges
        remaining[point.key] = set()
        for first, end in ranges:
            if len(ranges) > 1 and store.part_done(point, (first, end)):
                continue
            save_to = str(store.path(point, None if len(ranges) == 1 else (first, end))) \
                if workers_write else None
            key = f"oceanmc-point-{point.key}-{first}-{uuid.uuid4().hex}"
            future = client.submit(run_part, point.part_yaml(first, end), first, threads,
                                   save_to, key=key, pure=False)
            task_of[future] = (point, (first, end))
            remaining[point.key].add((first, end))
    failed: dict[str, str] = {}
    pending = set(task_of)
    with tqdm(total=total, initial=skipped, unit="point", disable=not progress,
              desc="sweep", smoothing=0.0) as bar:
        for point in todo:   # every group of these was done by an earlier run
            if not remaining[point.key]:
                on_done(point, store.merge_parts(point, ranges_of[point.key]), None)
                bar.update(1)
        try:
            while pending and not stopping():
                done = {future for future in pending if future.done()}
                if not done:
                    time.sleep(POLL_S)   # short sleeps: Ctrl-C is seen at once
                    continue
                pending -= done
                for future in done:
                    point, batches = task_of.pop(future)
                    try:
                        outcome = future.result()
                    except FutureCancelledError:
                        continue
                    except Exception as exc:  # KilledWorker: the point's task killed workers
                        outcome = f"{type(exc).__name__}: {exc}"
                    future.release()
                    if point.key in failed:
                        continue
                    if isinstance(outcome, str):
                        failed[point.key] = outcome
                        on_done(point, None, outcome)
                        bar.update(1)
                        continue
                    remaining[point.key].discard(batches)
                    if len(ranges_of[point.key]) == 1:
                        on_done(point, outcome if isinstance(outcome, Summary)
                                else store.save(point, outcome), None)
                        bar.update(1)
                        continue
                    if not isinstance(outcome, Summary):
                        store.save_part(point, batches, outcome)
                    if not remaining[point.key]:
                        on_done(point, store.merge_parts(point, ranges_of[point.key]), None)
                        bar.update(1)
        finally:
            if pending:
                client.cancel(list(pending))

