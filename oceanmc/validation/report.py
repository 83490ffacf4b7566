"""Writes the validation report: report.md (Markdown with PNG figures under figures/) and
results.json (one record per check)."""
from __future__ import annotations

import datetime as _dt
import json
import math
import platform
from collections import OrderedDict
from pathlib import Path

from .stats import FAMILY_ALPHA, MIN_Z_TOL


def _fmt(x, digits=5) -> str:
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    x = float(x)
    if not math.isfinite(x):
        return "inf" if x > 0 else ("-inf" if x < 0 else "nan")
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def _pct(x) -> str:
    if x is None or not math.isfinite(float(x)):
        return "-"
    return f"{100 * float(x):.2f}%"


def source_revision() -> str:
    """The git commit of the oceanmc sources that ran, and whether the engine (oceanmc/ outside
    validation/) had uncommitted changes; 'unknown' outside a git checkout."""
    import subprocess

    import oceanmc
    root = Path(oceanmc.__file__).resolve().parent.parent
    try:
        rev = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True, timeout=20)
        if rev.returncode != 0:
            return "unknown (not a git checkout)"
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--",
                                "oceanmc", ":(exclude)oceanmc/validation"],
                               capture_output=True, text=True, timeout=20)
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    note = " with uncommitted engine changes" if dirty.stdout.strip() else ""
    return f"git {rev.stdout.strip()}{note}"


def write_results(outcomes, path: Path) -> None:
    records = [c.record() for o in outcomes for c in o.ctx.checks]
    tmp = path.with_suffix(".json.tmp")
    body = ",\n".join(json.dumps(r, allow_nan=False) for r in records)   # one record per line
    tmp.write_text("[\n" + body + "\n]\n", encoding="utf-8")
    tmp.replace(path)


def _case_stats(o):
    checks = o.ctx.checks
    scalar = [c for c in checks if c.kind == "z" and c.reference not in (None, 0) and
              c.rel_error is not None and math.isfinite(c.rel_error) and
              "quad" not in c.quantity and "band" not in c.quantity]
    max_rel = max((abs(c.rel_error) for c in scalar), default=None)
    med_rel_se = None
    if scalar:
        vals = sorted(c.rel_stderr for c in scalar if c.rel_stderr is not None)
        med_rel_se = vals[len(vals) // 2] if vals else None
    return {
        "n": len(checks),
        "n_fail": sum(not c.passed for c in checks),
        "worst_z": o.ctx.worst_z,
        "max_rel_scalar": max_rel,
        "median_rel_se_scalar": med_rel_se,
    }


def write_report(outcomes, path: Path, *, quick: bool, wall_s: float, threads: int | None,
                 override: dict | None) -> None:
    import numba
    import numpy
    import scipy

    import oceanmc
    lines: list[str] = []
    ok = all(o.passed for o in outcomes)
    now = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    lines += [
        "# oceanmc validation report",
        "",
        f"**Overall: {'PASS' if ok else 'FAIL'}** - {len(outcomes)} cases, "
        f"{sum(len(o.ctx.checks) for o in outcomes)} checks, "
        f"{sum(_case_stats(o)['n_fail'] for o in outcomes)} failing.",
        "",
        f"- mode: {'quick' if quick else 'full'}; generated {now}; total wall time "
        f"{wall_s:.0f} s on {threads or numba.get_num_threads()} threads",
        f"- oceanmc {oceanmc.__version__} ({source_revision()}), numba {numba.__version__}, "
        f"numpy {numpy.__version__}, "
        f"scipy {scipy.__version__}, Python {platform.python_version()} ({platform.machine()})",
        f"- photons simulated: {sum(r.photons for o in outcomes for r in o.ctx.runs):,} in "
        f"{sum(len(o.ctx.runs) for o in outcomes)} scenes",
    ]
    if override:
        lines.append(f"- **scene override applied to every scene: `{json.dumps(override)}`** "
                     "(not a validation of the default physics)")
    lines += [
        "- regenerate: `oceanmc validate -o validation` (see validation/README.md)",
        "",
        "| case | what | checks | failing | worst \\|z\\| | max \\|rel. error\\| (fluxes, "
        "reflectances: not quads or bands) | their median rel. stderr | time | result |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for o in outcomes:
        s = _case_stats(o)
        lines.append(
            f"| [{o.case.name}](#{o.case.name}) | {o.case.title} | {s['n']} | {s['n_fail']} | "
            f"{_fmt(s['worst_z'], 3)} | {_pct(s['max_rel_scalar'])} | "
            f"{_pct(s['median_rel_se_scalar'])} | {o.wall_s:.0f} s | "
            f"{'PASS' if o.passed else '**FAIL**'} |")
    lines += [
        "",
        "## How the checks work",
        "",
        "- Every Monte Carlo estimate is the mean over independent batches; its standard error "
        "is the batch standard deviation over sqrt(batches). Derived quantities (ratios, band "
        "averages, combinations of runs paired batch by batch) get jackknife standard errors "
        "over the batches.",
        "- A statistical check is a z-score z = (estimate - reference) / sqrt(stderr^2 + "
        "ref_error^2), ref_error being a deterministic reference's own error estimate (DISORT "
        "only; analytic references have none).",
        f"- Tolerance: the bounds of a case's statistical checks are set together so that a "
        f"correct engine fails the case with probability at most {FAMILY_ALPHA:g} (Bonferroni): "
        "half of that over the members of groups (quads, bands, depths), half over the single "
        "quantities and the groups' summaries. A z is Student-t distributed with batches - 1 "
        "degrees of freedom (its standard error comes from the batches), so the bounds are t "
        f"quantiles (never below {MIN_Z_TOL:g}); the bound of each check is in its record. Each "
        "group also gets a summary check, which catches a small bias spread over many bins: for "
        "groups whose batch covariance has rank r <= batches/2 (members often correlated, e.g. "
        "Ed at several depths of one run, or exact multiples of one another, as the local "
        "estimates of an isotropic radiance) Hotelling's T^2 over those r combinations, through "
        "F(r, batches - r), as a one-sided normal z; for larger groups (quads: disjoint bins) "
        "the chi-square of the members' normal-equivalent z, as a one-sided normal z.",
        "- Power: a check cannot pass by being noisy. Scalars carry a cap on the relative "
        "standard error (stderr/|reference|); groups a cap on its median over the group "
        "(recorded on the summary row). Quick mode uses about a tenth of the photons and "
        "looser caps, but asserts the same z bounds.",
        "- Deterministic checks (implicit-mode weights that are exact, zero radiance where no "
        "light can go, total internal reflection, references against quoted numbers) must hold "
        "to the stated absolute/relative tolerance.",
        "- The crossing estimator replaces 1/|mu| by 2/mu_cut for |mu| < mu_cut = 0.01 "
        "(oceanmc/kernel/tally.py). References for the band next to the horizontal are the "
        "expectation of that estimator (exact for radiance constant near the horizon); "
        "elsewhere they are plain quad averages.",
        "- Quad references are solid-angle averages over the quad (integrals over mu and phi), "
        "never the value at the quad centre.",
        "- Every record is in results.json (case, quantity, value, stderr, reference, z, "
        "tolerance, pass, kind, group, ref_error, rel_error, rel_stderr, rel_stderr_cap, note).",
        "",
    ]
    for o in outcomes:
        lines += _case_section(o)
    tmp = path.with_suffix(".md.tmp")
    tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    tmp.replace(path)


def _case_section(o) -> list[str]:
    ctx = o.ctx
    s = _case_stats(o)
    out = [f'<a id="{o.case.name}"></a>', "",
           f"## {o.case.name}: {o.case.title} - {'PASS' if o.passed else 'FAIL'}", ""]
    out.append(f"{o.case.summary}. {s['n']} checks, {s['n_fail']} failing, worst |z| "
               f"{_fmt(s['worst_z'], 3)}, {o.wall_s:.0f} s.")
    out.append("")
    if o.error:
        out += ["**The case raised an error:**", "", "```", o.error.strip(), "```", ""]
    for note in ctx.notes:
        out += [note, ""]
    for file, caption in ctx.figures:
        out += [f"![{caption}](figures/{file})", "", f"*{caption}*", ""]
    # scenes
    if ctx.runs:
        total = sum(r.photons for r in ctx.runs)
        out += [f"<details><summary>{len(ctx.runs)} scenes, {total:,} photons</summary>", "",
                "| scene | photons | batches | wall (s) | photons/s |", "|---|---|---|---|---|"]
        for r in ctx.runs:
            out.append(f"| {r.name} | {r.photons:,} | {r.batches} | {r.wall_s:.2f} | "
                       f"{r.photons_per_s:,.0f} |")
        out += ["", "</details>", ""]
    # scalar and exact checks
    singles = [c for c in ctx.checks if not c.group]
    if singles:
        out += ["| check | value | stderr | reference | rel. error | z | tolerance | pass |",
                "|---|---|---|---|---|---|---|---|"]
        for c in singles:
            tol = (f"\\|z\\| <= {_fmt(c.tolerance, 3)}" if c.kind == "z" else
                   f"\\|diff\\| <= {_fmt(c.tolerance, 3)}")
            if c.kind == "z" and c.rel_stderr_cap is not None:
                tol += f", rel. stderr {_pct(c.rel_stderr)} <= {_pct(c.rel_stderr_cap)}"
            out.append(f"| {c.quantity} | {_fmt(c.value, 6)} | {_fmt(c.stderr, 3)} | "
                       f"{_fmt(c.reference, 6)} | {_pct(c.rel_error)} | {_fmt(c.z, 3)} | {tol} | "
                       f"{'yes' if c.passed else '**NO**'} |")
        out.append("")
    groups: OrderedDict[str, list] = OrderedDict()
    for c in ctx.checks:
        if c.group:
            groups.setdefault(c.group, []).append(c)
    if groups:
        out += ["Groups (every member in results.json):", "",
                "| group | N | worst \\|z\\| (bound) | worst member | group summary z (<= 4) | "
                "max \\|rel. error\\| | median rel. stderr (cap) | pass |",
                "|---|---|---|---|---|---|---|---|"]
        for name, cs in groups.items():
            members = [c for c in cs if c.kind == "z"]
            summary = next((c for c in cs if c.kind == "chi2"), None)
            exacts = [c for c in cs if c.kind == "exact"]
            if not members:
                for c in exacts:
                    out.append(f"| {c.quantity} | - | - | - | - | - | - | "
                               f"{'yes' if c.passed else '**NO**'} |")
                continue
            worst = max(members, key=lambda c: abs(c.z) if c.z is not None and
                        math.isfinite(c.z) else math.inf)
            rels = [abs(c.rel_error) for c in members if c.rel_error is not None and
                    math.isfinite(c.rel_error)]
            label = worst.quantity[len(name):].strip() or worst.quantity
            cap = (f"{_pct(summary.rel_stderr)} ({_pct(summary.rel_stderr_cap)})"
                   if summary and summary.rel_stderr_cap is not None
                   else (_pct(summary.rel_stderr) if summary else "-"))
            out.append(
                f"| {name} | {len(members)} | "
                f"{_fmt(abs(worst.z) if worst.z is not None else None, 3)}"
                f" ({_fmt(worst.tolerance, 3)}) | {label} | "
                f"{_fmt(summary.z, 3) if summary else '-'} | "
                f"{_pct(max(rels)) if rels else '-'} | {cap} | "
                f"{'yes' if all(c.passed for c in cs) else '**NO**'} |")
        out.append("")
        failing = [c for c in ctx.checks if c.group and not c.passed]
        if failing:
            out += ["Failing group members:", "",
                    "| check | value | stderr | reference | z | tolerance |",
                    "|---|---|---|---|---|---|"]
            for c in failing[:40]:
                out.append(f"| {c.quantity} | {_fmt(c.value, 6)} | {_fmt(c.stderr, 3)} | "
                           f"{_fmt(c.reference, 6)} | {_fmt(c.z, 3)} | {_fmt(c.tolerance, 3)} |")
            if len(failing) > 40:
                out.append(f"| ... {len(failing) - 40} more in results.json | | | | | |")
            out.append("")
    return out
