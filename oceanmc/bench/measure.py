"""The benchmark's measurements: speed ceiling, feature costs, start-up, error against time."""
from __future__ import annotations

import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Callable

from ..config import load_config
from ..kernel.variants import EVERYTHING
from ..run.hdf5 import load_result
from ..run.simulation import simulate
from ..scene import predicted_variant
from .scenes import FEATURES, QUICK_COLD_START, Quantity, with_photons

# batches per error-vs-time run: the batch standard error, and so the FOM, to about 6% and 12%
FOM_BATCHES = 128


def _value(result, q: Quantity) -> tuple[float, float]:
    v, e = result[q.name], result.stderr(q.name)
    if q.index:
        v, e = v[q.index], e[q.index]
    return float(v), float(e)


def bare_walk_runs(script: Path, photons: int, threads: int, repeats: int) -> list[dict]:
    out = []
    for _ in range(repeats):
        done = subprocess.run([sys.executable, str(script), "--photons", str(photons),
                               "--threads", str(threads)], capture_output=True, text=True,
                              check=True)
        out.append(json.loads(done.stdout.strip().splitlines()[-1]))
    return out


def oceanmc_runs(config, photons: int, threads: int, repeats: int) -> list[float]:
    simulate(with_photons(config, 2 * config.batches), threads=threads)  # warm up
    return [simulate(with_photons(config, photons), threads=threads).attrs["photons_per_s"]
            for _ in range(repeats)]


def speed_ceiling(configs_dir: Path, bare_walk: Path | None, photons: int, repeats: int
                  ) -> dict:
    config = load_config(configs_dir / "bare_walk.yaml")
    record: dict = {"photons": photons, "repeats": repeats}
    for threads in (1, 2):
        ours = oceanmc_runs(config, photons, threads, repeats)
        record[f"oceanmc_{threads}t"] = statistics.median(ours)
        record[f"oceanmc_{threads}t_runs"] = ours
        if bare_walk is not None:
            runs = bare_walk_runs(bare_walk, photons, threads, repeats)
            record[f"bare_{threads}t"] = statistics.median(r["photons_per_s"] for r in runs)
            record[f"bare_{threads}t_runs"] = [r["photons_per_s"] for r in runs]
            record[f"ratio_{threads}t"] = record[f"oceanmc_{threads}t"] / record[f"bare_{threads}t"]
    record["scaling_2t_over_1t"] = record["oceanmc_2t"] / record["oceanmc_1t"]
    if bare_walk is not None:
        record["bare_scaling_2t_over_1t"] = record["bare_2t"] / record["bare_1t"]
        record["scaling_vs_bare"] = record["scaling_2t_over_1t"] \
            / record["bare_scaling_2t_over_1t"]
    return record



def feature_costs(configs_dir: Path, photons: int, repeats: int, quick: bool = False
                  ) -> list[dict]:
    config = load_config(configs_dir / "bare_walk.yaml")
    rows = []
    for label, changes in FEATURES:
        scene = with_photons(config, photons, **changes)
        speeds = oceanmc_runs(scene, photons, 1, repeats)
        rows.append({"variant": label, "photons_per_s_1t": statistics.median(speeds)})
    return rows


STARTUP_PHOTONS = 20_000
# seconds: each a process's wall time, except the cached start's (its kernel load)
COLD_TARGET_S, CACHED_TARGET_S, HELP_TARGET_S, CLI_RUN_TARGET_S = 15.0, 1.0, 0.5, 2.0


def child_env(cache: Path | None = None) -> dict[str, str]:
    """This process's environment for a child: the oceanmc under test first on PYTHONPATH (the
    child times the same code), and the compilation cache moved to `cache` if given."""
    paths = [str(Path(__file__).resolve().parents[2]), os.environ.get("PYTHONPATH")]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(dict.fromkeys(p for p in paths if p)))
    if cache is not None:
        env["OCEANMC_CACHE_DIR"] = str(cache)
    return env


def process_seconds(args: list, env: dict[str, str]) -> float:
    """Wall time of `python -m oceanmc ARGS` in a fresh process, from its start to its exit."""
    command = [sys.executable, "-m", "oceanmc", *map(str, args)]
    t0 = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env=env)
    seconds = time.perf_counter() - t0
    if done.returncode:
        raise RuntimeError(f"{' '.join(command)} failed:\n{done.stderr[-3000:]}")
    return seconds


def whole_loop_seconds(env: dict[str, str]) -> float:
    """Wall time of a fresh process that compiles the photon loop with every optional part
    (run.compiling.ready's default), from its start to its exit."""
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "from oceanmc.run.compiling import ready; ready()"],
                   env=env, check=True, capture_output=True)
    return time.perf_counter() - t0


def run_seconds(config: Path, folder: Path, env: dict[str, str]) -> tuple[float, float]:
    """(process wall time, the result's startup_time_s) of `oceanmc run CONFIG --photons
    STARTUP_PHOTONS`."""
    out = folder / "startup.h5"
    seconds = process_seconds(["run", config, "--photons", STARTUP_PHOTONS, "-o", out,
                               "--overwrite"], env)
    return seconds, float(load_result(out).attrs["startup_time_s"])


def target_row(row: str, scene: str | None, process_s: float, startup_time_s: float | None,
               target: str, target_s: float, **extra) -> dict:
    """A start-up row; target names the measure held to target_s (process_s, startup_time_s)."""
    value = process_s if target == "process_s" else startup_time_s
    return {"row": row, "scene": scene, "process_s": process_s, "startup_time_s": startup_time_s,
            "target": target, "target_s": target_s, "pass": value <= target_s, **extra}


def startup(scenes: list[tuple[str, Path]], folder: Path, quick: bool) -> dict:
    """Start-up rows, each from a fresh process: each scene with an empty cache of its own (with
    quick only QUICK_COLD_START) and again with that cache filled; a scene not started cold uses
    this process's cache, filled if need be by an untimed run first. Then `oceanmc --help`
    (median of 5) and a cached run of the first scene (median of 3)."""
    rows, envs = [], []
    for i, (label, config) in enumerate(scenes):
        cold = not quick or label == QUICK_COLD_START
        env = child_env(folder / f"cache-{i}" if cold else None)
        first = run_seconds(config, folder, env)
        if cold:
            rows.append(target_row("cold start (empty cache)", label, *first, "process_s",
                                   COLD_TARGET_S,
                                   parts=predicted_variant(load_config(config)).label))
        rows.append(target_row("cached start", label, *run_seconds(config, folder, env),
                               "startup_time_s", CACHED_TARGET_S))
        envs.append(env)
    if not quick:
        rows.append(target_row("cold compilation of the whole loop (empty cache)", None,
                               whole_loop_seconds(child_env(folder / "cache-whole")), None,
                               "process_s", COLD_TARGET_S, parts=EVERYTHING.label))
    helps = [process_seconds(["--help"], child_env()) for _ in range(5)]
    rows.append(target_row("`oceanmc --help`, median of 5", None, statistics.median(helps), None,
                           "process_s", HELP_TARGET_S, runs=helps))
    label, config = scenes[0]
    runs = [run_seconds(config, folder, envs[0])[0] for _ in range(3)]
    rows.append(target_row(f"`oceanmc run {label} --photons {STARTUP_PHOTONS}`, cached, "
                           "median of 3", label, statistics.median(runs), None, "process_s",
                           CLI_RUN_TARGET_S, runs=runs))
    return {"photons": STARTUP_PHOTONS, "rows": rows}


def long_run_reference(scene: dict, photons: int, threads: int,
                       progress: Callable[[str], None]) -> tuple[dict, dict, str]:
    """(values, standard errors, description) of the scene's quantities from one long run with
    another seed."""
    config = scene["config"]
    progress(f"  reference run, {photons:,} photons")
    long = simulate(with_photons(config, photons, seed=config.seed + 1000), threads=threads)
    values = {q.label: _value(long, q) for q in scene["quantities"]}
    # a crossing estimate is compared with the long run's local estimate of the same
    # quantity (same expectation, smaller error)
    best = {label: values.get(label.replace("(crossing)", "(local)"), values[label])
            for label in values}
    return ({label: v[0] for label, v in best.items()},
            {label: v[1] for label, v in best.items()},
            f"long run ({photons:,} photons, another seed)")


def error_vs_time(scene: dict, counts: list[int], reference_photons: int, threads: int,
                  progress: Callable[[str], None], reference: tuple | None = None) -> dict:
    """The scene at each photon count against its analytic reference, a long run of its own,
    or `reference` (a long_run_reference shared by scenes with the same expectations)."""
    config = scene["config"]
    if reference is not None:
        reference, reference_se, ref_source = reference
    elif scene["reference"] is None:
        reference, reference_se, ref_source = long_run_reference(scene, reference_photons,
                                                                 threads, progress)
    else:
        reference = scene["reference"]
        reference_se = {label: 0.0 for label in reference}
        ref_source = "analytic"
    rows = []
    for i, photons in enumerate(counts):
        # another seed per count, so the rows of a scene are independent samples
        result = simulate(with_photons(config, photons, seed=config.seed + i,
                                       batches=FOM_BATCHES), threads=threads)
        wall = result.attrs["wall_time_s"]
        for q in scene["quantities"]:
            value, se = _value(result, q)
            ref = reference[q.label]
            rel_se = se / abs(value) if value else math.inf
            rows.append({"photons": photons, "seconds": wall,
                         "photons_per_s": result.attrs["photons_per_s"], "quantity": q.label,
                         "value": value, "stderr": se, "reference": ref,
                         "error": value - ref,
                         "z": (value - ref) / math.hypot(se, reference_se.get(q.label, 0.0))
                         if se > 0 else 0.0,
                         "rel_stderr": rel_se,
                         "fom": 1.0 / (rel_se ** 2 * wall) if rel_se > 0 else math.inf})
        progress(f"  {photons:,} photons: {wall:.2f} s")
    return {"scene": scene["name"], "reference": ref_source, "rows": rows}
