"""simulate(config) -> Result: builds the scene arrays, runs the batches in groups on the
compiled kernel (a progress bar between groups), and hands the tallies to results.py."""
from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any, Callable

import numba
import numpy as np
from tqdm import tqdm

from . import __version__, scene
from .config import SceneConfig, config_to_yaml, load_config
from .kernel.driver import features_of, photon_loop
from .kernel.models import FEATURE_SPLITTING, SPLIT_STACK_ROWS, STACK_COLUMNS
from .results import Result, budget_terms, from_tallies


def batch_seeds(seed: int, n_batches: int) -> np.ndarray:
    """One 32-bit seed per batch, a function of (seed, batch index) only (numpy SeedSequence with
    the batch index as spawn key), so batch b is the same whatever the batch count or grouping.
    Numba's generator takes 32-bit seeds; a rare collision inside a run is re-derived."""
    seeds = []
    seen = set()
    for b in range(n_batches):
        attempt = 0
        while True:
            s = int(np.random.SeedSequence(seed, spawn_key=(b, attempt)).generate_state(1)[0])
            if s not in seen:
                break
            attempt += 1
        seen.add(s)
        seeds.append(s)
    return np.array(seeds, dtype=np.int64)


def allocate(sc, n_batches: int, n_depths: int, grid, n_layers: int) -> dict[str, np.ndarray]:
    """Per-batch tally arrays; levels are the tally depths, then 0+ (all light), then 0+
    (water-leaving light only)."""
    nt, npf = (len(grid.theta), len(grid.phi)) if sc.tally_radiance else (1, 1)
    return {
        "flux": np.zeros((n_batches, n_depths + 2, 4)),
        "radiance": np.zeros((n_batches, n_depths + 2, nt, npf)),
        "local": np.zeros((n_batches, n_depths + 1, sc.le_dirs.shape[0])),
        "cap": np.zeros((n_batches, n_depths + 1)),
        "budget": np.zeros((n_batches, len(budget_terms(n_layers)))),
        "events": np.zeros(n_batches, dtype=np.int64),
    }


def _batches(raw: dict, lo: int, hi: int) -> tuple:
    """The tally arrays of batches lo .. hi - 1, in the photon loop's argument order."""
    return tuple(raw[name][lo:hi] for name in ("flux", "radiance", "local", "cap", "budget",
                                                "events"))


def simulate(config: SceneConfig | dict[str, Any] | str | Path, *, threads: int | None = None,
             progress: bool = False, first_batch: int = 0,
             should_stop: Callable[[], bool] | None = None,
             on_checkpoint: Callable[[Result], None] | None = None,
             checkpoint_every_s: float = 60.0) -> Result:
    """Runs a scene (a SceneConfig, a dict or a YAML path) and returns its Result.

    Batches first_batch .. batches-1 are traced (a resumed run starts after the batches it
    already has; batch b is the same whatever the start). Between groups of batches,
    should_stop() may end the run early: the Result then holds the batches completed and is
    marked partial. on_checkpoint(result) receives the batches completed so far every
    checkpoint_every_s seconds."""
    if not isinstance(config, SceneConfig):
        config = load_config(config)
    if threads is not None:
        numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    n_threads = numba.get_num_threads()
    sc, grid = scene.build(config)
    if not 0 <= first_batch < config.batches:
        raise ValueError(f"first_batch = {first_batch}: allowed 0 .. {config.batches - 1}")
    n_batches = config.batches - first_batch
    n_per_batch = math.ceil(config.photons / config.batches)
    n_layers = len(config.water.layers)
    depths = config.tallies.depths_m
    seeds = batch_seeds(config.seed, config.batches)[first_batch:]
    local_rows = scene.local_directions(config)[3]
    raw = allocate(sc, n_batches, len(depths), grid, n_layers)
    # room for split packets waiting their turn (scratch, one per batch; unused without splitting)
    splitting = features_of(sc) & FEATURE_SPLITTING
    stack = np.zeros((n_batches, SPLIT_STACK_ROWS if splitting else 1, STACK_COLUMNS))

    t0 = time.perf_counter()
    # compiles this scene's loop (or loads it from the cache) outside the timing
    loop = photon_loop(sc, n_per_batch, seeds, *_batches(raw, 0, 1), stack)
    startup = time.perf_counter() - t0

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
        return from_tallies(part, grid, np.array(depths), n_per_batch,
                            config.illumination.Ed0, n_layers, sc.tally_radiance, attrs,
                            config.tallies.local_directions_deg, local_rows, sc.cap_estimates)

    group = max(1, n_threads)
    done = 0
    t1 = last_checkpoint = time.perf_counter()
    with tqdm(total=n_batches * n_per_batch, unit="photon", unit_scale=True, delay=1.0,
              disable=not progress, desc=config.name[:40], leave=False) as bar:
        while done < n_batches:
            hi = min(n_batches, done + group)
            loop(n_per_batch, seeds[done:hi], *_batches(raw, done, hi), stack[done:hi])
            bar.update((hi - done) * n_per_batch)
            done = hi
            if should_stop is not None and should_stop():
                break
            now = time.perf_counter()
            if on_checkpoint is not None and done < n_batches \
                    and now - last_checkpoint >= checkpoint_every_s:
                on_checkpoint(result_of(done, now - t1))
                last_checkpoint = now
    return result_of(done, time.perf_counter() - t1)
