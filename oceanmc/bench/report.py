"""The benchmark's report: FOM tables and ratios, the error-against-time figure, bench.md and
bench.json."""
from __future__ import annotations

import json
import statistics
from pathlib import Path

import numpy as np

from ..plot import panels, save
from .scenes import (COSINE, COSINE_SPLIT, CROSSING_ONLY, FEATURES_BEFORE, IMPORTANCE, NO_ROULETTE,
                     SKY_SPOT, SPLIT_WEIGHT, SPOT_CONTRAST, SPOT_RADIUS_DEG, SPOT_ZENITH_DEG,
                     UPWARD, UPWARD_FRACTION)


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
    fig, axes = panels(len(curves), 3, (4.6, 4.0))
    for ax, curve in zip(axes, curves):
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
    save(fig, path)


def speed_lines(data: dict) -> list[str]:
    """The speed ceiling, feature-cost and start-up sections of the report."""
    s = data["speed_ceiling"]
    lines = ["## Speed ceiling (bare-walk scene: tau = 1, albedo 0.9, isotropic, n = 1.34, "
             "pencil beam)", "",
             f"Medians of {s['repeats']} runs of {s['photons']:,} photons, compilation "
             "excluded; oceanmc tallies Ed, Eu, Eod, Eou and radiance quads at 0 and 1 m.", "",
             "| threads | bare walk photons/s | oceanmc photons/s | ratio |", "|---|---|---|---|"]
    for t in (1, 2):
        bare = s.get(f"bare_{t}t")
        lines.append(f"| {t} | {bare:,.0f} | {s[f'oceanmc_{t}t']:,.0f} | "
                     f"{s[f'ratio_{t}t']:.2f} |" if bare else
                     f"| {t} | (not found) | {s[f'oceanmc_{t}t']:,.0f} | - |")
    lines += ["", f"Scaling of oceanmc from 1 to 2 threads: {s['scaling_2t_over_1t']:.2f}x"
              + (f"; of the bare walk in the same run: {s['bare_scaling_2t_over_1t']:.2f}x; "
                 f"oceanmc's scaling is {s['scaling_vs_bare']:.2f} of the bare walk's."
                 if "scaling_vs_bare" in s else "."), "",
              "## What each feature costs (bare-walk scene, 1 thread, medians)", "",
              "Ratio: photons/s over the bare walk's on 1 thread in this run. Before: the same "
              "ratio with the kernel before the component records (c077515, its committed "
              "benchmarks/bench.md).", "",
              "| variant | photons/s | ratio to the bare walk | before | change |",
              "|---|---|---|---|---|"]
    bare_before = FEATURES_BEFORE["bare walk"]
    for row in data["features"]:
        ratio = row["photons_per_s_1t"] / s["bare_1t"] if s.get("bare_1t") else None
        before = FEATURES_BEFORE.get(row["variant"])
        before = None if before is None else before / bare_before
        cells = [f"{x:.3f}" if x is not None else "-" for x in (ratio, before)]
        change = f"{ratio / before - 1.0:+.1%}" if ratio and before else "-"
        lines.append(f"| {row['variant']} | {row['photons_per_s_1t']:,.0f} | {cells[0]} | "
                     f"{cells[1]} | {change} |")
    startup = data["startup"]
    lines += ["", "## Start-up", "",
              "Each row a fresh process: `oceanmc run CONFIG --photons "
              f"{startup['photons']} -o OUT.h5 --overwrite` (cold: `OCEANMC_CACHE_DIR` an "
              "empty folder of its own; cached: again, with the cache filled), or `oceanmc "
              "--help`. Process: from its start to its exit; kernel: the result's "
              "`startup_time_s` (compile or load). A cold start compiles the variant of the "
              "photon loop that holds the scene's optional parts (kernel/variants.py); the "
              "whole loop's row compiles every part, as one loop for every scene did before "
              "the variants.", "",
              "| start-up | scene | parts compiled | process (s) | kernel (s) | target | |",
              "|---|---|---|---|---|---|---|"]
    for row in startup["rows"]:
        kernel = "-" if row["startup_time_s"] is None else f"{row['startup_time_s']:.2f}"
        measure = "process" if row["target"] == "process_s" else "kernel"
        lines.append(f"| {row['row']} | {row['scene'] or '-'} | {row.get('parts', '-')} | "
                     f"{row['process_s']:.2f} | "
                     f"{kernel} | {measure} <= {row['target_s']:g} s | "
                     f"{'pass' if row['pass'] else 'FAIL'} |")
    return lines


QUICK_FLAG = {True: " --quick", False: ""}


def mode_lines(data: dict) -> list[str]:
    """What bench.md and speed.md of `oceanmc bench --quick` say first: their numbers come from
    small photon counts (a smoke test that the bench runs), not measurements (the sections'
    own reports say --quick in their regenerate lines)."""
    if not data.get("quick"):
        return []
    return ["", "**Mode: quick** (`--quick`: small photon counts and repeats, a smoke test that "
                "the bench runs; its times, errors and pass/FAIL rows are not measurements)."]


def write_speed_report(out_dir: Path, data: dict) -> None:
    """DIR/speed.md and DIR/speed.json (`oceanmc bench --speed`): the speed ceiling, the
    feature costs and the start-up rows alone (what a change to the kernel reports)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "speed.json").write_text(json.dumps(data, indent=1))
    lines = ["# oceanmc benchmark: speed and start-up", "",
             f"Machine: {data['machine']}; {data['date']}; oceanmc {data['version']}, "
             f"numba {data['numba']}; kernel commit {kernel_commit()}. Regenerate with "
             f"`oceanmc bench --speed{QUICK_FLAG[data['quick']]} -o DIR` (the full `oceanmc "
             "bench` has these sections in bench.md).", *mode_lines(data), ""]
    (out_dir / "speed.md").write_text("\n".join(lines + speed_lines(data)) + "\n")


def write_report(out_dir: Path, data: dict) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "bench.json").write_text(json.dumps(data, indent=1))
    plot(data["error_vs_time"], out_dir / "error_vs_time.png")
    lines = ["# oceanmc benchmark", "",
             f"Machine: {data['machine']}; {data['date']}; oceanmc {data['version']}, "
             f"numba {data['numba']}; kernel commit {kernel_commit()}. Regenerate with "
             f"`oceanmc bench{QUICK_FLAG[data['quick']]} -o {out_dir}`.", *mode_lines(data), ""]
    lines += speed_lines(data)
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
    if "spectral" in data:
        from .spectral import report_lines
        lines += [""] + report_lines(data["spectral"])
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


def error_over_spread(means: np.ndarray, errors: np.ndarray) -> np.ndarray:
    """Repeated runs (axis 0) of the same quantities: the root-mean-square of the runs' batch
    standard errors over the standard deviation of their means, 1 when the error bars are
    right (DESIGN 7.6)."""
    return np.sqrt((errors ** 2).mean(axis=0)) / means.std(axis=0, ddof=1)


def run_section(out_dir: Path, name: str, quick: bool, measure, lines) -> int:
    """A section of `oceanmc bench` on its own (--real-scenes, --inelastic): measure(quick,
    say) gives its data; DIR/name.json holds them with the kernel commit they measured,
    DIR/name.md the report lines(data, commit)."""
    data = measure(quick, lambda text: print(text, flush=True))
    data["quick"] = quick
    commit = kernel_commit()
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / f"{name}.json").write_text(json.dumps({**data, "kernel_commit": commit},
                                                      indent=1))
    (out_dir / f"{name}.md").write_text("\n".join(lines(data, commit)))
    print(f"wrote {out_dir / (name + '.md')}")
    return 0


def kernel_commit() -> str:
    """The last commit that changed the compiled kernel (oceanmc/kernel/), with '+' when the
    working tree changes it too, for a report to say what it measured; 'unknown' outside a
    git checkout."""
    import subprocess
    kernel = Path(__file__).resolve().parents[1] / "kernel"
    try:
        commit = subprocess.run(["git", "log", "-1", "--format=%h", "--", str(kernel)],
                                cwd=kernel, capture_output=True, text=True, timeout=10,
                                check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", str(kernel)], cwd=kernel,
                               capture_output=True, text=True, timeout=10, check=True).stdout
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return (commit or "unknown") + ("+" if dirty.strip() else "")
