"""The deep-light section of `oceanmc bench` (issue 26, item 5): depth importance weight windows
(estimator.depth_splitting; scene/weight_window.py) on a stratified Case-1 column.

The scene: 180 layers of 0.5 m of Case-1 water (the case1 component) with a deep chlorophyll
maximum (a Gaussian of 4 mg/m3 at 40 m, 8 m wide, over 1 mg/m3), over infinitely deep water at
the background, at 490 nm, sun at 30 deg with a 20% sky, flat sea; Ed, Eou and Lu tallied every
5 m from 0 to 110 m, where Ed has fallen by e^-11. Run with windows (auto: on here) and without
(off), both at the scene's defaults (estimator.upward_fraction auto: scattering biased toward
straight up by 0.1 where the windows are on, none without them; scene/weight_window.py) and
without the bias: per depth and quantity the time to a 1% relative
standard error, t (rel / 0.01)^2 with rel^2 the mean over interleaved repeats and t their
median time on 2 threads, compilation excluded.

Then: the rule of auto (the same column with its deepest tally 10 to 55 m down: the worst time
to 1% over every Ed, Eou and Lu, and Rrs's, with and without windows); the shipped
configs/deep_chlorophyll_maximum.yaml with and without; and whether the batch standard errors
can be trusted under windows: repeated runs with other seeds, the spread of their means
against their standard errors. Writes DIR/deep.md and DIR/deep.json (`oceanmc bench --deep`).
"""
from __future__ import annotations

import copy
import math
import time
from pathlib import Path

import numpy as np
import yaml

from .. import optics
from ..config import load_config
from ..run.simulation import simulate
from ..scene import weight_window
from .report import error_over_spread, run_section

WAVELENGTH_NM = 490.0
LAYERS, LAYER_M = 180, 0.5
CHL_BACKGROUND, CHL_PEAK, PEAK_DEPTH_M, PEAK_WIDTH_M = 1.0, 4.0, 40.0, 8.0
DEPTHS = [float(z) for z in range(0, 111, 5)]
QUANTITIES = ("Ed", "Eou", "Lu")
TARGET_REL, TARGET_S, TARGET_DEPTHS = 0.01, 60.0, 10.0
BATCHES = 64
VARIANTS = (("defaults (upward bias auto: 0.1 with the windows, none without them)", {}),
            ("no upward bias", {"upward_fraction": None}))
MODES = ("off", "auto")
# the deepest tally of the auto-rule rows (m; six levels evenly from 0)
AUTO_DEEPEST_M = (10.0, 20.0, 30.0, 40.0, 55.0)
SPREAD_SEEDS = 12
SHIPPED = Path(__file__).resolve().parents[2] / "configs" / "deep_chlorophyll_maximum.yaml"


def chlorophyll(z: np.ndarray) -> np.ndarray:
    return CHL_BACKGROUND + CHL_PEAK * np.exp(-0.5 * ((z - PEAK_DEPTH_M) / PEAK_WIDTH_M) ** 2)


def scene(photons: int, seed: int, estimator: dict, depths=DEPTHS) -> dict:
    """The stratified column as a user writes it (estimator: what the run changes)."""
    middles = (np.arange(LAYERS) + 0.5) * LAYER_M
    layers = [{"thickness_m": LAYER_M, "components": [
        {"model": "pure_water"}, {"model": "case1", "chl_mg_m3": round(float(chl), 4)}]}
        for chl in chlorophyll(middles)]
    layers.append({"thickness_m": float("inf"), "components": [
        {"model": "pure_water"}, {"model": "case1", "chl_mg_m3": CHL_BACKGROUND}]})
    return {"name": "stratified Case-1 column, deep chlorophyll maximum", "photons": photons,
            "seed": seed, "batches": BATCHES, "wavelengths_nm": [WAVELENGTH_NM],
            "illumination": {"sun_zenith_deg": 30.0, "diffuse_fraction": 0.2},
            "surface": {"model": "flat"}, "water": {"layers": layers},
            "bottom": {"model": "none"},
            "tallies": {"depths_m": list(depths), "radiance": False},
            "estimator": dict(estimator)}


def beam_optical_depths(depths) -> list[float]:
    """tau = integral of c dz from the surface to each depth, at WAVELENGTH_NM."""
    layers = optics.column_iops(load_config(scene(BATCHES * 2, 1, {})))
    z = np.asarray(depths, dtype=np.float64)
    tau = np.zeros(len(z))
    for layer in layers:
        tau += float(layer.c[0]) * np.clip(z - layer.top_m, 0.0, layer.thickness_m)
    return tau.tolist()


def _run(config: dict):
    t0 = time.perf_counter()
    result = simulate(config, threads=2)
    return time.perf_counter() - t0, result


def _summary(runs: list, names=QUANTITIES) -> dict:
    """Median time, photons/s, events per photon, and per quantity the time to 1% (t times
    the mean over the runs of rel^2 / 0.01^2) at each level."""
    seconds = float(np.median([t for t, _ in runs]))
    first = runs[0][1]
    photons = int(first.attrs["photons"])
    out = {"time_s": seconds, "photons_per_s": photons / seconds,
           "events_per_photon": first.attrs["scattering_events"] / photons,
           "depth_splitting": str(first.attrs["depth_splitting"])}
    for name in names:
        rel2 = np.mean([np.ravel(r.stderr(name) / np.abs(r[name])) ** 2 for _, r in runs],
                       axis=0)
        out[name] = (seconds * rel2 / TARGET_REL ** 2).tolist()
    return out


def _interleaved(make, modes, repeats: int, say, label: str) -> dict:
    """{mode: [(seconds, result)]}: make(mode, seed) run for each repeat, modes in turn."""
    runs = {mode: [] for mode in modes}
    for r in range(repeats):
        for mode in modes:
            say(f"  {label}, {mode}, repeat {r + 1}")
            runs[mode].append(_run(make(mode, 1 + r)))
    return runs


def _spread(photons: int, seeds: int, estimator: dict, say) -> dict:
    """Repeated runs of the windowed scene: per quantity, z = (mean_i - grand mean) / se_i
    (scaled by sqrt(n / (n - 1)) for the grand mean's share) over every run and depth, and the
    ratio of the root-mean-square standard error to the spread of the runs' means at each
    depth."""
    results = []
    for seed in range(seeds):
        say(f"  spread: seed {100 + seed}")
        results.append(simulate(scene(photons, 100 + seed, estimator), threads=2))
    out = {"photons": photons, "seeds": seeds}
    for name in QUANTITIES:
        means = np.array([np.ravel(r[name]) for r in results])
        errors = np.array([np.ravel(r.stderr(name)) for r in results])
        z = (means - means.mean(axis=0)) / errors * math.sqrt(seeds / (seeds - 1))
        ratio = error_over_spread(means, errors)
        out[name] = {"rms_z": float(np.sqrt((z ** 2).mean())), "max_abs_z": float(
            np.abs(z).max()), "ratio_median": float(np.median(ratio)),
            "ratio_min": float(ratio.min()), "ratio_max": float(ratio.max())}
    # one ratio from n runs: the spread's relative standard deviation sqrt(1 / (2 (n - 1)))
    out["ratio_one_depth_sd"] = math.sqrt(1.0 / (2.0 * (seeds - 1)))
    return out


def _auto_rows(photons: int, repeats: int, say) -> list[dict]:
    """The column with its deepest tally at each AUTO_DEEPEST_M (six levels from 0), upward
    bias 0.1, windows on and off: the worst time to 1% over every Ed, Eou and Lu, Rrs's."""
    rows = []
    for deepest in AUTO_DEEPEST_M:
        depths = [round(deepest * k / 5, 3) for k in range(6)]

        def make(mode, seed):
            return scene(photons, seed, {"upward_fraction": 0.1, "depth_splitting": mode},
                         depths)
        runs = _interleaved(make, ("off", "on"), repeats, say, f"auto rule, {deepest:g} m")
        plain = runs["off"][0][1]
        config = load_config(make("auto", 1))
        row = {"deepest_m": deepest,
               "attenuation_depths": float(np.log(plain["Ed"][0] / plain["Ed"][-1])),
               "auto": weight_window.choose(config, optics.column_iops(config)).why}
        for mode in ("off", "on"):
            summary = _summary(runs[mode], QUANTITIES + ("air/Rrs_nadir",))
            row[mode] = {"worst_s": max(max(summary[q]) for q in QUANTITIES),
                         "rrs_s": summary["air/Rrs_nadir"][0], "time_s": summary["time_s"]}
        rows.append(row)
    return rows


def _shipped(photons: int, repeats: int, say) -> dict | None:
    """configs/deep_chlorophyll_maximum.yaml with and without windows: per quantity the
    worst and the best ratio over its depths and bands of the FOM with over without."""
    if not SHIPPED.is_file():
        return None
    base = yaml.safe_load(SHIPPED.read_text())

    def make(mode, seed):
        config = copy.deepcopy(base)
        config.update(photons=photons, seed=seed, batches=BATCHES)
        config["estimator"] = dict(config.get("estimator") or {}, depth_splitting=mode)
        return config
    runs = _interleaved(make, ("off", "auto"), repeats, say, "deep_chlorophyll_maximum.yaml")
    names = ("Ed", "Eou", "Lu", "air/Rrs_nadir")
    off, on = _summary(runs["off"], names), _summary(runs["auto"], names)
    out = {"photons": photons, "decision": on["depth_splitting"], "time_off_s": off["time_s"],
           "time_on_s": on["time_s"]}
    for name in names:
        ratio = np.array(off[name]) / np.array(on[name])   # FOM ratio: time to 1%, inverted
        out[name] = {"fom_ratio_min": float(ratio.min()), "fom_ratio_max": float(ratio.max())}
    return out


def measure(quick: bool, say) -> dict:
    photons = 20_000 if quick else 300_000
    repeats = 1 if quick else 3
    for _, estimator in VARIANTS:   # warm-up: compilation and the cap tables
        for mode in MODES:
            simulate(scene(2 * BATCHES, 99, dict(estimator, depth_splitting=mode)), threads=2)
    data = {"photons": photons, "repeats": repeats, "depths_m": DEPTHS,
            "beam_optical_depths": beam_optical_depths(DEPTHS), "variants": []}
    for label, estimator in VARIANTS:
        runs = _interleaved(lambda mode, seed: scene(photons, seed, dict(
            estimator, depth_splitting=mode)), MODES, repeats, say, label)
        ed = np.mean([r["Ed"] for _, r in runs["auto"]], axis=0)
        data["variants"].append({"variant": label, "estimator": estimator,
                                 "attenuation_depths": np.log(ed[0] / ed).tolist(),
                                 **{mode: _summary(runs[mode]) for mode in MODES}})
    data["auto_rule"] = _auto_rows(10_000 if quick else 200_000, repeats if quick else 2, say)
    data["shipped"] = _shipped(10_000 if quick else 200_000, 1 if quick else 2, say)
    data["spread"] = _spread(10_000 if quick else 100_000, 3 if quick else SPREAD_SEEDS,
                             {"upward_fraction": 0.1}, say)
    return data


def main(out_dir: Path, quick: bool) -> int:
    return run_section(out_dir, "deep", quick, measure, report_lines)


def _met(row: dict, zeta: list[float], depths: list[float]) -> tuple[bool, float, str]:
    """Whether every quantity at every depth down to TARGET_DEPTHS attenuation depths (and the
    first below, so that 10 is covered) reaches 1% within TARGET_S; the worst time and where."""
    last = next((k for k, z in enumerate(zeta) if z >= TARGET_DEPTHS), len(zeta) - 1)
    worst, where = 0.0, ""
    for name in QUANTITIES:
        times = row[name][:last + 1]
        k = int(np.argmax(times))
        if times[k] > worst:
            worst, where = times[k], f"{name} at {depths[k]:g} m"
    return worst <= TARGET_S, worst, where


def _seconds(value: float) -> str:
    return f"{value:,.1f}" if math.isfinite(value) else "-"


def report_lines(data: dict, kernel_commit: str) -> list[str]:
    """The section's report (DIR/deep.md)."""
    lines = ["# oceanmc benchmark: deep light (issue 26, item 5)", "",
             "Regenerate with `oceanmc bench --deep -o benchmarks`"
             + (" (--quick: small counts)" if data.get("quick") else "") + ". "
             f"Kernel commit {kernel_commit}.", "",
             f"The stratified scene: {LAYERS} layers of {LAYER_M:g} m of Case-1 water (the "
             f"case1 component) with a deep chlorophyll maximum ({CHL_PEAK:g} mg/m3 at "
             f"{PEAK_DEPTH_M:g} m, a Gaussian {PEAK_WIDTH_M:g} m wide, over "
             f"{CHL_BACKGROUND:g} mg/m3), over infinitely deep water at the background, at "
             f"{WAVELENGTH_NM:g} nm; sun at 30 deg, 20% sky, flat sea; Ed, Eou and Lu (the "
             "nadir cap's local estimate) tallied every 5 m from 0 to 110 m. `off`: "
             "estimator.depth_splitting off; `auto`: the default, which turns the depth "
             "windows on here. "
             f"{data['photons']:,} photons per run, {BATCHES} batches, 2 threads, times the "
             f"median of {data['repeats']} interleaved runs (compilation excluded); time to "
             "1% = t x (mean over the runs of rel^2) / 0.01^2 (-: no light reached the "
             "depth). Attenuation depths: ln(Ed(0-) / Ed(z)) of the runs with windows; beam "
             "optical depth: the integral of c dz.", ""]
    zeta_tau = data["beam_optical_depths"]
    for variant in data["variants"]:
        zeta = variant["attenuation_depths"]
        off, on = variant["off"], variant["auto"]
        lines += [f"## {variant['variant']}", "",
                  f"Without windows: {off['photons_per_s']:,.0f} photons/s, "
                  f"{off['events_per_photon']:.0f} scattering events per photon; with "
                  f"(`{on['depth_splitting']}`): {on['photons_per_s']:,.0f} photons/s, "
                  f"{on['events_per_photon']:.0f} events per photon.", "",
                  "| depth (m) | attenuation depths | beam optical depth | "
                  + " | ".join(f"{q} off (s) | {q} auto (s) | {q} gain" for q in QUANTITIES)
                  + " |", "|---" * (3 + 3 * len(QUANTITIES)) + "|"]
        for k, depth in enumerate(data["depths_m"]):
            cells = [f"{depth:g}", f"{zeta[k]:.2f}", f"{zeta_tau[k]:.1f}"]
            for name in QUANTITIES:
                a, b = off[name][k], on[name][k]
                cells += [_seconds(a), _seconds(b),
                          f"{a / b:.2f}x" if math.isfinite(a / b) else "-"]
            lines.append("| " + " | ".join(cells) + " |")
        for mode, label in (("off", "without windows"), ("auto", "with windows")):
            met, worst, where = _met(variant[mode], zeta, data["depths_m"])
            lines.append("")
            lines.append(f"Target (every Ed, Eou and Lu down to {TARGET_DEPTHS:g} attenuation "
                         f"depths at <= 1% in <= {TARGET_S:g} s), {label}: "
                         f"{'**met**' if met else '**not met**'}; the worst is {where}, "
                         f"{worst:,.0f} s.")
        lines.append("")
    lines += ["## The rule of auto", "",
              "The same column with upward bias 0.1 and its deepest tally at each depth below "
              "(six levels evenly from 0): the worst time to 1% over every Ed, Eou and Lu, and "
              "Rrs's, without and with windows. auto turns them on from "
              "scene.weight_window.AUTO_ATTENUATION_DEPTHS attenuation depths (its estimate "
              "from the IOPs; the measured value beside it).", "",
              "| deepest tally (m) | attenuation depths | auto | worst off (s) | worst on (s) "
              "| Rrs off (s) | Rrs on (s) |", "|---|---|---|---|---|---|---|"]
    for row in data["auto_rule"]:
        lines.append(f"| {row['deepest_m']:g} | {row['attenuation_depths']:.2f} | "
                     f"{row['auto'].split(' (')[0]} | {row['off']['worst_s']:,.1f} | "
                     f"{row['on']['worst_s']:,.1f} | {row['off']['rrs_s']:,.2f} | "
                     f"{row['on']['rrs_s']:,.2f} |")
    shipped = data.get("shipped")
    if shipped:
        lines += ["", "## configs/deep_chlorophyll_maximum.yaml", "",
                  f"{shipped['photons']:,} photons, 6 bands, tallies 0-100 m; auto: "
                  f"`{shipped['decision']}`. Time {shipped['time_off_s']:.1f} s without "
                  f"windows, {shipped['time_on_s']:.1f} s with. FOM with windows over "
                  "without, the lowest and the highest over depths and bands:", "",
                  "| quantity | lowest | highest |", "|---|---|---|"]
        for name in ("Ed", "Eou", "Lu", "air/Rrs_nadir"):
            lines.append(f"| {name} | {shipped[name]['fom_ratio_min']:.2f}x | "
                         f"{shipped[name]['fom_ratio_max']:.2f}x |")
    spread = data["spread"]
    lines += ["", "## Error bars under windows", "",
              f"{spread['seeds']} runs of {spread['photons']:,} photons with other seeds (upward "
              "bias 0.1, windows on), every depth: z = (run's mean - mean of the runs) / run's "
              "standard error x sqrt(n / (n - 1)), whose root mean square is 1 when the "
              "standard errors are right (1.02 for t with 63 degrees of freedom); and at each "
              "depth the root-mean-square standard error over the standard deviation of the "
              "runs' means, 1 when right, each such ratio uncertain by "
              f"{100 * spread['ratio_one_depth_sd']:.0f}% (one standard deviation).", "",
              "| quantity | rms z | max abs z | SE / spread: median over depths | lowest | "
              "highest |", "|---|---|---|---|---|---|"]
    for name in QUANTITIES:
        s = spread[name]
        lines.append(f"| {name} | {s['rms_z']:.3f} | {s['max_abs_z']:.2f} | "
                     f"{s['ratio_median']:.2f} | {s['ratio_min']:.2f} | {s['ratio_max']:.2f} |")
    lines.append("")
    return lines
