"""The rough-sea section of `oceanmc bench`: what the Cox-Munk surface (kernel/surface/
cox_munk.py) costs against the flat one. Photons/s of the bare-walk scene (configs/
bare_walk.yaml) with each surface, on 1 thread (medians of repeats, compilation excluded), and
the figure of merit FOM = 1 / (rel_err^2 time) of Rrs in the clear-ocean scene (configs/
clear_ocean.yaml) with each surface: exact nadir by local estimates through the surface, nadir
by crossing, and the standard above-water geometry (40 deg from nadir, 135 deg from the sun) by
local estimates; rel_err the batch standard error over the value, time the run's (medians of
repeats). The two surfaces give different Rrs, so each error is its own run's. Writes
DIR/surface.md and DIR/surface.json (`oceanmc bench --surface`)."""
from __future__ import annotations

import json
import statistics
import time
from pathlib import Path

from ..config import load_config
from ..run.simulation import simulate
from .measure import FOM_BATCHES, oceanmc_runs
from .scenes import with_photons

WIND_M_S = 5.0
ABOVE_WATER = [40.0, 135.0]    # view zenith from nadir, azimuth from the sun (Mobley 1999)
QUANTITIES = (("air/Rrs_local", 0, "Rrs exact nadir (local)"),
              ("air/Rrs_local", 1, "Rrs 40 deg, 135 deg (local)"),
              ("air/Rrs_nadir", None, "Rrs nadir (crossing)"))


def surfaces(n_water: float) -> dict[str, dict]:
    return {"flat": {"model": "flat", "n_water": n_water},
            f"rough (cox_munk, {WIND_M_S:g} m/s)": {"model": "cox_munk", "n_water": n_water,
                                                    "wind_speed_m_s": WIND_M_S}}


def measure(configs_dir: Path, quick: bool, say) -> dict:
    photons = 200_000 if quick else 2_000_000
    repeats = 3 if quick else 5
    bare = load_config(configs_dir / "bare_walk.yaml")
    clear = load_config(configs_dir / "clear_ocean.yaml")
    fom_photons = 100_000 if quick else 1_000_000
    out = {"photons": photons, "fom_photons": fom_photons, "repeats": repeats, "speed": {},
           "fom": {}}
    for name, surface in surfaces(bare.surface.n_water).items():
        say(f"surface: photons/s, {name} ...")
        speeds = oceanmc_runs(with_photons(bare, photons, surface=surface), photons, 1, repeats)
        out["speed"][name] = {"photons_per_s_1t": statistics.median(speeds), "runs": speeds}
    for name, surface in surfaces(clear.surface.n_water).items():
        say(f"surface: FOM of Rrs, {name} ...")
        scene = with_photons(clear, fom_photons, surface=surface, batches=FOM_BATCHES,
                             **{"tallies.nadir_estimator": "crossing",
                                "tallies.local_directions_deg": [[180.0, 0.0],
                                                                 [180.0 - ABOVE_WATER[0],
                                                                  ABOVE_WATER[1]]]})
        simulate(with_photons(scene, 2 * scene.batches), threads=2)     # warm up
        runs = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            result = simulate(scene, threads=2)
            runs.append((time.perf_counter() - t0, result))
        seconds = statistics.median(t for t, _ in runs)
        result = runs[0][1]
        row = {"seconds": seconds, "quantities": {}}
        for key, index, label in QUANTITIES:
            value, err = result[key], result.stderr(key)
            if index is not None:
                value, err = value[index], err[index]
            rel = float(abs(err / value))
            row["quantities"][label] = {"value": float(value), "rel_err": rel,
                                        "fom": 1.0 / (rel * rel * seconds)}
        out["fom"][name] = row
    return out


def report_lines(data: dict) -> list[str]:
    flat, rough = list(data["speed"])
    speed_flat = data["speed"][flat]["photons_per_s_1t"]
    speed_rough = data["speed"][rough]["photons_per_s_1t"]
    lines = ["## The rough sea against the flat surface", "",
             f"Speed: the bare-walk scene (configs/bare_walk.yaml), {data['photons']:,} photons, "
             f"1 thread, median of {data['repeats']} runs, compilation excluded.", "",
             "| surface | photons/s (1 thread) | rough / flat |", "|---|---|---|",
             f"| {flat} | {speed_flat:,.0f} | |",
             f"| {rough} | {speed_rough:,.0f} | {speed_rough / speed_flat:.2f} |", "",
             f"Figure of merit FOM = 1 / (rel_err^2 time) of Rrs in configs/clear_ocean.yaml "
             f"with each surface: {data['fom_photons']:,} photons, 2 threads, time the median of "
             f"{data['repeats']} runs, rel_err the batch standard error over the value (the FOM "
             f"to about {100 * (2 / (FOM_BATCHES - 1)) ** 0.5:.0f}%: {FOM_BATCHES} batches). "
             "Local estimates through the rough surface use its transmittance "
             "(kernel/surface/cox_munk.py).", "",
             "| quantity | Rrs flat (1/sr) | Rrs rough (1/sr) | FOM flat | FOM rough | rough / "
             "flat |", "|---|---|---|---|---|---|"]
    for label in data["fom"][flat]["quantities"]:
        a, b = data["fom"][flat]["quantities"][label], data["fom"][rough]["quantities"][label]
        lines.append(f"| {label} | {a['value']:.5f} | {b['value']:.5f} | {a['fom']:.3g} | "
                     f"{b['fom']:.3g} | {b['fom'] / a['fom']:.2f} |")
    lines += ["", f"Run times (s): flat {data['fom'][flat]['seconds']:.2f}, rough "
              f"{data['fom'][rough]['seconds']:.2f}.", ""]
    return lines


def main(out_dir: Path, configs_dir: Path, quick: bool) -> int:
    data = measure(configs_dir, quick, lambda text: print(text, flush=True))
    data["quick"] = quick
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "surface.json").write_text(json.dumps(data, indent=1))
    (out_dir / "surface.md").write_text("\n".join(
        ["# oceanmc benchmark: rough-sea section", "",
         f"Regenerate with `oceanmc bench --surface{' --quick' if quick else ''} -o "
         f"{out_dir}`.", ""] + report_lines(data)))
    print(f"wrote {out_dir / 'surface.md'}")
    return 0
