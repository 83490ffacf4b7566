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
- start-up: the first run with an empty compilation cache, and a run with the cache filled.
Writes DIR/bench.md, DIR/bench.json and DIR/error_vs_time.png.
"""
from __future__ import annotations

import copy
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from .config import load_config
from .kernel.surface.fresnel import fresnel
from .run.simulation import simulate


@dataclass
class Quantity:
    label: str
    name: str            # Result key
    index: tuple = ()    # index into the Result array


def _value(result, q: Quantity) -> tuple[float, float]:
    v, e = result[q.name], result.stderr(q.name)
    if q.index:
        v, e = v[q.index], e[q.index]
    return float(v), float(e)


# --- references --------------------------------------------------------------------------------

def snell_window_reference(config) -> dict[str, float]:
    """Uniform sky, black clear water: Ed(0-) = Ed0 (1 - r) with r the cosine-weighted Fresnel
    reflectance, and the 0-5 deg downward cap radiance just below the surface =
    average over the cap of t(theta_air) n^2 L_sky, L_sky = Ed0 / pi (DESIGN.md section 4)."""
    n = config.surface.n_water
    ed0 = config.illumination.Ed0
    mu = np.linspace(0.0, 1.0, 20001)[1:]
    r = np.array([fresnel(1.0, n, m)[0] for m in mu])
    ed_0minus = ed0 * (1.0 - np.trapezoid(2.0 * r * mu, mu))
    mu_w = np.linspace(math.cos(math.radians(5.0)), 1.0, 2001)
    sin_a = np.sqrt(1.0 - mu_w ** 2) * n
    t = np.array([1.0 - fresnel(1.0, n, math.sqrt(1.0 - s * s))[0] for s in sin_a])
    cap = np.trapezoid(t * n * n * ed0 / math.pi, mu_w) / (1.0 - mu_w[0])
    return {"Ed(0-)": float(ed_0minus), "L cap down (0-)": float(cap)}


# --- scenes ------------------------------------------------------------------------------------

def without_exact_directions(config):
    return with_photons(config, config.photons, **{"tallies.local_directions_deg": []})


CROSSING_ONLY = ", crossing estimator only"
NO_ROULETTE = ", roulette at weight 1e-12"
UPWARD_FRACTION = 0.1
UPWARD = f", upward-biased scattering (fraction {UPWARD_FRACTION:g})"
# batches per error-vs-time run: the batch standard error, and so the FOM, to about 6% and 12%
FOM_BATCHES = 128


def scenes(configs_dir: Path) -> list[dict]:
    """The benchmark scenes with their headline quantities and references: None (a long run
    of their own), a scene's name (that scene's long run) or a dict of analytic values."""
    def cfg(name):
        return load_config(configs_dir / name)
    snell = cfg("snell_window.yaml")
    bare = cfg("bare_walk.yaml")
    # their headline quantities come from the cap estimates: the exact-nadir local estimates of
    # the example configs (a Petzold phase-function evaluation per collision) are left out
    clear, shallow = (without_exact_directions(cfg(name))
                      for name in ("clear_ocean.yaml", "coastal_sand.yaml"))
    return [
        {"name": "bare walk", "config": bare, "reference": None,
         "quantities": [Quantity("reflectance (water-leaving)", "budget/water_leaving"),
                        Quantity("Ed(1 m)", "Ed", (1,))]},
        {"name": "clear ocean", "config": clear, "reference": None,
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Rrs nadir (crossing)", "air/Rrs_nadir_crossing"),
                        Quantity("Lu(10 m) (local)", "Lu", (2,)),
                        Quantity("Lu(10 m) (crossing)", "Lu_crossing", (2,)),
                        Quantity("Ed(10 m)", "Ed", (2,))]},
        # plain photon counting on its own: the fair time for the crossing estimates
        {"name": f"clear ocean{CROSSING_ONLY}", "reference": "clear ocean",
         "config": with_photons(clear, clear.photons, **{"tallies.nadir_estimator": "crossing"}),
         "quantities": [Quantity("Rrs nadir (crossing)", "air/Rrs_nadir"),
                        Quantity("Lu(10 m) (crossing)", "Lu", (2,)),
                        Quantity("Ed(10 m)", "Ed", (2,))]},
        # Russian roulette's worth: the same scene with roulette at a weight packets never
        # reach in practice (they are followed until they leave or the weight underflows)
        {"name": f"clear ocean{NO_ROULETTE}", "reference": "clear ocean",
         "config": with_photons(clear, clear.photons, **{"estimator.roulette_weight": 1e-12}),
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Lu(10 m) (local)", "Lu", (2,)),
                        Quantity("Ed(10 m)", "Ed", (2,))]},
        # scattering biased toward straight up: the same expectations, so the plain scene's
        # long run is its reference
        {"name": f"clear ocean{UPWARD}", "reference": "clear ocean",
         "config": with_photons(clear, clear.photons,
                                **{"estimator.upward_fraction": UPWARD_FRACTION}),
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Rrs nadir (crossing)", "air/Rrs_nadir_crossing"),
                        Quantity("Lu(10 m) (local)", "Lu", (2,)),
                        Quantity("Lu(10 m) (crossing)", "Lu_crossing", (2,)),
                        Quantity("Ed(10 m)", "Ed", (2,))]},
        {"name": "shallow sand", "config": shallow, "reference": None,
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Rrs nadir (crossing)", "air/Rrs_nadir_crossing"),
                        Quantity("Eu(0-)", "Eu", (0,))]},
        {"name": f"shallow sand{UPWARD}", "reference": "shallow sand",
         "config": with_photons(shallow, shallow.photons,
                                **{"estimator.upward_fraction": UPWARD_FRACTION}),
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Rrs nadir (crossing)", "air/Rrs_nadir_crossing"),
                        Quantity("Eu(0-)", "Eu", (0,))]},
        {"name": "Snell's window", "config": snell, "reference": snell_window_reference(snell),
         "quantities": [Quantity("Ed(0-)", "Ed", (0,)),
                        Quantity("L cap down (0-)", "radiance", (0, 0, 0))]},
    ]


SPOT_ZENITH_DEG = 40.0       # the bright spot's centre, seen at phi_view = 180 deg
SPOT_RADIUS_DEG = 2.0
SPOT_CONTRAST = 1000.0       # spot radiance over the background's
IMPORTANCE, COSINE = "(importance sampling)", "(cosine sampling)"
SPLIT_WEIGHT = 2.0
COSINE_SPLIT = f"(cosine sampling, split_weight {SPLIT_WEIGHT:g})"
SKY_SPOT = "sky map with a small bright spot"


def sky_spot_map(path: Path) -> Path:
    """Writes a 1 x 1 deg sky map (.npy): radiance 1, and SPOT_CONTRAST inside the cells whose
    centres lie within SPOT_RADIUS_DEG of the spot's centre (20 cells, ~0.004 sr, half of the
    sky's irradiance)."""
    theta = np.radians(np.arange(90) + 0.5)[:, None]
    phi = np.radians(np.arange(360) + 0.5)[None, :]
    centre = math.radians(SPOT_ZENITH_DEG)
    cos_from_centre = (np.cos(theta) * math.cos(centre)
                       + np.sin(theta) * math.sin(centre) * np.cos(phi - math.pi))
    inside = cos_from_centre >= math.cos(math.radians(SPOT_RADIUS_DEG))
    np.save(path, np.where(inside, SPOT_CONTRAST, 1.0))
    return path


def sky_spot_scenes(map_path: Path) -> list[dict]:
    """The spot map over clear, weakly scattering deep water, all light from the sky, sampled
    by importance, cosine-weighted, and cosine-weighted with splitting of the heavy packets
    (the spot's, weight ~500): the same expectations, so one reference serves all three."""
    def config(sampling, split_weight=None):
        return load_config({
            "name": f"{SKY_SPOT}, {sampling} sampling", "seed": 1,
            "estimator": {"split_weight": split_weight},
            "illumination": {"Ed0": 1.0, "diffuse_fraction": 1.0,
                             "sky": {"map": str(map_path), "sampling": sampling}},
            "water": {"layers": [{"thickness_m": math.inf, "a": 0.1, "b": 0.2,
                                  "phase": {"model": "henyey_greenstein", "g": 0.9}}]},
            "bottom": {"model": "none"}, "tallies": {"depths_m": [0.0, 5.0]}})
    importance = config("importance")
    # the spot's light travels at phi = 0 (phi_view + 180 deg), refracted by Snell's law
    n = importance.surface.n_water
    refracted = math.degrees(math.asin(math.sin(math.radians(SPOT_ZENITH_DEG)) / n))
    band = int(np.searchsorted(importance.tallies.theta_edges, refracted, side="right")) - 1
    quantities = [Quantity("Ed(0-)", "Ed", (0,)), Quantity("Ed(5 m)", "Ed", (1,)),
                  Quantity("Eou(0-)", "Eou", (0,)), Quantity("Lu(0-) (local)", "Lu", (0,)),
                  Quantity(f"L of the spot's quad (0-, {refracted:.1f} deg)", "radiance",
                           (0, band, 0))]
    return [{"name": f"{SKY_SPOT} {IMPORTANCE}", "config": importance, "reference": None,
             "quantities": quantities},
            {"name": f"{SKY_SPOT} {COSINE}", "config": config("cosine"), "reference": None,
             "quantities": quantities},
            {"name": f"{SKY_SPOT} {COSINE_SPLIT}", "config": config("cosine", SPLIT_WEIGHT),
             "reference": None, "quantities": quantities}]


def with_photons(config, photons: int, **changes):
    data = copy.deepcopy(config.model_dump())
    data["photons"] = int(photons)
    for path, value in changes.items():
        node = data
        keys = path.split(".")
        for key in keys[:-1]:
            node = node[key]
        node[keys[-1]] = value
    return load_config(data)


# --- measurements ------------------------------------------------------------------------------

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
    return record


FEATURES: list[tuple[str, dict]] = [
    ("no tallies at all", {"tallies.depths_m": [], "tallies.radiance": False,
                           "tallies.nadir_estimator": "crossing"}),
    ("irradiances at 0, 1 m (radiance off)", {"tallies.radiance": False,
                                              "tallies.nadir_estimator": "crossing"}),
    ("+ radiance quads (the bare-walk config)", {}),
    ("+ local nadir-cap estimate", {"tallies.nadir_estimator": "local"}),
    ("+ local estimate, exact nadir", {"tallies.nadir_estimator": "local",
                                       "tallies.local_directions_deg": [[180.0, 0.0]]}),
    ("+ sky (20% uniform)", {"illumination.diffuse_fraction": 0.2}),
    ("+ Lambertian bottom (0.3)", {"bottom": {"model": "lambertian", "reflectance": 0.3}}),
    (f"+ upward-biased scattering (fraction {UPWARD_FRACTION:g}; shorter histories)",
     {"estimator.upward_fraction": UPWARD_FRACTION}),
    ("no surface (index-matched)", {"surface.model": "none"}),
    ("analog estimator", {"estimator.mode": "analog"}),
]


# the --quick smoke test measures only these (each other row compiles a loop of its own)
QUICK_FEATURES = ("no tallies at all", "+ local nadir-cap estimate")


def feature_costs(configs_dir: Path, photons: int, repeats: int, quick: bool = False
                  ) -> list[dict]:
    config = load_config(configs_dir / "bare_walk.yaml")
    rows = []
    for label, changes in FEATURES:
        if quick and label not in QUICK_FEATURES:
            continue
        scene = with_photons(config, photons, **changes)
        speeds = oceanmc_runs(scene, photons, 1, repeats)
        rows.append({"variant": label, "photons_per_s_1t": statistics.median(speeds)})
    return rows


def startup_times(cold: bool = True) -> dict:
    """Seconds from process start to the end of a tiny run: with an empty cache (compiles),
    then with that cache filled (only the latter when cold is False)."""
    code = ("import time; t0 = time.perf_counter(); import oceanmc; "
            "r = oceanmc.simulate({'photons': 64, 'batches': 2, 'water': {'layers': "
            "[{'thickness_m': 1, 'a': 0.1, 'b': 0.5}]}, 'bottom': {'model': 'black'}}); "
            "print(time.perf_counter() - t0, r.attrs['startup_time_s'])")
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, OCEANMC_CACHE_DIR=cache) if cold else dict(os.environ)
        for label in (("cold (empty cache)", "cached") if cold else ("cached",)):
            done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                  env=env, check=True)
            total, kernel = (float(x) for x in done.stdout.split())
            out[label] = {"process_s": total, "kernel_load_or_compile_s": kernel}
    return out


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


# --- report ------------------------------------------------------------------------------------

def fom_summary(curves: list[dict]) -> list[dict]:
    out = []
    for curve in curves:
        by_q: dict[str, list[float]] = {}
        for row in curve["rows"]:
            by_q.setdefault(row["quantity"], []).append(row["fom"])
        for label, foms in by_q.items():
            out.append({"scene": curve["scene"], "quantity": label,
                        "fom_median": statistics.median(foms)})
    return out


def plot(curves: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ncols = min(3, len(curves))
    nrows = -(-len(curves) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.6 * ncols, 4 * nrows), squeeze=False)
    for ax in axes.flat[len(curves):]:
        ax.set_visible(False)
    for ax, curve in zip(axes.flat, curves):
        labels = sorted({r["quantity"] for r in curve["rows"]})
        for label in labels:
            rows = [r for r in curve["rows"] if r["quantity"] == label]
            t = np.array([r["seconds"] for r in rows])
            rel = np.array([r["rel_stderr"] for r in rows])
            err = np.array([abs(r["error"] / r["reference"]) if r["reference"] else np.nan
                            for r in rows])
            line, = ax.loglog(t, rel, "o-", label=label)
            ax.loglog(t, err, "x", color=line.get_color(), alpha=0.6)
            ax.loglog(t, rel[0] * np.sqrt(t[0] / t), ":", color=line.get_color(), alpha=0.5)
        ax.set_title(curve["scene"], fontsize=9)
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel("relative error (o: std err, x: |error| vs ref)")
        ax.legend(fontsize=6)
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle("error against run time; dotted: 1/sqrt(t)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_report(out_dir: Path, data: dict) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "bench.json").write_text(json.dumps(data, indent=1))
    plot(data["error_vs_time"], out_dir / "error_vs_time.png")
    s = data["speed_ceiling"]
    lines = ["# oceanmc benchmark", "",
             f"Machine: {data['machine']}; {data['date']}; oceanmc {data['version']}, "
             f"numba {data['numba']}. Regenerate with `oceanmc bench -o {out_dir}`.", "",
             "## Speed ceiling (bare-walk scene: tau = 1, albedo 0.9, isotropic, n = 1.34, "
             "pencil beam)", "",
             f"Medians of {s['repeats']} runs of {s['photons']:,} photons, compilation "
             "excluded; oceanmc tallies Ed, Eu, Eod, Eou and radiance quads at 0 and 1 m.", "",
             "| threads | bare walk photons/s | oceanmc photons/s | ratio |", "|---|---|---|---|"]
    for t in (1, 2):
        bare = s.get(f"bare_{t}t")
        lines.append(f"| {t} | {bare:,.0f} | {s[f'oceanmc_{t}t']:,.0f} | "
                     f"{s[f'ratio_{t}t']:.2f} |" if bare else
                     f"| {t} | (not found) | {s[f'oceanmc_{t}t']:,.0f} | - |")
    lines += ["", f"Scaling of oceanmc from 1 to 2 threads: {s['scaling_2t_over_1t']:.2f}x.", "",
              "## What each feature costs (bare-walk scene, 1 thread, medians)", "",
              "| variant | photons/s |", "|---|---|"]
    for row in data["features"]:
        lines.append(f"| {row['variant']} | {row['photons_per_s_1t']:,.0f} |")
    lines += ["", "## Start-up", "", "| | process start to end of a tiny run (s) | "
              "kernel load or compile (s) |", "|---|---|---|"]
    for label, row in data["startup"].items():
        lines.append(f"| {label} | {row['process_s']:.2f} | {row['kernel_load_or_compile_s']:.2f} |")
    lines += ["", "## Error against run time", "",
              "FOM = 1 / (relative standard error^2 x wall time), median over the photon "
              "counts; `z` is (value - reference) / combined standard error.", "",
              "![error vs time](error_vs_time.png)", ""]
    for curve in data["error_vs_time"]:
        lines += [f"### {curve['scene']} (reference: {curve['reference']})", "",
                  "| photons | s | quantity | value | std err | reference | z | FOM |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in curve["rows"]:
            lines.append(f"| {r['photons']:,} | {r['seconds']:.2f} | {r['quantity']} | "
                         f"{r['value']:.6g} | {r['stderr']:.2g} | {r['reference']:.6g} | "
                         f"{r['z']:.2f} | {r['fom']:.3g} |")
        lines.append("")
    lines += ["## Figure of merit by quantity and estimator", "",
              "| scene | quantity | FOM (median) |", "|---|---|---|"]
    for row in data["fom"]:
        lines.append(f"| {row['scene']} | {row['quantity']} | {row['fom_median']:.3g} |")
    ratios = data.get("fom_ratios", {})
    if ratios:
        lines += ["", "Local over crossing estimator, same quantity and scene:", ""]
        for key, value in ratios.items():
            lines.append(f"- {key}: {value:.1f}x")
    roulette = data.get("roulette_ratios", {})
    if roulette:
        lines += ["", "Russian roulette at its defaults (weight 1e-3, survival 0.1) over roulette "
                  "at weight 1e-12 (packets followed until they leave or underflow):", ""]
        for key, value in roulette.items():
            lines.append(f"- {key}: {value:.2f}x")
    upward = data.get("upward_ratios", {})
    if upward:
        lines += ["", "Scattering biased toward straight up (`estimator.upward_fraction: "
                  f"{UPWARD_FRACTION:g}`, cone 15 deg; the fraction is at most 1 - w0 per "
                  "layer) over the same scene without it, and its local estimates over plain "
                  "photon counting:", ""]
        for key, value in upward.items():
            lines.append(f"- {key}: {value:.2f}x")
    spot = data.get("sky_sampling")
    if spot:
        lines += ["", f"## Sky sampling: {SKY_SPOT}", "",
                  f"A 1 x 1 deg sky map, radiance 1 with a disc of radius {SPOT_RADIUS_DEG:g} deg "
                  f"at zenith {SPOT_ZENITH_DEG:g} deg {SPOT_CONTRAST:g} times brighter (half of "
                  "the sky's irradiance), all of Ed0 from the sky, over deep water (a = 0.1, "
                  "b = 0.2 1/m, HG g = 0.9). The same scene with `sampling: importance` "
                  "(directions in proportion to L cos) and `sampling: cosine` (directions "
                  "cosine-weighted, weights L pi / E), both against one long importance-sampled "
                  "run; the rows are in the tables above. With cosine sampling the spot is hit "
                  "by ~1 photon in 1000 carrying ~500 times the mean weight, so its standard "
                  "errors at the smaller counts are themselves uncertain (see z).", "",
                  "",
                  f"Splitting by weight (`estimator.split_weight: {SPLIT_WEIGHT:g}`) on the "
                  "cosine-sampled run: each heavy spot photon enters as up to 64 copies "
                  "(the split stack's room).", "",
                  "| quantity | FOM importance | FOM cosine | FOM cosine + splitting | "
                  "importance / cosine | cosine + splitting / cosine |",
                  "|---|---|---|---|---|---|"]
        for row in spot:
            lines.append(f"| {row['quantity']} | {row['fom_importance']:.3g} | "
                         f"{row['fom_cosine']:.3g} | {row['fom_cosine_split']:.3g} | "
                         f"{row['ratio']:.3g} | {row['ratio_split']:.3g} |")
    (out_dir / "bench.md").write_text("\n".join(lines) + "\n")


def fom_table(foms: list[dict]) -> dict[tuple[str, str], float]:
    """The median FOM by (scene, quantity)."""
    return {(r["scene"], r["quantity"]): r["fom_median"] for r in foms}


def fom_ratios(foms: list[dict]) -> dict[str, float]:
    """FOM of each local estimate over the crossing estimate of the same quantity: from a run
    with the crossing estimator only where the benchmark has one (each method timed alone, the
    fair ratio), else from the same run (both estimators share the run time)."""
    table = fom_table(foms)
    out = {}
    for (scene, label), value in table.items():
        if label.endswith("(local)"):
            crossing = label.replace("(local)", "(crossing)")
            name = label.replace(" (local)", "")
            alone = table.get((scene + CROSSING_ONLY, crossing))
            if alone:
                out[f"{scene}, {name}, against a crossing-only run"] = value / alone
            same = table.get((scene, crossing))
            if same:
                out[f"{scene}, {name}, both estimators in one run"] = value / same
    return out


def variant_ratios(foms: list[dict], suffix: str) -> dict[str, float]:
    """FOM of each quantity of a scene run with a variant (the scene's name + suffix) over the
    FOM of the same quantity in the scene itself."""
    table = fom_table(foms)
    return {f"{scene}, {label}": value / table[(scene, label)]
            for (name, label), value in table.items() if name.endswith(suffix)
            for scene in [name[:-len(suffix)]] if (scene, label) in table}


def roulette_ratios(foms: list[dict]) -> dict[str, float]:
    """FOM with the default roulette (weight 1e-3, survival 0.1) over the FOM with roulette
    pushed out of reach, per quantity of the scene that has both runs."""
    return {key: 1.0 / value for key, value in variant_ratios(foms, NO_ROULETTE).items()}


def upward_ratios(foms: list[dict]) -> dict[str, float]:
    """FOM with scattering biased toward straight up over the FOM without, per quantity; and
    for the local estimates with the bias, over plain photon counting (the crossing-only run)."""
    out = {f"{key}, biased over plain": value
           for key, value in variant_ratios(foms, UPWARD).items()}
    table = fom_table(foms)
    for (name, label), value in table.items():
        if name.endswith(UPWARD) and label.endswith("(local)"):
            scene = name[:-len(UPWARD)]
            alone = table.get((scene + CROSSING_ONLY, label.replace("(local)", "(crossing)")))
            if alone:
                out[f"{scene}, {label.replace(' (local)', '')}: local estimate with upward-"
                    "biased scattering over a crossing-only run"] = value / alone
    return out


def sampling_ratios(foms: list[dict]) -> list[dict]:
    """Median FOM per quantity of the sky-spot scenes (importance, cosine, cosine with
    splitting) and the ratios importance / cosine and split / cosine."""
    table = fom_table(foms)
    out = []
    for (scene, label), fom in table.items():
        if scene == f"{SKY_SPOT} {IMPORTANCE}":
            cosine = table[(f"{SKY_SPOT} {COSINE}", label)]
            split = table[(f"{SKY_SPOT} {COSINE_SPLIT}", label)]
            out.append({"quantity": label, "fom_importance": fom, "fom_cosine": cosine,
                        "fom_cosine_split": split, "ratio": fom / cosine,
                        "ratio_split": split / cosine})
    return out


def main(out_dir: Path, configs_dir: Path, bare_walk: Path | None, quick: bool = False) -> int:
    import platform

    import numba

    from . import __version__

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
    say("start-up ...")
    data["startup"] = startup_times(cold=not quick)
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
    data["fom"] = fom_summary(data["error_vs_time"])
    data["fom_ratios"] = fom_ratios(data["fom"])
    data["roulette_ratios"] = roulette_ratios(data["fom"])
    data["upward_ratios"] = upward_ratios(data["fom"])
    data["sky_sampling"] = sampling_ratios(data["fom"])
    write_report(out_dir, data)
    say(f"wrote {out_dir / 'bench.md'}")
    return 0
