"""The real-scenes section of `oceanmc bench` (issue 26): the scene users run, a 31-band Rrs
spectrum (400-700 nm every 10 nm) of Case-1 water under sun and sky from a date and place
(SPECTRL2, Harrison-Coombes sky) and a 7 m/s Cox-Munk sea, deep at chlorophyll 0.03, 0.3 and 10
mg/m3 and over a 5 m bottom at 0.3, run with the default settings (what `auto` chooses: the
nadir cap's local estimate and, in spectral scenes, scattering biased toward straight up) and
with the crossing estimate of the same cap. Per scene: photons/s, the worst band's relative
standard error of Rrs at nadir and the time that band needs for 1% (t (rel / 0.01)^2), and per
band the figure of merit FOM = 1 / (rel^2 t) of the defaults over the crossing estimate's; times
are medians of interleaved runs on 2 threads, compilation excluded. Last, the headline scene
(Chl 0.3, deep) is run with the photons the extrapolation asks for 1% in every band, and its
time and worst band are reported. Writes DIR/real_scenes.md and DIR/real_scenes.json
(`oceanmc bench --real-scenes`)."""
from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from ..run.simulation import simulate
from .report import run_section

WAVELENGTHS = {"start": 400.0, "stop": 700.0, "step": 10.0}
QUANTITY = "air/Rrs_nadir"
TARGET_REL = 0.01
BATCHES = 64
# (label, chlorophyll, bottom depth (None: deep))
SCENES = (("Chl 0.3, deep", 0.3, None), ("Chl 0.3, bottom 0.3 at 5 m", 0.3, 5.0),
          ("Chl 0.03, deep", 0.03, None), ("Chl 10, deep", 10.0, None))
ESTIMATORS = (("defaults", {}), ("crossing", {"nadir_estimator": "crossing"}))


def scene(chl: float, bottom_depth: float | None, photons: int, seed: int,
          tallies: dict) -> dict:
    """The scene as a user writes it: nothing about estimators unless `tallies` says so. CDOM
    covaries with chlorophyll as a_CDOM(440) = 0.0316 Chl^0.63 (configs/case1_spectral.yaml)."""
    return {
        "name": f"windy Case-1, Chl {chl:g}", "photons": photons, "seed": seed,
        "batches": BATCHES, "wavelengths_nm": WAVELENGTHS,
        "illumination": {"sun_position": {"time": "2024-06-21T14:00:00Z", "latitude_deg": 31.7,
                                          "longitude_deg": -64.2},
                         "spectrum": {"model": "spectrl2"}, "sky": "harrison_coombes"},
        "surface": {"model": "cox_munk", "wind_speed_m_s": 7.0},
        "water": {"layers": [{"thickness_m": bottom_depth or float("inf"), "components": [
            {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": chl},
            {"model": "cdom", "a440": 0.0316 * chl ** 0.63}]}]},
        "bottom": {"model": "lambertian", "reflectance": 0.3} if bottom_depth
        else {"model": "none"},
        "tallies": {"depths_m": [0.0], **tallies},
    }


def _run(config: dict) -> tuple[float, np.ndarray]:
    """(seconds, relative standard error of Rrs nadir per band)."""
    t0 = time.perf_counter()
    result = simulate(config, threads=2)
    elapsed = time.perf_counter() - t0
    return elapsed, result.stderr(QUANTITY) / np.abs(result[QUANTITY])


def measure(quick: bool, say) -> dict:
    photons = 20_000 if quick else 200_000
    repeats = 1 if quick else 3
    out = {"photons": photons, "repeats": repeats, "scenes": []}
    for label, chl, depth in SCENES:
        say(f"  {label}")
        for _, tallies in ESTIMATORS:   # warm-up: compilation and the cap tables
            simulate(scene(chl, depth, 2 * BATCHES, 99, tallies), threads=2)
        times = {name: [] for name, _ in ESTIMATORS}
        rels = {}
        for r in range(repeats):
            for name, tallies in ESTIMATORS:
                elapsed, rel = _run(scene(chl, depth, photons, 1 + r, tallies))
                times[name].append(elapsed)
                rels.setdefault(name, rel)
        row = {"scene": label}
        for name, _ in ESTIMATORS:
            t = float(np.median(times[name]))
            rel = rels[name]
            row[name] = {"time_s": t, "photons_per_s": photons / t,
                         "worst_rel": float(rel.max()),
                         "worst_nm": float(400.0 + 10.0 * int(np.argmax(rel))),
                         "time_to_target_s": t * (float(rel.max()) / TARGET_REL) ** 2,
                         "fom": (1.0 / (rel ** 2 * t)).tolist()}
        ratio = np.array(row["defaults"]["fom"]) / np.array(row["crossing"]["fom"])
        row["fom_ratio_min"], row["fom_ratio_median"] = float(ratio.min()), float(np.median(
            ratio))
        out["scenes"].append(row)
    head = out["scenes"][0]["defaults"]
    # the worst of 31 bands' errors, each from 64 batches, is itself uncertain by ~10-20%:
    # ask for 2.5 times the extrapolated photons, so that every band reaches the target
    needed = int(math.ceil(photons * (head["worst_rel"] / TARGET_REL) ** 2 * 2.5 / BATCHES)
                 ) * BATCHES
    if quick:
        needed = min(needed, 4 * photons)
    say(f"  Chl 0.3, deep, to 1%: {needed:,} photons")
    elapsed, rel = _run(scene(0.3, None, needed, 7, {}))
    out["to_target"] = {"photons": needed, "time_s": elapsed, "worst_rel": float(rel.max()),
                        "worst_nm": float(400.0 + 10.0 * int(np.argmax(rel)))}
    return out


def main(out_dir: Path, quick: bool) -> int:
    return run_section(out_dir, "real_scenes", quick, measure, report_lines)


def report_lines(data: dict, kernel_commit: str) -> list[str]:
    """The section's report (DIR/real_scenes.md)."""
    lines = ["# oceanmc benchmark: real scenes (issue 26)", "",
             "Regenerate with `oceanmc bench --real-scenes -o benchmarks`"
             + (" (--quick: small counts)" if data.get("quick") else "") + ". "
             f"Kernel commit {kernel_commit}.", "",
             "A 31-band Rrs spectrum (400-700 nm) of Case-1 water (pure water, chlorophyll, "
             "CDOM a440 = 0.0316 Chl^0.63), sun from a date and place (2024-06-21 14:00 UTC, "
             "31.7 N 64.2 W: SPECTRL2 with a Harrison-Coombes sky), Cox-Munk sea at 7 m/s, "
             "2 threads. `defaults`: nothing about estimators in the config (auto: the nadir "
             "cap's local estimate through the waves and scattering biased toward straight up, "
             "fraction 0.1); `crossing`: tallies.nadir_estimator: crossing (photons leaving "
             "through the same cap), the same upward bias. "
             f"{data['photons']:,} photons per run, {BATCHES} batches, time the median of "
             f"{data['repeats']} interleaved runs (compilation excluded); time to 1% = t "
             "(worst band's relative standard error / 0.01)^2.", "",
             "| scene | estimator | photons/s | worst band | rel. std. error | time to 1% (s) |",
             "|---|---|---|---|---|---|"]
    for row in data["scenes"]:
        for name, _ in ESTIMATORS:
            e = row[name]
            lines.append(f"| {row['scene']} | {name} | {e['photons_per_s']:,.0f} | "
                         f"{e['worst_nm']:g} nm | {100 * e['worst_rel']:.2f}% | "
                         f"{e['time_to_target_s']:,.0f} |")
    lines += ["", "Figure of merit of Rrs nadir per band, defaults over crossing:", "",
              "| scene | lowest band | median band |", "|---|---|---|"]
    for row in data["scenes"]:
        lines.append(f"| {row['scene']} | {row['fom_ratio_min']:.1f}x | "
                     f"{row['fom_ratio_median']:.1f}x |")
    t = data["to_target"]
    lines += ["", f"The headline scene (Chl 0.3, deep) with the defaults and "
              f"{t['photons']:,} photons: {t['time_s']:.1f} s, worst band {t['worst_nm']:g} nm "
              f"at {100 * t['worst_rel']:.2f}% (target: every band <= 1% in <= 60 s).", ""]
    return lines
