"""Many scenes at once: a look-up table over any keys of a scene, run on Dask.

    import oceanmc
    lut = oceanmc.sweep("lut.yaml", "lut.nc", workers=2)   # -> xarray.Dataset
    lut["air_Rrs_nadir"].sel({"bottom.reflectance": 0.2})

The phases, one module each: axes.py (the sweep file, key paths, the grid of points),
points.py (each point's scene, validated before any photon runs), execute.py (the points on a
Dask cluster), dataset.py (per-point results files and the assembled dataset).
"""
from __future__ import annotations

import tempfile
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from ..kernel.variants import Variant, union
from .axes import SweepError, SweepSpec, check_count, load_sweep, set_key_path
from .dataset import (OutputExists, PointStore, Summary, assemble, check_replaceable,
                      write_dataset)
from .points import Point, build_points, check_batch_groups, check_scenes

__all__ = ["sweep", "prepare", "SweepError", "OutputExists", "SweepSpec", "load_sweep",
           "set_key_path", "points_folder"]


def points_folder(output: Path) -> Path:
    """Where a dataset's finished points are kept: `LUT.nc` -> `LUT.points/`."""
    return output.with_suffix(".points")


class FailedPoints(UserWarning):
    """sweep() finished with points whose run raised (status `failed`, the error in the
    dataset's `error`, NaN values): a notebook sees it without reading attribute
    points_failed; the command, which lists them and exits 1, does not warn."""


@dataclass
class Plan:
    """A validated sweep, ready to run: its points and those an earlier run finished."""
    spec: SweepSpec
    points: list[Point]
    store: PointStore
    variant: Variant        # the photon loop's variant that every point runs on
    summaries: dict[str, Summary] = field(default_factory=dict)
    errors: dict[str, str] = field(default_factory=dict)

    @property
    def todo(self) -> list[Point]:
        return [p for p in self.points if p.key not in self.summaries]

    def dataset(self):
        """The dataset of the points done, the store's folder being the record: a worker may
        have written a point's file before its answer reached this process (a Ctrl-C then)."""
        for point in self.todo:
            if point.key not in self.errors:
                summary = self.store.finished(point)
                if summary is not None:
                    self.summaries[point.key] = summary
        return assemble(self.spec, self.points, self.summaries, self.errors)


def prepare(source: str | Path | dict, store_folder: Path, batch_groups: int | None = None,
            *, replacing: Path | None = None,
            should_stop: Callable[[], bool] | None = None) -> Plan:
    """Reads and validates the sweep (every point's scene, tables included: SweepError naming
    the point), and finds the points a previous run has finished. replacing: the dataset this
    sweep will write, which must not hold anything it would lose (OutputExists, before the
    kernel is compiled). should_stop: checked while the kernel compiles (CompileInterrupted)."""
    from ..run.compiling import ready
    from ..scene import predicted_variant

    spec = load_sweep(source)
    if batch_groups is not None:
        spec = SweepSpec(spec.base, spec.base_dir, spec.settings, spec.axes, batch_groups)
    points = build_points(spec)
    check_batch_groups(spec.batch_groups, points)
    if replacing is not None:
        check_replaceable(replacing, store_folder, spec)
    # compiles here, once, a variant that every point runs on, into the disk cache that local
    # workers load from
    variant = ready(union(predicted_variant(point.config) for point in points), should_stop)[1]
    check_scenes(points, spec)
    store = PointStore(store_folder)
    plan = Plan(spec, points, store, variant)
    for point in points:
        summary = store.finished(point)
        if summary is not None:
            plan.summaries[point.key] = summary
    return plan


def run(plan: Plan, client, threads: int | None = None, progress: bool = False,
        workers_write: bool = False, should_stop: Callable[[], bool] | None = None) -> None:
    """Runs the points not yet done on the client's cluster; each finished point is stored as it
    arrives (a KeyboardInterrupt, or should_stop() turning true, cancels the rest and leaves
    the plan with what is done). workers_write: the workers see the output folder and write the
    points' results files themselves."""
    from .execute import run_points

    def on_done(point: Point, summary: Summary | None, error: str | None) -> None:
        if summary is not None:
            plan.summaries[point.key] = summary
        else:
            plan.errors[point.key] = error

    todo = plan.todo
    if todo:
        run_points(client, plan.store, todo, plan.spec.batch_groups, threads, on_done, progress,
                   len(plan.points), len(plan.points) - len(todo), workers_write, plan.variant,
                   should_stop)


def sweep(source: str | Path | dict[str, Any], output: str | Path | None = None, *,
          workers: int | None = None, scheduler: str | None = None, client=None,
          threads: int | None = None, batch_groups: int | None = None,
          workers_write: bool | None = None, progress: bool = False,
          log: Callable[[str], None] | None = None, overwrite: bool = False,
          should_stop: Callable[[], bool] | None = None):
    """Runs a sweep and returns its xarray Dataset (written to `output`, a .nc file, if given).

    source: a sweep YAML file or a mapping {base: scene file | scene mapping | SceneConfig,
    axes: {key path: [values], name: {key: key path, values: [values]}, zip: {key path:
    [values], ...}}, set: {key path: value}, batch_groups: N} (an axis given a name is the
    dataset's dimension of that name, e.g. `chl`, instead of its key path's). The points run
    on `client` (a distributed.Client), on the scheduler at `scheduler` (tcp://HOST:PORT), or
    on a local cluster of `workers` processes (default: one per core), `threads` threads each
    (default: the cores shared among the local workers).
    Finished points are kept in `<output stem>.points/` (a temporary folder without output):
    a rerun skips them. workers_write: the workers write the points' files there themselves
    (they must see that folder: a shared file system; default: only on the local cluster
    started here), else they send each Result back to be written here. A KeyboardInterrupt
    writes the points done so far (status `pending` for the rest) and is raised again;
    should_stop() turning true does the same and returns that partial dataset (attribute
    partial = 1): a caller's signal handler sets it (the command's SIGINT and SIGTERM).
    An existing `output` is replaced only if it is this sweep's dataset or that of a sweep
    whose every point this one has (a rerun, or values added to an axis), else OutputExists
    (before anything runs), unless overwrite. log(text) receives a line on what is about to
    run."""
    import os

    # (the command checks its options; a caller of this function gets the same refusals:
    # workers=0 or -1 started no worker and waited for ever, batch_groups=0 divided by zero)
    for name, value in (("workers", workers), ("threads", threads),
                        ("batch_groups", batch_groups)):
        if value is not None:
            check_count(name, value)
    with tempfile.TemporaryDirectory(prefix="oceanmc-sweep-") as scratch:
        folder = points_folder(Path(output)) if output is not None else Path(scratch)
        plan = prepare(source, folder, batch_groups, should_stop=should_stop,
                       replacing=None if output is None or overwrite else Path(output))
        local = client is None and scheduler is None
        if local:
            workers = workers or os.cpu_count() or 1
            if threads is None:
                threads = max(1, (os.cpu_count() or 1) // workers)
        todo = len(plan.todo)
        if log is not None:
            where = f"a local cluster of {workers} worker process(es), {threads} thread(s) " \
                    "each" if local else \
                f"the Dask scheduler at {scheduler or client.scheduler.address}"
            log(f"{len(plan.points)} points ({' x '.join(map(str, plan.spec.shape)) or '1'}): "
                f"{len(plan.points) - todo} finished earlier, {todo} to run on {where}")

        def finish():
            dataset = plan.dataset()
            if output is not None:
                write_dataset(dataset, Path(output))
            return dataset

        if not todo or (should_stop is not None and should_stop()):
            return finish()
        from .execute import dask_client
        with dask_client(workers, scheduler, client) as dask:
            try:
                run(plan, dask, threads, progress,
                    workers_write=local if workers_write is None else workers_write,
                    should_stop=should_stop)
            finally:   # also on Ctrl-C: the points done so far, before the cluster closes
                dataset = finish()
    failed = int(dataset.attrs.get("points_failed", 0))
    if failed:
        warnings.warn(f"{failed} of {dataset.attrs['points']} points failed (status 'failed', "
                      "values NaN; each one's error in the variable 'error'): a rerun of the "
                      "sweep runs them again", FailedPoints, stacklevel=2)
    return dataset
