"""`oceanmc bench --sweep`: a 100-point look-up table (Rrs over 10 absorption coefficients x 10
bottom depths) run as a plain loop of simulate() calls in one process, then by `oceanmc.sweep`
on a local Dask cluster of 1 and of 2 worker processes (one thread per point everywhere): points
per minute, the scaling from 1 to 2 workers, and the sweep's overhead per point against the
loop. The clusters are started before the clock starts (their start-up is reported apart); the
timed sweep includes validating every point, storing each point's results file and assembling
the dataset. Writes DIR/sweep.md and DIR/sweep.json."""
from __future__ import annotations

import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from .report import kernel_commit

A_VALUES = [round(float(a), 4) for a in np.geomspace(0.02, 0.5, 10)]
BOTTOM_DEPTHS_M = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 15.0, 20.0]


def lut_sweep(photons: int) -> dict:
    """Rrs at nadir over absorption x bottom depth above a sand bottom; irradiances at 0- only
    and no radiance quads (a LUT of reflectances)."""
    return {
        "base": {
            "name": "sweep benchmark: Rrs over a x bottom depth",
            "photons": photons, "batches": 8, "seed": 11,
            "illumination": {"sun_zenith_deg": 30, "diffuse_fraction": 0.2},
            "water": {"layers": [{"thickness_m": 5.0, "a": 0.1, "b": 0.3,
                                  "phase": {"model": "fournier_forand", "bb_ratio": 0.0183}}]},
            "bottom": {"model": "lambertian", "reflectance": 0.3},
            "tallies": {"depths_m": [0], "radiance": False},
        },
        "axes": {"water.layers[0].a": A_VALUES, "water.layers[0].thickness_m": BOTTOM_DEPTHS_M},
    }


def main(out_dir: Path, quick: bool = False) -> int:
    import numba

    from .. import __version__, simulate, sweep
    from ..sweeps import load_sweep
    from ..sweeps.execute import local_client
    from ..sweeps.points import build_points

    photons = 4000 if quick else 100_000
    spec = lut_sweep(photons)
    points = build_points(load_sweep(spec))
    say = lambda text: print(text, flush=True)  # noqa: E731
    data = {"machine": f"{platform.machine()}, {os.cpu_count()} cores, "
                       f"{platform.python_implementation()} {platform.python_version()}",
            "date": time.strftime("%Y-%m-%d %H:%M"), "version": __version__,
            "numba": numba.__version__, "quick": quick, "points": len(points),
            "photons_per_point": photons, "load_before": os.getloadavg()[0]}
    simulate(points[0].config, threads=1)   # the kernel loaded, the phase tables made
    say(f"plain loop: {len(points)} simulate() calls, 1 thread ...")
    t0 = time.perf_counter()
    loop_values = [simulate(p.config, threads=1)["air/Rrs_nadir"] for p in points]
    data["loop_s"] = time.perf_counter() - t0
    say("plain loop, each point's results file written ...")
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        for i, point in enumerate(points):
            simulate(point.config, threads=1).save(Path(tmp) / f"{i}.h5")
        data["loop_save_s"] = time.perf_counter() - t0
    data["runs"] = []
    for workers in (1, 2):
        say(f"sweep on {workers} worker process(es) ...")
        t0 = time.perf_counter()
        with local_client(workers) as client:
            client.wait_for_workers(workers)
            started = time.perf_counter() - t0
            with tempfile.TemporaryDirectory() as tmp:
                t1 = time.perf_counter()
                lut = sweep(spec, Path(tmp) / "lut.nc", client=client, threads=1,
                            workers_write=True)
                wall = time.perf_counter() - t1
        rrs = lut["air_Rrs_nadir"].values.ravel()
        identical = bool(np.array_equal(rrs, np.array(loop_values)))
        data["runs"].append({"workers": workers, "cluster_start_s": started, "sweep_s": wall,
                             "identical_to_loop": identical,
                             "point_s_median": float(statistics.median(
                                 lut["wall_time_s"].values.ravel()))})
    data["load_after"] = os.getloadavg()[0]
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "sweep.json").write_text(json.dumps(data, indent=2))
    (out_dir / "sweep.md").write_text(report(data))
    say(f"wrote {out_dir / 'sweep.md'}")
    return 0


def report(data: dict) -> str:
    n = data["points"]
    loop = data["loop_s"]
    one, two = data["runs"]
    saved = data["loop_save_s"]
    rows = [f"| plain loop of simulate() (1 process) | | {loop:.1f} | {60 * n / loop:.0f} | "
            "| |",
            f"| plain loop, each Result saved as a results file | | {saved:.1f} | "
            f"{60 * n / saved:.0f} | | |"]
    for run in data["runs"]:
        rows.append(f"| oceanmc.sweep, {run['workers']} worker process(es) | "
                    f"{run['cluster_start_s']:.1f} | {run['sweep_s']:.1f} | "
                    f"{60 * n / run['sweep_s']:.0f} | {run['point_s_median']:.3f} | "
                    f"{'yes' if run['identical_to_loop'] else 'NO'} |")
    overhead = (one["sweep_s"] - loop) / n
    return "\n".join([
        "# Sweep benchmark",
        "",
        f"Produced by `oceanmc bench --sweep` ({data['date']}, oceanmc {data['version']}, numba "
        f"{data['numba']}; kernel commit {kernel_commit()}; {data['machine']}; load average "
        f"{data['load_before']:.2f} before, "
        f"{data['load_after']:.2f} after{'; --quick' if data['quick'] else ''}).",
        "",
        f"A {n}-point look-up table: Rrs at nadir (local estimate) over 10 absorption "
        f"coefficients `water.layers[0].a` (0.02 to 0.5 1/m, geometric) x 10 bottom depths "
        f"`water.layers[0].thickness_m` (1 to 20 m) above Lambertian sand, Fournier-Forand "
        f"particles, {data['photons_per_point']:,} photons per point in 8 batches, irradiances "
        "at 0- and no radiance quads; one thread per point everywhere. The sweep's time "
        "includes validating the 100 scenes, storing each point's results file and writing the "
        "NetCDF dataset; the cluster's start-up is apart.",
        "",
        "| how | cluster start (s) | wall time (s) | points per minute | median point run (s) | "
        "Rrs bit-identical to the loop |",
        "|---|---|---|---|---|---|",
        *rows,
        "",
        f"- Scaling from 1 to 2 workers: {one['sweep_s'] / two['sweep_s']:.2f}x "
        "(2 cores, shared with other jobs while this ran: see the load averages).",
        f"- Overhead of the sweep per point against the plain loop (1 worker): "
        f"{1000 * overhead:.0f} ms ({100 * overhead * n / loop:.0f}% of a point's "
        f"{1000 * loop / n:.0f} ms), of which {1000 * (saved - loop) / n:.0f} ms is writing "
        "the point's results file (what a rerun skips with; the worker writes it) and "
        f"{1000 * (one['sweep_s'] - saved) / n:.0f} ms the rest: loading the kernel in the "
        "new worker process, validating and packing all the scenes first, Dask's scheduling "
        "and transfers, assembling and writing the dataset.",
        "",
    ])
