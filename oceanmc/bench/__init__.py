"""`oceanmc bench`: run time against error, the speed ceiling, feature costs, start-up times.

Everything is measured in one run on this machine, so ratios compare like with like:
- speed ceiling: shared/bench/bare_walk.py (a bare compiled random walk, no tallies) against
  oceanmc on the same scene (configs/bare_walk.yaml, tallies at 0 and 1 m), on 1 and 2 threads;
  medians of repeated runs, compilation excluded (both warm up first);
- feature costs: photons/s of the bare-walk scene with each feature added in turn;
- error against time: each scene at increasing photon counts; the error of headline quantities
  against a reference (analytic where there is one, else a long run in the same benchmark);
  the figure of merit FOM = 1 / (rel_err^2 time) per quantity and estimator;
- sky sampling: a sky map with a small bright spot, importance-sampled against cosine-sampled
  (sky_maps.py), error against time for both against one long importance-sampled run, and the
  FOM ratio importance / cosine per quantity;
- start-up, each in a fresh process against a target: `oceanmc run` of four scenes with an
  empty compilation cache of their own (one scene with --quick) and with the cache filled,
  `oceanmc --help`, and a cached 20,000-photon run of configs/default.yaml.
Writes DIR/bench.md, DIR/bench.json and DIR/error_vs_time.png; `--speed` only the speed
ceiling, feature costs and start-up (DIR/speed.md, DIR/speed.json).

scenes.py defines what is run, measure.py runs and times it, report.py writes the report.
"""
from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from .measure import error_vs_time, feature_costs, long_run_reference, speed_ceiling, startup
from .report import (fom_ratios, fom_summary, roulette_ratios, sampling_ratios, upward_ratios,
                     write_report, write_speed_report)
from . import spectral
from .scenes import SKY_SPOT, scenes, sky_spot_map, sky_spot_scenes, startup_scenes


def _startup(configs_dir: Path, quick: bool, say) -> dict:
    say("start-up ...")
    with tempfile.TemporaryDirectory() as tmp:
        return startup(startup_scenes(configs_dir, Path(tmp), quick), Path(tmp), quick)


def main(out_dir: Path, configs_dir: Path, bare_walk: Path | None, quick: bool = False,
         speed_only: bool = False) -> int:
    """The whole benchmark (DIR/bench.md), or with speed_only the speed ceiling, the feature
    costs and the start-up rows alone (DIR/speed.md: what a change to the kernel reports)."""
    import platform

    import numba

    from .. import __version__

    def say(text):
        print(text, flush=True)

    photons = 200_000 if quick else 2_000_000
    repeats = 2 if quick else 5
    counts = [20_000, 80_000] if quick else [250_000, 1_000_000, 4_000_000]
    reference_photons = 200_000 if quick else 16_000_000
    say("speed ceiling ...")
    data = {"machine": f"{platform.machine()}, {os.cpu_count()} cores, "
                       f"{platform.python_implementation()} {platform.python_version()}",
            "date": time.strftime("%Y-%m-%d %H:%M"), "version": __version__,
            "numba": numba.__version__, "quick": quick}
    data["speed_ceiling"] = speed_ceiling(configs_dir, bare_walk, photons, repeats)
    say("feature costs ...")
    data["features"] = feature_costs(configs_dir, photons, repeats, quick)
    if speed_only:
        data["startup"] = _startup(configs_dir, quick, say)
        write_speed_report(out_dir, data)
        say(f"wrote {out_dir / 'speed.md'}")
        return 0
    data["error_vs_time"] = []
    long_runs: dict[str, tuple] = {}
    for scene in scenes(configs_dir):
        say(f"error vs time: {scene['name']} ...")
        if scene["reference"] is None:
            long_runs[scene["name"]] = long_run_reference(scene, reference_photons, 2, say)
        shared = long_runs[scene["reference"]] if isinstance(scene["reference"], str) else None
        data["error_vs_time"].append(error_vs_time(
            scene, counts, reference_photons, 2, say,
            reference=long_runs.get(scene["name"], shared)))
    spot_counts = [10_000, 20_000] if quick else [100_000, 400_000, 1_600_000]
    spot_reference_photons = 40_000 if quick else 8_000_000
    with tempfile.TemporaryDirectory() as tmp:
        pair = sky_spot_scenes(sky_spot_map(Path(tmp) / "sky_spot.npy"))
        say(f"error vs time: {SKY_SPOT} ...")
        values, stderrs, source = long_run_reference(pair[0], spot_reference_photons, 2, say)
        for scene in pair:
            say(f"  {scene['name']}")
            data["error_vs_time"].append(error_vs_time(
                scene, spot_counts, spot_reference_photons, 2, say,
                reference=(values, stderrs, f"{source}, importance sampling")))
    say("spectral: one history against 31 runs ...")
    data["spectral"] = spectral.measure(quick, say)
    # last: with --quick the cached rows use this process's cache, filled by the runs above
    data["startup"] = _startup(configs_dir, quick, say)
    data["fom"] = fom_summary(data["error_vs_time"])
    data["fom_ratios"] = fom_ratios(data["fom"])
    data["roulette_ratios"] = roulette_ratios(data["fom"])
    data["upward_ratios"] = upward_ratios(data["fom"])
    data["sky_sampling"] = sampling_ratios(data["fom"])
    write_report(out_dir, data)
    say(f"wrote {out_dir / 'bench.md'}")
    return 0
