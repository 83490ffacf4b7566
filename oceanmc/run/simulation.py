"""simulate(config) -> Result: packs the scene (scene/), runs the batches in groups on the
compiled kernel (a progress bar between groups), and hands the tallies to results.py."""
from __future__ import annotations

import math
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Callable

import numba
import numpy as np
from tqdm import tqdm

from .. import __version__, scene
from ..config import SceneConfig, config_to_yaml, load_config
from ..kernel.records import PACKET, SPLIT_STACK_ROWS
from ..kernel.rng import batch_state
from ..scene.grid import tally_views
from .compiling import ready
from .results import Result, from_tallies


LINE_FLOATS = 8                           # a 64-byte cache line of float64
PACKET_STRIDE = 256 // PACKET.itemsize    # packets of two batches 256 bytes apart


def simulate(config: SceneConfig | dict[str, Any] | str | Path, *, threads: int | None = None,
             progress: bool = False, first_batch: int = 0,
             should_stop: Callable[[], bool] | None = None,
             on_checkpoint: Callable[[Result], None] | None = None,
             checkpoint_every_s: float = 60.0) -> Result:
    """Runs a scene (a SceneConfig, a dict or a YAML path) and returns its Result.

    Batches first_batch .. batches-1 are traced, `threads` at a time (a resumed run starts
    after the batches it already has; batch b is the same whatever the start). After each
    batch, should_stop() may end the run early: the Result then holds the batches completed and is
    marked partial. on_checkpoint(result) receives the batches completed so far every
    checkpoint_every_s seconds."""
    if not isinstance(config, SceneConfig):
        config = load_config(config)
    # batches run in threads (trace_batch releases the GIL); NUMBA_NUM_THREADS (default: the
    # number of cores) is the default and the most
    n_threads = numba.config.NUMBA_NUM_THREADS if threads is None \
        else max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS))
    t0 = time.perf_counter()
    # compiles the kernel (or loads it from the cache) before the scene is packed, which uses it
    trace = ready(should_stop)
    startup = time.perf_counter() - t0
    sc = scene.build(config)
    if not 0 <= first_batch < config.batches:
        raise ValueError(f"first_batch = {first_batch}: allowed 0 .. {config.batches - 1}")
    n_batches = config.batches - first_batch
    n_per_batch = math.ceil(config.photons / config.batches)
    n_layers = len(config.water.layers)
    depths = config.tallies.depths_m
    # each batch's random stream (rows 128 bytes apart: a thread writes its state at every draw)
    rngs = np.zeros((n_batches, 16), dtype=np.uint64)
    for b in range(n_batches):
        rngs[b, :4] = batch_state(config.seed, first_batch + b)
    beams = np.zeros((n_batches, 4))
    beams[:, 3] = 1.0
    # each batch's tally row and packet on cache lines of their own: two threads writing to
    # one line slow each other down (false sharing; measured: 1.5x instead of 2x on 2 threads)
    tallies = np.zeros((n_batches, -(-sc.tally_size // LINE_FLOATS) * LINE_FLOATS + LINE_FLOATS))
    events = np.zeros(n_batches, dtype=np.int64)
    packets = np.zeros((n_batches, PACKET_STRIDE), dtype=PACKET)
    # room for split packets waiting their turn (scratch, one per batch; unused without splitting)
    stacks = np.zeros((n_batches, SPLIT_STACK_ROWS if sc.splitting else 1), dtype=PACKET)
    raw = dict(tally_views(sc.grid, tallies), events=events)

    def batch(b: int) -> tuple:
        return (rngs[b, :4], beams[b], tallies[b], packets[b, :1], stacks[b])

    def run_batch(b: int) -> None:
        start = -1
        while start < n_per_batch:
            start, n_events = trace(*sc.kernel_args(), n_per_batch, start, 1 << 20, *batch(b))
            events[b] += n_events

    def result_of(done: int, wall: float) -> Result:
        photons = done * n_per_batch
        attrs = {
            "name": config.name,
            "config_yaml": config_to_yaml(config),
            "oceanmc_version": __version__,
            "numba_version": numba.__version__,
            "seed": config.seed,
            "photons": photons,
            "batches": done,
            "first_batch": first_batch,
            "photons_per_batch": n_per_batch,
            "partial": first_batch + done < config.batches,
            "threads": n_threads,
            "wall_time_s": wall,
            "startup_time_s": startup,
            "photons_per_s": photons / wall if wall > 0 else float("inf"),
            "scattering_events": int(raw["events"][:done].sum()),
        }
        part = {name: values[:done] for name, values in raw.items()}
        return from_tallies(part, sc.angles, np.array(depths), n_per_batch,
                            config.illumination.Ed0, n_layers, config.tallies.radiance, attrs,
                            config.tallies.local_directions_deg, sc.local_rows,
                            config.nadir_local)

    done = 0
    t1 = last_checkpoint = time.perf_counter()
    with tqdm(total=n_batches * n_per_batch, unit="photon", unit_scale=True, delay=1.0,
              disable=not progress, desc=config.name[:40], leave=False) as bar, \
            ThreadPoolExecutor(max_workers=n_threads) as pool:
        # every batch queued at once (no barrier between groups); they finish in about the
        # order queued and are counted in order, so a stop keeps a prefix of whole batches
        futures = [pool.submit(run_batch, b) for b in range(n_batches)]
        try:
            for future in futures:
                future.result()
                done += 1
                bar.update(n_per_batch)
                if should_stop is not None and should_stop():
                    break
                now = time.perf_counter()
                if on_checkpoint is not None and done < n_batches \
                        and now - last_checkpoint >= checkpoint_every_s:
                    on_checkpoint(result_of(done, now - t1))
                    last_checkpoint = now
        finally:
            for future in futures[done:]:
                future.cancel()   # the batches in flight finish; the rest never start
    return result_of(done, time.perf_counter() - t1)
