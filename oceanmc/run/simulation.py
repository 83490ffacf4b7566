"""simulate(config) -> Result: packs the scene (prepare: scene/), traces the batches on the
compiled kernel in a thread pool, and hands the tallies to derivation.py.

A batch is traced in short calls (transport.trace_batch continues a batch where the last call
stopped, bit for bit), each given a work budget that keeps it near CALL_SECONDS, so a stop, a
checkpoint and the progress bar wait at most about that long whatever the photon count. A stop
reports the leading whole batches (each batch an equal, independent sample: the mean and
standard error over batches stay exact); the batches begun after them keep their state (random
stream, next photon, entered sun beam, the tallies so far as named arrays) in
Result.resume_state, from which a resumed run continues them exactly."""
from __future__ import annotations

import math
import numbers
import os
import sys
import threading
import time
from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numba
import numpy as np
from tqdm import tqdm

from .. import __version__, scene
from ..optics import iops_table, illumination_spectrum
from ..optics.tables import OutsideTable
from ..config import ConfigError, SceneConfig, config_to_yaml, data_file_hashes, load_config
from ..config.loading import at_file_key
from ..kernel.records import PACKET, packet_state_size, work_size
from ..kernel.rng import STATE_WORDS, batch_state
from ..scene.grid import tally_arrays, tally_views, write_tally_arrays
from .compiling import ready, startup_seconds
from .derivation import RunFacts, run_result
from .merge import MergeError
from .result import Result


LINE_FLOATS = 8                           # a 64-byte cache line of float64
PACKET_STRIDE = 256 // PACKET.itemsize    # packets of two batches 256 bytes apart
RNG_STRIDE = 16                           # random states 128 bytes apart (written at every draw)
RNG_WORDS = 2 * STATE_WORDS               # a batch's two streams (kernel/rng.py batch_state)
# what Batches.unfinished stores of each unfinished batch, beside its tally arrays (tally/...)
RESUME_STATE_KEYS = ("batch", "rng", "beam", "next_photon", "events")
CALL_SECONDS = 0.2      # aimed length of one kernel call: the latency of a stop or a checkpoint
FIRST_BUDGET = 1 << 12  # work units (photons + scattering events) of a batch's first call
MIN_BUDGET = 1 << 8
POLL_SECONDS = 0.25     # how often the main thread looks at stops, checkpoints and progress
ESTIMATE_AFTER_S = 3.0  # tracing time before a run's duration is estimated
LONG_RUN_S = 3600.0     # a run estimated longer than this says so at its start


# the tallies may take this share of the machine's physical memory, counting the RESULT_COPIES
# of them a run holds at its end (the rows, their normalised copy in derivation.from_tallies,
# the temporaries of the means and standard errors written to the file)
MEMORY_SHARE = 0.5
RESULT_COPIES = 3


def row_floats(tally_size: int) -> int:
    """Floats of one batch's tally row: whole cache lines and one more, so that no two batches
    share a line (false sharing; measured: 1.5x instead of 2x on 2 threads)."""
    return -(-tally_size // LINE_FLOATS) * LINE_FLOATS + LINE_FLOATS


def check_tally_memory(config: SceneConfig, sc: scene.Scene) -> None:
    """Raises ConfigError (one line: the estimate and the limit) before anything is allocated
    when the scene's tallies would not fit in memory."""
    try:
        physical = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # no such query here: nothing to compare to
        return
    need = RESULT_COPIES * 8 * config.batches * row_floats(sc.tally_size)
    if physical > 0 and need > MEMORY_SHARE * physical:
        raise ConfigError(
            f"tallies: {config.batches} batches x {sc.tally_size:,} tally values need about "
            f"{need / 2**30:,.1f} GiB, more than the limit of {MEMORY_SHARE * physical / 2**30:.1f}"
            f" GiB ({MEMORY_SHARE:.0%} of this machine's memory); use fewer tallies.depths_m, "
            "wider bands (tallies.theta_edges_deg, tallies.phi_bands), tallies.radiance: false "
            "or fewer batches")


class NonFiniteResult(RuntimeError):
    """A run whose tallies hold NaN or inf. The scene passed validation, so this is a fault of
    oceanmc, not of the scene: refused (one line) rather than returned or written as results."""


def check_finite(result: Result, wavelengths: np.ndarray) -> None:
    """Raises NonFiniteResult naming the first quantity with a NaN or inf in its batches, the
    wavelengths where it has one, and how many other quantities have one too."""
    bad = [(name, q) for name, q in result.quantities.items()
           if not np.isfinite(q.batches).all()]
    if not bad:
        return
    name, q = bad[0]
    flags = ~np.isfinite(q.batches)
    kind = "NaN" if np.isnan(q.batches).any() else "inf"
    if "wavelength" in q.dims:   # after the batch axis
        axis = 1 + q.dims.index("wavelength")
        per_wavelength = flags.any(axis=tuple(i for i in range(flags.ndim) if i != axis))
        at = wavelengths[per_wavelength]
    else:
        at = np.asarray(wavelengths)[:1]
    where = " at " + ", ".join(f"{w:g}" for w in at) + " nm" if np.isfinite(at).all() \
        else ""   # a monochromatic scene's wavelength is nan: none to name
    more = f", and in {len(bad) - 1} other quantit{'y' if len(bad) == 2 else 'ies'}" \
        if len(bad) > 1 else ""
    raise NonFiniteResult(
        f"the run produced non-finite values ({kind}) in {name}{where}{more}: a fault of "
        "oceanmc, not of the scene, which passed validation; no results were written; please "
        "report it with the scene file")


def next_budget(budget: int, seconds: float) -> int:
    """The work budget of a batch's next call from the last one's: scaled toward CALL_SECONDS,
    by at most 4x per call. The budget only decides where calls end, never what is traced."""
    factor = min(4.0, max(0.25, CALL_SECONDS / max(seconds, 1e-6)))
    return int(min(max(budget * factor, MIN_BUDGET), 1 << 40))


def _duration(seconds: float) -> str:
    return f"{seconds / 3600:.1f} h" if seconds < 48 * 3600 else f"{seconds / 86400:.1f} days"


@dataclass(frozen=True)
class PreparedRun:
    """A scene ready to trace, made once per run by prepare(): `oceanmc run` checks every scene
    this way before the first runs, then hands each to simulate as it is."""
    config: SceneConfig
    scene: scene.Scene
    facts: RunFacts     # fixed for the run: the derivation's, and the illumination spectrum
    scene_yaml: str     # the resolved scene as stored (with a spectrum's Ed(0+) noted)
    data_hashes: str    # data_files_sha256: the data files the scene names, as the build read


def prepare(config: SceneConfig) -> PreparedRun:
    """Packs a validated scene and computes its illumination spectrum, once. Raises
    ConfigError (one line) for unusable auxiliary files or tallies too large for memory."""
    data_hashes = data_file_hashes(config)   # before the build reads them
    try:
        ed0, diffuse, _ = illumination_spectrum(config)
        sc = scene.build(config, (ed0, diffuse))
    except OutsideTable as exc:
        raise ConfigError(at_file_key(exc.explained(config.added_wavelengths), config)) \
            from None
    except ConfigError as exc:   # (a table's own checks name the file: the key named too)
        raise type(exc)(at_file_key(str(exc), config)) from None
    check_tally_memory(config, sc)
    return PreparedRun(config, sc, RunFacts.of(config, sc, ed0, diffuse),
                       config_to_yaml(config, (ed0, diffuse)), data_hashes)


class Batches:
    """The state of batches first .. config.batches-1 between kernel calls, each batch's on
    cache lines of its own: random streams (the photons', then the inelastic emissions'), next
    photon (-1: not begun), entered sun beam (weight per sun packet, direction), scattering
    events, tally row, packet, the stack its split copies and emitted packets wait on, their
    spectral state (kernel/packet.py) and one event's scratch. A batch's lock is held through
    each of its calls, so that a snapshot copies its state between two calls."""

    def __init__(self, run: PreparedRun, first: int) -> None:
        config, sc = run.config, run.scene
        self.first, self.grid = first, sc.grid
        self.photons_per_batch = run.facts.photons_per_batch
        n = config.batches - first
        self.rngs = np.zeros((n, RNG_STRIDE), dtype=np.uint64)
        for b in range(n):
            self.rngs[b, :STATE_WORDS] = batch_state(config.seed, first + b)
            self.rngs[b, STATE_WORDS:RNG_WORDS] = batch_state(config.seed, first + b, 1)
        self.beams = np.zeros((n, 4))
        self.beams[:, 3] = 1.0
        self.next_photon = np.full(n, -1, dtype=np.int64)
        self.events = np.zeros(n, dtype=np.int64)
        self.tallies = np.zeros((n, row_floats(sc.tally_size)))
        self.packets = np.zeros((n, PACKET_STRIDE), dtype=PACKET)
        self.stacks = np.zeros((n, sc.stack_rows), dtype=PACKET)
        n_wl = len(config.wavelengths)
        n_parts = int(sc.grid[0]["n_parts"])
        self.states = np.zeros((n, sc.stack_rows + 1,
                                row_floats(packet_state_size(n_wl, n_parts))))
        self.work = np.zeros((n, row_floats(work_size(n_wl, n_parts))))
        self.locks = [threading.Lock() for _ in range(n)]
        self.stopping = threading.Event()

    def __len__(self) -> int:
        return len(self.next_photon)

    def trace(self, b: int, trace: Callable, args: tuple) -> None:
        """Traces batch b to its end in calls of about CALL_SECONDS, or until stopping."""
        budget = FIRST_BUDGET
        while not self.stopping.is_set():
            with self.locks[b]:
                if self.next_photon[b] >= self.photons_per_batch:
                    return
                t = time.perf_counter()
                self.next_photon[b], n_events = trace(
                    *args, self.photons_per_batch, self.next_photon[b], budget,
                    self.rngs[b, :STATE_WORDS], self.rngs[b, STATE_WORDS:RNG_WORDS],
                    self.beams[b], self.tallies[b], self.packets[b, :1], self.stacks[b],
                    self.states[b], self.work[b])
                self.events[b] += n_events
            budget = next_budget(budget, time.perf_counter() - t)

    def photons(self) -> int:
        """Photons traced so far."""
        return int(np.maximum(self.next_photon, 0).sum())

    def whole(self) -> int:
        """How many leading batches are whole."""
        done = 0
        while done < len(self) and self.next_photon[done] >= self.photons_per_batch:
            done += 1
        return done

    def unfinished(self, done: int) -> dict[str, np.ndarray] | None:
        """The state of the batches begun after the `done` leading whole ones (a Result's
        resume_state), None if none is. The tallies as named arrays (tally/flux, ...), not raw
        rows: the row's layout is the kernel's to change, a file's state stays readable."""
        begun = [b for b in range(done, len(self)) if self.next_photon[b] >= 0]
        if not begun:
            return None
        scores = tally_arrays(self.grid, self.tallies)
        state = {"batch": np.array(begun, dtype=np.int64) + self.first,
                 "rng": np.empty((len(begun), RNG_WORDS), dtype=np.uint64),
                 "beam": np.empty((len(begun), 4)),
                 "next_photon": np.empty(len(begun), dtype=np.int64),
                 "events": np.empty(len(begun), dtype=np.int64)}
        state.update({f"tally/{name}": np.empty((len(begun),) + values.shape[1:])
                      for name, values in scores.items()})
        for k, b in enumerate(begun):
            with self.locks[b]:
                state["rng"][k] = self.rngs[b, :RNG_WORDS]
                state["beam"][k] = self.beams[b]
                state["next_photon"][k] = self.next_photon[b]
                state["events"][k] = self.events[b]
                for name, values in scores.items():
                    state[f"tally/{name}"][k] = values[b]
        return state

    def restore(self, state: dict[str, np.ndarray]) -> None:
        """Puts a partial run's unfinished batches (Result.resume_state) back where they
        stopped, their tally rows rebuilt from the named score arrays. Raises MergeError (one
        line: the CLI's --resume says it and exits 2) when those arrays or batches are not this
        scene's, or the state is not a partial Result's."""
        missing = [key for key in RESUME_STATE_KEYS if key not in state]
        if missing:
            raise MergeError(f"the stored unfinished batches lack {', '.join(missing)}: "
                             "allowed a partial Result's resume_state")
        count = len(np.atleast_1d(state["batch"]))
        uneven = [key for key in RESUME_STATE_KEYS if np.ndim(state[key]) < 1
                  or len(state[key]) != count
                  or (key == "rng" and not 0 < np.shape(state[key])[-1] <= RNG_WORDS)]
        if uneven:
            raise MergeError(f"the stored unfinished batches' {', '.join(uneven)} do not hold "
                             f"one row for each of their {count} batches: allowed a partial "
                             "Result's resume_state")
        problem = self.state_problem(state)
        if problem:
            raise MergeError(f"the stored unfinished batches are damaged ({problem}): allowed "
                             "a partial Result's resume_state")
        rows = np.zeros((count, self.tallies.shape[1]))
        try:
            write_tally_arrays(self.grid, {key.removeprefix("tally/"): values
                                           for key, values in state.items()
                                           if key.startswith("tally/")}, rows)
        except ValueError as exc:
            raise MergeError(f"the stored unfinished batches' tallies do not fit this scene: "
                             f"{exc}") from None
        for k, batch in enumerate(state["batch"]):
            b = int(batch) - self.first
            if not 0 <= b < len(self):
                raise MergeError(f"stored unfinished batch {batch} is outside {self.first} .. "
                                 f"{self.first + len(self) - 1}")
            # (a file from before the second stream holds the first only: the second starts
            # anew)
            self.rngs[b, :state["rng"].shape[1]] = state["rng"][k]
            self.beams[b] = state["beam"][k]
            self.next_photon[b] = state["next_photon"][k]
            self.events[b] = state["events"][k]
            self.tallies[b] = rows[k]

    def state_problem(self, state: dict[str, np.ndarray]) -> str:
        """What in a stored state no run writes, '' if nothing: a photon count outside the
        batch's, a random stream of all zeros (xoshiro's one degenerate state), an entered sun
        beam of no finite weight or no unit direction, negative events. (Edited by hand, such
        a state resumed with exit status 0 and wrong tallies, or a segfault: a user's
        review.) The tallies so far cannot be checked this way: any finite values are some
        run's."""
        next_photon = np.asarray(state["next_photon"])
        if np.any((next_photon < -1) | (next_photon > self.photons_per_batch)):
            return f"next photon outside -1 .. {self.photons_per_batch}"
        rng = np.asarray(state["rng"]).reshape(len(next_photon), -1)
        if np.any(np.all(rng[:, :STATE_WORDS] == 0, axis=1)):
            return "a random stream of all zeros"
        beam = np.asarray(state["beam"], dtype=np.float64).reshape(len(next_photon), -1)
        if beam.shape[1] != 4 or not np.all(np.isfinite(beam)) or np.any(beam[:, 0] < 0.0) \
                or np.any(np.abs(np.sum(beam[:, 1:] ** 2, axis=1) - 1.0) > 1e-9):
            return "an entered sun beam without a finite weight and a unit direction"
        if np.any(np.asarray(state["events"]) < 0):
            return "negative scattering events"
        return ""


def run_attrs(run: PreparedRun, batches: Batches, done: int, threads: int, wall: float,
              startup: float) -> dict[str, object]:
    """The attributes of a Result of the `done` leading whole batches, traced in `wall`
    seconds after a start-up (the kernel compiled or loaded) of `startup` seconds."""
    config, facts = run.config, run.facts
    photons = done * facts.photons_per_batch
    attrs = {
        "name": config.name,
        "config_yaml": run.scene_yaml,
        "data_files_sha256": run.data_hashes,
        "oceanmc_version": __version__,
        "numba_version": numba.__version__,
        "seed": config.seed,
        "photons": photons,
        "batches": done,
        "first_batch": batches.first,
        "photons_per_batch": facts.photons_per_batch,
        "partial": batches.first + done < config.batches,
        "threads": threads,
        "wall_time_s": wall,
        "startup_time_s": startup,
        "photons_per_s": photons / wall if wall > 0 else float("inf"),
        "scattering_events": int(batches.events[:done].sum()),
        # Ed(0+) and its diffuse (sky) share per wavelength, as the run used them (from
        # illumination's Ed0 and diffuse_fraction, or its spectrum model or table)
        "illumination_Ed0": np.asarray(facts.ed0, dtype=np.float64),
        "illumination_diffuse_fraction": np.asarray(facts.diffuse, dtype=np.float64),
        # estimator.depth_splitting as decided for the scene, and why (scene/weight_window.py)
        "depth_splitting": run.scene.depth_splitting,
        # estimator.upward_fraction as it ran, 0 for none (auto is left in the stored config
        # of a one-wavelength scene: scene/weight_window.upward_fraction)
        "upward_fraction": run.scene.upward_fraction,
    }
    if facts.inelastic:
        # the outputs' parts (derivation.add_parts), and the wavelengths traced for the
        # excitation of inelastic light beyond those asked for (config/inelastic.py)
        attrs["inelastic_parts"] = " ".join(facts.parts)
        attrs["wavelengths_added_nm"] = np.asarray(config.added_wavelengths, dtype=float)
    return attrs


def simulate(config: PreparedRun | SceneConfig | dict[str, Any] | str | Path, *,
             threads: int | None = None, progress: bool = False, first_batch: int = 0,
             should_stop: Callable[[], bool] | None = None,
             on_checkpoint: Callable[[Result], None] | None = None,
             checkpoint_every_s: float = 60.0,
             resume_state: dict[str, np.ndarray] | None = None) -> Result:
    """Runs a scene (a SceneConfig, a dict, a YAML path, or one prepare() packed) and returns
    its Result.

    Batches first_batch .. batches-1 are traced, `threads` at a time (a resumed run starts
    after the whole batches it already has; batch b is the same whatever the start), continuing
    those in resume_state (a partial Result's) where they stopped. Every CALL_SECONDS or so,
    should_stop() may end the run early: the Result then holds the leading whole batches, the
    state of the later ones begun, and is marked partial. on_checkpoint(result) receives such a
    partial Result every checkpoint_every_s seconds. progress: a progress bar on stderr, and a
    notice there when the run looks like taking more than an hour. A NaN or inf in the
    tallies (a fault of oceanmc) raises NonFiniteResult, at the end or at a checkpoint."""
    if not isinstance(config, (PreparedRun, SceneConfig)):
        config = load_config(config)
    if not (math.isfinite(checkpoint_every_s) and checkpoint_every_s >= 0.0):
        # (a NaN would never checkpoint: every comparison with it is false)
        raise ValueError(f"checkpoint_every_s = {checkpoint_every_s}: allowed a finite number "
                         "of seconds >= 0")
    # batches run in threads (trace_batch releases the GIL); NUMBA_NUM_THREADS (default: the
    # number of cores) is the default and the most
    if threads is not None and (isinstance(threads, bool)
                                or not isinstance(threads, numbers.Integral) or threads < 1):
        raise ValueError(f"threads = {threads!r}: allowed an integer >= 1 (or None: every "
                         "core)")
    n_threads = numba.config.NUMBA_NUM_THREADS if threads is None \
        else min(int(threads), numba.config.NUMBA_NUM_THREADS)
    # compiles the kernel's variant for the scene (or loads it from the cache) before the scene
    # is packed, which uses it; the time it took (here or before: cli.py) is the first run's
    # start-up
    trace, variant = ready(config.scene.variant if isinstance(config, PreparedRun)
                           else scene.predicted_variant(config), should_stop)
    run = config if isinstance(config, PreparedRun) else prepare(config)
    config, sc = run.config, run.scene
    if not variant.holds(sc.variant):   # the prediction from the config missed a part
        trace, variant = ready(sc.variant, should_stop)
    startup = startup_seconds()
    if not 0 <= first_batch < config.batches:
        raise ValueError(f"first_batch = {first_batch}: allowed 0 .. {config.batches - 1}")
    batches = Batches(run, first_batch)
    if resume_state is not None:
        batches.restore(resume_state)
    views = [tally_views(sc.grid, batches.tallies, j) for j in range(len(config.wavelengths))]
    args = sc.kernel_args() + variant.kernel_args()

    def result_of(wall: float) -> Result:
        """The leading whole batches, and the state of the later ones begun."""
        done = batches.whole()
        state = batches.unfinished(done)
        attrs = run_attrs(run, batches, done, n_threads, wall, startup)
        unit = scene.surface.reflected_local(config, sc.surface[0], first_batch, done) \
            if config.tallies.local_directions_deg else None
        reflected = None if unit is None else \
            [scene.surface.reflected_at(unit, ed0, diffuse)
             for ed0, diffuse in zip(run.facts.ed0, run.facts.diffuse)]
        result = run_result(views, done, run.facts, attrs, reflected)
        # before a checkpoint or the end hands it on to be written or returned
        check_finite(result, config.wavelengths)
        result.resume_state = state
        result.iops = iops_table(sc.layers, config.wavelengths, sc.bottom_reflectance)
        return result

    photons_before = batches.photons()
    t1 = last_checkpoint = time.perf_counter()
    estimated = False
    with tqdm(total=len(batches) * batches.photons_per_batch, initial=photons_before,
              unit="photon", unit_scale=True, delay=1.0, disable=not progress,
              desc=config.name[:40], leave=False) as bar, \
            ThreadPoolExecutor(max_workers=n_threads) as pool:
        # every batch queued at once, in order: they finish in about that order, so a stop
        # leaves few begun batches after the whole ones
        futures = [pool.submit(batches.trace, b, trace, args) for b in range(len(batches))]
        try:
            while True:
                finished, running = wait(futures, timeout=POLL_SECONDS,
                                         return_when=FIRST_EXCEPTION)
                for future in finished:
                    future.result()   # a batch's exception, raised here
                photons_now = batches.photons()
                bar.update(photons_now - bar.n)
                if not running:
                    break
                if should_stop is not None and should_stop():
                    break
                now = time.perf_counter()
                if progress and not estimated and now - t1 >= ESTIMATE_AFTER_S \
                        and photons_now > photons_before:
                    estimated = True
                    rate = (photons_now - photons_before) / (now - t1)
                    left = (len(batches) * batches.photons_per_batch - photons_now) / rate
                    if left > LONG_RUN_S:
                        bar.write(f"oceanmc: {config.name}: about {_duration(left)} to go at "
                                  f"{rate:,.0f} photons/s; Ctrl-C stops it within seconds and "
                                  "writes what is done (--resume continues it)", file=sys.stderr)
                if on_checkpoint is not None and now - last_checkpoint >= checkpoint_every_s:
                    on_checkpoint(result_of(now - t1))
                    last_checkpoint = now
        finally:
            # the calls in flight end within about CALL_SECONDS; batches not begun never start
            batches.stopping.set()
            for future in futures:
                future.cancel()
            wait(futures)
    for future in futures:
        if not future.cancelled():
            future.result()
    return result_of(time.perf_counter() - t1)
