"""Regression comparison of every output quantity between two versions of the kernel.

    python benchmarks/regression.py record OUT.npz [--configs configs] [--cases all]
    python benchmarks/regression.py compare BEFORE.npz AFTER.npz [-o benchmarks/regression.md]
        [--labels "commit c077515" "commit abc1234"]

`record` runs, with fixed seeds, every shipped config (configs/*.yaml, at its own photon count)
and every scene of every validation case (quick mode: the case's own seeds), and stores each
output quantity's mean and standard error. Run it once with the old kernel on the path
(PYTHONPATH=/path/to/old/checkout) and once with the new one.

`compare` matches the scenes and quantities of the two files and computes, for every element,
z = (after - before) / sqrt(se_before^2 + se_after^2). Each standard error comes from a scene's
batches (as few as 2 in some validation scenes), so z is Student-t distributed with the
Welch-Satterthwaite degrees of freedom nu = (s0^2 + s1^2)^2 / (s0^4 / (n0 - 1) + s1^4 / (n1 - 1))
(Welch 1947, Biometrika 34, 28): it is reported as the normal z of the same two-sided tail
probability (as is, where a recording has no batch counts). Elements whose standard errors are
both zero must agree to 1e-12 relative, unless the scene has fewer than EXACT_MIN_BATCHES
batches: there two equal batch values (one photon in a quad in each) happen by chance, and such
elements are counted, not tested. The bound is Bonferroni-corrected for the number of elements
compared: a family-wise false-alarm rate of 1% two-sided, |z| <= Phi^-1(1 - 0.005 / N).
Identical random streams give z = 0 everywhere; the report says how many elements are
bit-identical. Exit status 1 if any element fails.
"""
from __future__ import annotations

import argparse
import json
import math
from collections import Counter
import sys
import time
from pathlib import Path

import numpy as np
from scipy import stats

ROOT = Path(__file__).resolve().parent.parent
FAMILY_ALPHA = 0.01
EXACT_MIN_BATCHES = 8
ROUNDING = 1e-12            # relative difference below which two values are equal to rounding


def _store(store: dict, key: str, result) -> None:
    for name, q in result.quantities.items():
        store[f"{key}|{name}|mean"] = np.asarray(q.mean, dtype=np.float64)
        store[f"{key}|{name}|stderr"] = np.asarray(q.stderr, dtype=np.float64)
    store[f"{key}|batches"] = np.asarray(result.attrs["batches"])


def record(out: Path, configs_dir: Path, cases: list[str] | None) -> int:
    import oceanmc
    import oceanmc.validation as validation

    store: dict[str, np.ndarray] = {}
    for path in sorted(configs_dir.glob("*.yaml")):
        t0 = time.perf_counter()
        _store(store, f"config:{path.stem}", oceanmc.simulate(path))
        print(f"config {path.stem}: {time.perf_counter() - t0:.1f} s", flush=True)

    real_simulate = oceanmc.simulate
    current = {"case": "", "n": 0}

    def recording_simulate(config, **kwargs):
        result = real_simulate(config, **kwargs)
        current["n"] += 1
        _store(store, f"case:{current['case']}:{current['n']}", result)
        return result

    oceanmc.simulate = recording_simulate
    try:
        names = cases or [c.name for c in validation.CASES]
        for name in names:
            current["case"], current["n"] = name, 0
            t0 = time.perf_counter()
            outcome = validation.run_case(name, quick=True)
            print(f"case {name}: {current['n']} scenes, "
                  f"{'pass' if outcome.passed else 'FAIL'}, {time.perf_counter() - t0:.1f} s",
                  flush=True)
    finally:
        oceanmc.simulate = real_simulate
    np.savez_compressed(out, **store)
    print(f"{sum(k.endswith('|mean') for k in store)} quantities written to {out}")
    return 0


def compare(before_path: Path, after_path: Path, report: Path | None,
            labels: tuple[str, str] = ("before", "after")) -> int:
    before = np.load(before_path)
    after = np.load(after_path)
    keys = sorted({k.rsplit("|", 1)[0] for k in before.files if k.count("|") == 2})
    keys_after = sorted({k.rsplit("|", 1)[0] for k in after.files if k.count("|") == 2})

    def batches(recording, key):
        """The scene's batch count (0: not recorded)."""
        name = key.split("|", 1)[0] + "|batches"
        return int(recording[name]) if name in recording.files else 0
    missing = sorted(set(keys) - set(keys_after))
    extra = sorted(set(keys_after) - set(keys))
    rows = []
    n_elements = n_identical = n_exact = n_untested = n_rounding = 0
    for key in keys:
        if key in missing:
            continue
        m0, s0, m1, s1 = (np.atleast_1d(recording[f"{key}|{part}"])
                          for recording in (before, after) for part in ("mean", "stderr"))
        if m0.shape != m1.shape:
            rows.append((key, m0.size, math.inf, "shape changed"))
            continue
        finite = np.isfinite(m0) & np.isfinite(m1)
        n_elements += int(finite.sum())
        n_identical += int((finite & (m0 == m1)).sum())
        v0, v1 = np.nan_to_num(s0) ** 2, np.nan_to_num(s1) ** 2
        se = np.sqrt(v0 + v1)
        exact = finite & (se == 0.0)
        n_exact += int(exact.sum())
        scale = np.maximum(np.abs(m0), np.abs(m1))
        # equal to rounding: a deterministic quantity (the incoming sun in its quad) has a
        # standard error of rounding noise (1e-15), so a z of such differences means nothing
        rounding = finite & (np.abs(m1 - m0) <= ROUNDING * np.maximum(scale, 1e-300))
        n_rounding += int((rounding & (m0 != m1)).sum())
        exact_bad = exact & ~rounding
        n1 = batches(after, key)
        n0 = batches(before, key) or n1
        if 0 < min(n0, n1) < EXACT_MIN_BATCHES:
            n_untested += int(exact_bad.sum())
            exact_bad = np.zeros_like(exact_bad)
        with np.errstate(divide="ignore", invalid="ignore"):
            tested = finite & (se > 0.0) & ~rounding
            z = np.where(tested, (m1 - m0) / se, 0.0)
            if min(n0, n1) >= 2:
                nu = (v0 + v1) ** 2 / (v0 ** 2 / (n0 - 1) + v1 ** 2 / (n1 - 1))
                z[tested] = np.sign(z[tested]) * stats.norm.isf(
                    stats.t.sf(np.abs(z[tested]), nu[tested]))
        worst = float(np.max(np.abs(z))) if z.size else 0.0
        if exact_bad.any():
            worst = math.inf
        nan_mismatch = int((np.isfinite(m0) != np.isfinite(m1)).sum())
        rows.append((key, int(finite.sum()), worst,
                     f"{nan_mismatch} finite/non-finite mismatches" if nan_mismatch else ""))
    bound = float(stats.norm.isf(FAMILY_ALPHA / 2.0 / max(1, n_elements)))
    failing = [r for r in rows if r[2] > bound or r[3]]
    worst = max((r[2] for r in rows), default=0.0)
    lines = [
        "# Regression comparison: kernel before and after",
        "",
        f"`python benchmarks/regression.py compare {before_path.name} {after_path.name}`",
        "",
        f"Before: {labels[0]}. After: {labels[1]}. Every shipped config (configs/*.yaml, at its "
        "own photon count and seed) and every scene of every validation case (quick mode, the "
        "cases' own seeds), recorded with `python benchmarks/regression.py record FILE.npz`.",
        "",
        f"- scene quantities compared: {len(rows)} ({len(keys)} before, {len(keys_after)} after;"
        f" missing after: {len(missing)}, new after: {len(extra)})",
        f"- elements compared: {n_elements}; bit-identical: {n_identical}; exact (zero standard "
        f"error on both sides): {n_exact}; of those, untested (equal batches by chance in a "
        f"scene of fewer than {EXACT_MIN_BATCHES} batches, values differ): {n_untested}; "
        f"equal to rounding (relative difference <= {ROUNDING:g}, not z-tested): {n_rounding}",
        f"- bound: |z| <= {bound:.2f} (Bonferroni, family-wise two-sided alpha {FAMILY_ALPHA} "
        f"over {n_elements} elements)",
        f"- worst |z|: {worst:.3g}; failing quantities: {len(failing)}",
        "",
    ]
    if missing:
        lines += ["Missing after: " + ", ".join(missing), ""]
    if extra:
        # by quantity name, with the number of scenes that have it
        by_name = Counter(key.split("|", 1)[1] for key in extra)
        lines += ["New after (not compared; quantity: scenes): " + ", ".join(
            f"{name}: {count}" for name, count in sorted(by_name.items())), ""]
    if failing:
        lines += ["| quantity | elements | worst abs z | note |", "|---|---|---|---|"]
        lines += [f"| {k} | {n} | {w:.3g} | {note} |" for k, n, w, note in failing]
        lines.append("")
    lines += ["Worst ten:", "", "| quantity | elements | worst abs z |", "|---|---|---|"]
    lines += [f"| {k} | {n} | {w:.3g} |" for k, n, w, _ in sorted(rows, key=lambda r: -r[2])[:10]]
    text = "\n".join(lines) + "\n"
    print(text)
    if report is not None:
        report.write_text(text)
        report.with_suffix(".json").write_text(json.dumps(
            {"elements": n_elements, "identical": n_identical, "exact": n_exact,
             "untested": n_untested, "rounding": n_rounding,
             "bound": bound, "worst_z": worst, "missing": missing, "extra": extra,
             "rows": [{"quantity": k, "elements": n, "worst_z": w, "note": note}
                      for k, n, w, note in rows]}, indent=1, default=float))
    return 1 if failing or missing else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="run every config and validation scene, store outputs")
    rec.add_argument("out", type=Path)
    rec.add_argument("--configs", type=Path, default=ROOT / "configs")
    rec.add_argument("--cases", default="all", help="comma-separated validation case names")
    cmp_ = sub.add_parser("compare", help="compare two recordings")
    cmp_.add_argument("before", type=Path)
    cmp_.add_argument("after", type=Path)
    cmp_.add_argument("-o", "--report", type=Path, default=None)
    cmp_.add_argument("--labels", nargs=2, default=("before", "after"),
                      help="what the two recordings are (e.g. the commits)")
    args = parser.parse_args(argv)
    if args.command == "record":
        cases = None if args.cases == "all" else [c for c in args.cases.split(",") if c]
        return record(args.out, args.configs, cases)
    return compare(args.before, args.after, args.report, tuple(args.labels))


if __name__ == "__main__":
    sys.exit(main())
