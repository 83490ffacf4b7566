"""The Cox-Munk surface's table (kernel/surface/cox_munk_table.py): built from the facet walk
once per (slope alpha, n_water), kept on disk beside the compile cache.

Build: at each of the NODES incidences per side, WALKS_PER_NODE walks split at their first
facet, their first facets drawn by Latin hypercube sampling (cox_munk_table.walk_node: 2
weighted leaving directions a walk), in threads (the walks release the GIL); R is the reflected weight over the walks, and each branch's quantiles are the
weighted empirical quantiles of its leaving directions (the value where the cumulative weight,
counted to the middle of each sample, reaches the level; linear between samples, the extreme
samples at levels 0 and 1); at normal incidence the azimuth is uniform by symmetry and its
exact quantiles are stored. Each node has its own random stream and permutations from
(TABLE_SEED, side, node), so a table is the same whatever the number of threads.

Cache: CACHE_DIR's parent / surface_tables / cox_munk-<sources>-<key>.npy, <sources> a hash of
the walk's and the table's kernel sources (an edit there makes new tables), <key> a hash of
alpha and n_water (exact binary values), the layout, the walk count and FORMAT_VERSION. Written
to a temporary file and renamed (os.replace: a reader never sees half a file); a file that
cannot be read, or is not a finite table of the expected size with 0 <= R <= 1, is built again
and replaced. Tables of other kernel sources are deleted when a new one is written."""
from __future__ import annotations

import hashlib
import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from ..kernel.compile import CACHE_DIR
from ..kernel.rng import batch_state
from ..kernel.surface import cox_munk_table as layout
from .disk_cache import save_atomically

FORMAT_VERSION = 1
WALKS_PER_NODE = 15_000
TABLE_SEED = 20_161_126
TABLE_DIR = CACHE_DIR.parent / "surface_tables"
# the sources a table depends on: the walk, the table's layout and sampler, this builder
_SOURCES = ("kernel/surface/cox_munk.py", "kernel/surface/cox_munk_table.py",
            "kernel/surface/fresnel.py", "kernel/rng.py", "scene/surface_table.py")


def edge_levels(n: int) -> np.ndarray:
    """The cumulative probabilities at the n + 2 TAIL_SPLITS + 1 edges of the cells of
    cox_munk_table.refined_bin: n equal cells, the first and last split by halving toward 0
    and 1."""
    s = layout.TAIL_SPLITS
    low = [0.0] + [2.0 ** -(s - i) / n for i in range(s + 1)]
    middle = [j / n for j in range(2, n - 1)]
    high = [1.0 - 2.0 ** -i / n for i in range(s + 1)] + [1.0]
    return np.array(low + middle + high)


POLAR_LEVELS = edge_levels(layout.POLAR_BINS)
AZIMUTH_LEVELS = edge_levels(layout.AZIMUTH_BINS)


def _sources_hash() -> str:
    digest = hashlib.sha256()
    package = Path(__file__).parents[1]
    for name in _SOURCES:
        digest.update((package / name).read_bytes())
    return digest.hexdigest()[:12]


def cache_path(alpha: float, n_water: float) -> Path:
    key = "|".join(str(v) for v in (
        float(alpha).hex(), float(n_water).hex(), layout.NODES, layout.MU_GRAZING,
        layout.POLAR_BINS, layout.AZIMUTH_BINS, layout.TAIL_SPLITS, WALKS_PER_NODE,
        TABLE_SEED, FORMAT_VERSION))
    return TABLE_DIR / (f"cox_munk-{_sources_hash()}-"
                        f"{hashlib.sha256(key.encode()).hexdigest()[:20]}.npy")


def _usable(table) -> bool:
    reflectances = table[:layout.REFLECTANCES] if isinstance(table, np.ndarray) else None
    return (reflectances is not None and table.dtype == np.float64
            and table.shape == (layout.TABLE_SIZE,) and bool(np.isfinite(table).all())
            and bool(((reflectances >= 0.0) & (reflectances <= 1.0)).all()))


def table(alpha: float, n_water: float) -> np.ndarray:
    """The table of an isotropic surface (Beckmann alpha, n_water), from the cache or built
    (and then cached when the cache folder is writable)."""
    path = cache_path(alpha, n_water)
    try:
        cached = np.load(path, allow_pickle=False)
        if _usable(cached):
            return cached
    except (OSError, ValueError, EOFError):
        pass       # absent, unreadable or corrupt: built again below
    built = build(alpha, n_water)
    if save_atomically(path, built):   # (a read-only location: used without being kept)
        prefix = path.name[:len("cox_munk-") + 12]
        try:
            for old in TABLE_DIR.glob("cox_munk-*.npy"):
                if not old.name.startswith(prefix):
                    old.unlink(missing_ok=True)
        except OSError:
            pass   # another run removed it first
    return built


def _quantiles(t: np.ndarray, az: np.ndarray, w: np.ndarray) -> np.ndarray:
    """One branch's block: the weighted quantiles of t at POLAR_LEVELS, then, for the samples
    of each polar cell (by their cumulative weight), those of az = tan(dphi / 4) at
    AZIMUTH_LEVELS. All cells
    at once: with the samples sorted by (cell, az) and key 2 cell + m (m in (0, 1) the
    cumulative weight within the cell, to each sample's middle), a cell's quantile at level L
    is the key 2 cell + L interpolated, its extreme samples repeated at keys 2 cell and
    2 cell + 1 (a cell no sample falls in, possible only when one sample's weight spans it,
    gets the azimuths between its neighbours')."""
    out = np.zeros(layout.BLOCK)
    if w.size == 0:
        return out      # a branch that never happens at this node (its R or T is 0)
    order = np.argsort(t)
    t, az, w = t[order], az[order], w[order]
    cum = np.cumsum(w)
    mid = (cum - 0.5 * w) / cum[-1]
    out[:layout.POLAR_EDGES] = np.interp(POLAR_LEVELS, mid, t)
    n_cells = layout.POLAR_EDGES - 1
    cells = np.clip(np.searchsorted(POLAR_LEVELS, mid, side="right") - 1, 0, n_cells - 1)
    order = np.argsort(2.0 * cells + az)     # by (cell, az): 0 <= az <= 1 < 2
    cells, az, w = cells[order], az[order], w[order]
    cum = np.cumsum(w)
    totals = np.bincount(cells, weights=w, minlength=n_cells)
    before = np.concatenate(([0.0], np.cumsum(totals)[:-1]))
    m = (cum - before[cells] - 0.5 * w) / totals[cells]
    first = np.flatnonzero(np.diff(cells, prepend=-1))
    last = np.append(first[1:] - 1, cells.size - 1)
    # the samples with each cell's two sentinels around them, in increasing key order
    rank = np.cumsum(np.diff(cells, prepend=-1) != 0) - 1   # the cell's rank among non-empty
    keys = np.empty(cells.size + 2 * first.size)
    values = np.empty_like(keys)
    keys[np.arange(cells.size) + 2 * rank + 1] = 2.0 * cells + m
    values[np.arange(cells.size) + 2 * rank + 1] = az
    keys[first + 2 * np.arange(first.size)] = 2.0 * cells[first]
    values[first + 2 * np.arange(first.size)] = az[first]
    keys[last + 2 * np.arange(first.size) + 2] = 2.0 * cells[last] + 1.0
    values[last + 2 * np.arange(first.size) + 2] = az[last]
    targets = 2.0 * np.arange(n_cells)[:, None] + AZIMUTH_LEVELS[None, :]
    out[layout.POLAR_EDGES:] = np.interp(targets.ravel(), keys, values)
    return out


def _node(alpha: float, n_water: float, side: int, node: int) -> tuple[float, np.ndarray,
                                                                       np.ndarray]:
    """(R, reflected block, transmitted block) of one incidence node."""
    t_i = node / (layout.NODES - 1)
    mu = max(1.0 - t_i * t_i, layout.MU_GRAZING)
    n_incident, n_other = (1.0, n_water) if side == 0 else (n_water, 1.0)
    size = 2 * WALKS_PER_NODE
    branch = np.empty(size, dtype=np.int64)
    t, az, w = np.empty(size), np.empty(size), np.empty(size)
    stream = batch_state(TABLE_SEED, side * layout.NODES + node)
    permutations = np.random.default_rng(stream)
    strata = np.stack([permutations.permutation(WALKS_PER_NODE) for _ in range(3)])
    count = layout.walk_node(alpha, n_incident, n_other, mu, WALKS_PER_NODE, strata, stream,
                             branch, t, az, w)
    branch, t, az, w = branch[:count], t[:count], az[:count], w[:count]
    reflected = branch == layout.REFLECTED
    r = float(w[reflected].sum() / WALKS_PER_NODE)
    blocks = (_quantiles(t[reflected], az[reflected], w[reflected]),
              _quantiles(t[~reflected], az[~reflected], w[~reflected]))
    if node == 0:
        # normal incidence on isotropic slopes: the leaving azimuth is uniform on [0, pi] at
        # every polar angle (symmetry), so its exact quantiles replace the sampled ones
        for block in blocks:
            block[layout.POLAR_EDGES:] = np.tile(np.tan(0.25 * np.pi * AZIMUTH_LEVELS),
                                                 layout.POLAR_EDGES - 1)
    return (min(max(r, 0.0), 1.0),) + blocks


def build(alpha: float, n_water: float, threads: int | None = None) -> np.ndarray:
    """The table (layout: kernel/surface/cox_munk_table.py), built from the walk."""
    out = np.zeros(layout.TABLE_SIZE)
    jobs = [(side, node) for side in (0, 1) for node in range(layout.NODES)]
    with ThreadPoolExecutor(threads or min(2, os.cpu_count() or 1)) as pool:
        results = list(pool.map(lambda job: _node(alpha, n_water, *job), jobs))
    for (side, node), (r, reflected, transmitted) in zip(jobs, results):
        out[side * layout.NODES + node] = r
        out[layout.block_at(side, node, layout.REFLECTED):][:layout.BLOCK] = reflected
        out[layout.block_at(side, node, layout.TRANSMITTED):][:layout.BLOCK] = transmitted
    return out
