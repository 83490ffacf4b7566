"""Long-run soak (not in CI): run the bare-walk benchmark scene for MINUTES, record the peak
resident memory as photons accumulate, and compare the result with a short run of the same scene
(another seed) quantity by quantity in standard errors.

    python benchmarks/soak.py --minutes 30 -o benchmarks/soak.json
"""
import argparse
import json
import math
import resource
import time
from pathlib import Path

import oceanmc

QUANTITIES = ["budget/water_leaving", "budget/absorbed_layer_1", "Ed", "Eu", "Eo",
              "air/Eu_water_leaving"]


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("-o", "--output", default="benchmarks/soak.json")
    args = parser.parse_args()
    scene = Path(__file__).resolve().parents[1] / "configs" / "bare_walk.yaml"
    # more photons than the run can trace: it ends at the deadline, between groups of batches
    # (256 batches of 50M photons: the tallies take 256 x the per-batch size, whatever the
    # photon count, so memory must stay flat)
    config = oceanmc.load_config(scene).model_copy(update={"photons": 256 * 50_000_000,
                                                           "batches": 256})
    short = oceanmc.simulate(config.model_copy(update={"photons": 2_000_000, "batches": 64,
                                                       "seed": 99}), threads=args.threads)
    samples = []
    start = time.perf_counter()

    def checkpoint(partial):
        samples.append({"seconds": time.perf_counter() - start,
                        "photons": int(partial.attrs["photons"]), "peak_rss_mb": peak_rss_mb()})
        print(samples[-1], flush=True)

    deadline = start + 60.0 * args.minutes
    long = oceanmc.simulate(config, threads=args.threads,
                            should_stop=lambda: time.perf_counter() > deadline,
                            on_checkpoint=checkpoint, checkpoint_every_s=60.0)
    rows = []
    for name in QUANTITIES:
        a, ea = long[name], long.stderr(name)
        b, eb = short[name], short.stderr(name)
        for i, (x, y, sx, sy) in enumerate(zip(*(map(lambda v: [v] if not hasattr(v, "__len__")
                                                     else list(v), (a, b, ea, eb))))):
            rows.append({"quantity": name, "index": i, "long": float(x), "long_se": float(sx),
                         "short": float(y), "short_se": float(sy),
                         "z": float((x - y) / math.hypot(sx, sy)) if sx or sy else None})
    report = {"minutes": args.minutes, "photons": int(long.attrs["photons"]),
              "photons_per_s": long.attrs["photons_per_s"], "peak_rss_mb": peak_rss_mb(),
              "samples": samples, "comparison_with_short_run": rows,
              "max_abs_z": max(abs(r["z"]) for r in rows if r["z"] is not None)}
    Path(args.output).write_text(json.dumps(report, indent=1))
    print(json.dumps({k: v for k, v in report.items() if k not in ("samples",
                                                                    "comparison_with_short_run")}))


if __name__ == "__main__":
    main()
