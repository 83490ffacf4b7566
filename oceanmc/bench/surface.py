"""The rough-sea section of `oceanmc bench`: what the Cox-Munk surface costs against the flat one,
sampled by its facet walk (kernel/surface/cox_munk.py, surface.method walk) and from its table
(cox_munk_table.py, method table). Photons/s of the bare-walk scene (configs/bare_walk.yaml)
with each surface, on 1 thread, the surfaces' runs interleaved in one process (medians of
repeats, compilation excluded); the table's build time on a cache miss (an empty table folder,
the builder compiled) and its load on a hit; and the figure of merit FOM = 1 / (rel_err^2 time)
of Rrs in the clear-ocean scene (configs/clear_ocean.yaml) with each surface: exact nadir by
local estimates through the surface, nadir by crossing, and the standard above-water geometry
(40 deg from nadir, 135 deg from the sun) by local estimates; rel_err the batch standard error
over the value, time the run's (medians of repeats). Flat and rough give different Rrs, so
each error is its own run's. Writes DIR/surface.md and DIR/surface.json (`oceanmc bench
--surface`)."""
from __future__ import annotations

import json
import math
import os
import statistics
import tempfile
import time
from pathlib import Path

from ..config import load_config
from ..run.simulation import simulate
from .measure import FOM_BATCHES
from .report import kernel_commit
from .scenes import with_photons

WIND_M_S = 7.0
ABOVE_WATER = [40.0, 135.0]    # view zenith from nadir, azimuth from the sun (Mobley 1999)
QUANTITIES = (("air/Rrs_local", 0, "Rrs exact nadir (local)"),
              ("air/Rrs_local", 1, "Rrs 40 deg, 135 deg (local)"),
              ("air/Rrs_nadir", None, "Rrs nadir (crossing)"))


def surfaces(n_water: float) -> dict[str, dict]:
    """The surfaces compared, flat first."""
    rough = {"model": "cox_munk", "n_water": n_water, "wind_speed_m_s": WIND_M_S}
    return {"flat": {"model": "flat", "n_water": n_water},
            f"rough, walk ({WIND_M_S:g} m/s)": rough | {"method": "walk"},
            f"rough, table ({WIND_M_S:g} m/s)": rough | {"method": "table"}}


def table_build_times(n_water: float) -> dict:
    """Seconds to get the WIND_M_S table on a cache miss (built into an empty folder, the
    builder compiled beforehand) and on a hit (read back), and the machine's load then."""
    import numpy as np

    from ..config import Surface
    from ..kernel.rng import batch_state
    from ..kernel.surface import cox_munk_table
    from ..scene import surface_table
    alpha = math.sqrt(2.0 * Surface(model="cox_munk",
                                    wind_speed_m_s=WIND_M_S).slope_variances()[0])
    # one walk: compiles the builder, or loads it from the compile cache, outside the timing
    cox_munk_table.walk_node(alpha, 1.0, n_water, 0.5, 1, np.zeros((3, 1), dtype=np.int64),
                             batch_state(0, 0),
                             np.empty(2, dtype=np.int64), np.empty(2), np.empty(2), np.empty(2))
    kept = surface_table.TABLE_DIR
    with tempfile.TemporaryDirectory() as folder:
        surface_table.TABLE_DIR = Path(folder)
        try:
            t0 = time.perf_counter()
            surface_table.table(alpha, n_water)
            t1 = time.perf_counter()
            surface_table.table(alpha, n_water)
            t2 = time.perf_counter()
        finally:
            surface_table.TABLE_DIR = kept
    return {"miss_s": t1 - t0, "hit_s": t2 - t1, "load_average": os.getloadavg()[0]}


def measure(configs_dir: Path, quick: bool, say) -> dict:
    photons = 200_000 if quick else 2_000_000
    repeats = 3 if quick else 5
    bare = load_config(configs_dir / "bare_walk.yaml")
    clear = load_config(configs_dir / "clear_ocean.yaml")
    fom_photons = 100_000 if quick else 1_000_000
    out = {"photons": photons, "fom_photons": fom_photons, "repeats": repeats, "speed": {},
           "fom": {}, "load_average_start": os.getloadavg()[0]}
    say("surface: table build time (cache miss, hit) ...")
    out["table_build"] = table_build_times(bare.surface.n_water)
    say("surface: photons/s, interleaved ...")
    scenes = {name: with_photons(bare, photons, surface=surface)
              for name, surface in surfaces(bare.surface.n_water).items()}
    for scene in scenes.values():
        simulate(with_photons(scene, 2 * scene.batches), threads=1)     # warm up
    runs: dict[str, list[float]] = {name: [] for name in scenes}
    for _ in range(repeats):
        for name, scene in scenes.items():
            runs[name].append(simulate(scene, threads=1).attrs["photons_per_s"])
    for name, speeds in runs.items():
        out["speed"][name] = {"photons_per_s_1t": statistics.median(speeds), "runs": speeds}
    for name, surface in surfaces(clear.surface.n_water).items():
        say(f"surface: FOM of Rrs, {name} ...")
        scene = with_photons(clear, fom_photons, surface=surface, batches=FOM_BATCHES,
                             **{"tallies.nadir_estimator": "crossing",
                                "tallies.local_directions_deg": [[180.0, 0.0],
                                                                 [180.0 - ABOVE_WATER[0],
                                                                  ABOVE_WATER[1]]]})
        simulate(with_photons(scene, 2 * scene.batches), threads=2)     # warm up
        timed = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            result = simulate(scene, threads=2)
            timed.append((time.perf_counter() - t0, result))
        seconds = statistics.median(t for t, _ in timed)
        result = timed[0][1]
        row = {"seconds": seconds, "quantities": {}}
        for key, index, label in QUANTITIES:
            value, err = result[key], result.stderr(key)
            if index is not None:
                value, err = value[index], err[index]
            rel = float(abs(err / value))
            row["quantities"][label] = {"value": float(value), "rel_err": rel,
                                        "fom": 1.0 / (rel * rel * seconds)}
        out["fom"][name] = row
    out["load_average_end"] = os.getloadavg()[0]
    return out


def report_lines(data: dict) -> list[str]:
    names = list(data["speed"])
    flat = names[0]
    speed = {name: data["speed"][name]["photons_per_s_1t"] for name in names}
    lines = ["## The rough sea against the flat surface", "",
             f"Speed: the bare-walk scene (configs/bare_walk.yaml), {data['photons']:,} photons, "
             f"1 thread, the surfaces' runs interleaved in one process, median of "
             f"{data['repeats']} runs each, compilation excluded.", "",
             "| surface | photons/s (1 thread) | / flat |", "|---|---|---|"]
    lines += [f"| {name} | {speed[name]:,.0f} | {speed[name] / speed[flat]:.2f} |"
              for name in names]
    walk = next((name for name in names if "walk" in name), None)
    table = next((name for name in names if "table" in name), None)
    if walk and table:
        lines += ["", f"The table samples the rough surface {speed[table] / speed[walk]:.1f}x "
                  "as fast as the walk (photons/s of the whole scene)."]
    if "table_build" in data:
        build = data["table_build"]
        lines += ["", f"The table's build on a cache miss: {build['miss_s']:.2f} s (2 threads, "
                  f"builder compiled; load average {build['load_average']:.1f} on 2 cores); "
                  f"read from the cache on a hit: {1000 * build['hit_s']:.1f} ms."]
    if "load_average_start" in data:
        lines += ["", f"Machine load average (1 min) at the start and end of this section: "
                  f"{data['load_average_start']:.1f}, {data['load_average_end']:.1f} (2 "
                  "cores, shared: absolute numbers drift, ratios of interleaved runs less)."]
    fom_names = list(data["fom"])
    lines += ["", f"Figure of merit FOM = 1 / (rel_err^2 time) of Rrs in configs/clear_ocean.yaml "
              f"with each surface: {data['fom_photons']:,} photons, 2 threads, time the median of "
              f"{data['repeats']} runs, rel_err the batch standard error over the value (the FOM "
              f"to about {100 * (2 / (FOM_BATCHES - 1)) ** 0.5:.0f}%: {FOM_BATCHES} batches). "
              "Local estimates through the rough surface sample its walk backwards, whatever "
              "the method.", "",
              "| quantity | " + " | ".join(f"Rrs {name} (1/sr)" for name in fom_names) + " | "
              + " | ".join(f"FOM {name}" for name in fom_names) + " | "
              + " | ".join(f"{name} / flat" for name in fom_names[1:]) + " |",
              "|---" * (3 * len(fom_names)) + "|"]
    for label in data["fom"][flat]["quantities"]:
        q = [data["fom"][name]["quantities"][label] for name in fom_names]
        lines.append(f"| {label} | " + " | ".join(f"{x['value']:.5f}" for x in q) + " | "
                     + " | ".join(f"{x['fom']:.3g}" for x in q) + " | "
                     + " | ".join(f"{x['fom'] / q[0]['fom']:.2f}" for x in q[1:]) + " |")
    lines += ["", "Run times (s): " + ", ".join(
        f"{name} {data['fom'][name]['seconds']:.2f}" for name in fom_names) + ".", ""]
    return lines


def main(out_dir: Path, configs_dir: Path, quick: bool) -> int:
    data = measure(configs_dir, quick, lambda text: print(text, flush=True))
    data["quick"] = quick
    data["kernel_commit"] = kernel_commit()
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "surface.json").write_text(json.dumps(data, indent=1))
    (out_dir / "surface.md").write_text("\n".join(
        ["# oceanmc benchmark: rough-sea section", "",
         f"Kernel commit {data['kernel_commit']}. Regenerate with `oceanmc bench --surface"
         f"{' --quick' if quick else ''} -o {out_dir}`.", ""] + report_lines(data)))
    print(f"wrote {out_dir / 'surface.md'}")
    return 0
