"""oceanmc's validation suite: analytic and independent references, and the report builder.

    from pathlib import Path
    import oceanmc.validation as v
    status = v.main(Path("validation"), quick=False)   # 0: every check passed, 1: some failed

main() runs every case, prints one line per case (name, PASS/FAIL, worst |z|), and writes
out_dir/report.md, out_dir/figures/*.png and out_dir/results.json (a list of records: case,
quantity, value, stderr, reference, z, tolerance, pass, and kind, group, ref_error, rel_error,
rel_stderr, rel_stderr_cap, note). The command line `oceanmc validate [-o DIR] [--quick]` calls it.

Cases (one module each under cases/, shared helpers in cases/common.py, the registry CASES in
cases/__init__.py; see also the report): brdf_bottom, brdf_models, optical_manhole, fresnel,
beer_lambert, chandrasekhar, disort, upward_bias, white_furnace, reciprocity.

Running with deliberately changed physics (to show that a check can fail):

- keyword arguments: main(out_dir, quick, cases=["fresnel"], override={"surface":
  {"fresnel": "schlick"}}) or run_case("fresnel", quick=True, override=...);
- environment variables, read by main() when the keywords are not given:
  OCEANMC_VALIDATION_OVERRIDE  a JSON object deep-merged into every scene's config
                               (e.g. '{"surface": {"fresnel": "schlick"}}');
  OCEANMC_VALIDATION_CASES     comma-separated case names to run (default: all).

An override changes every scene of the selected cases, so the report then says so at the top; it
is for testing the suite, not for validating the engine.
"""
from __future__ import annotations

import json
import os
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

from .cases import CASES, Case
from .context import Check, Ctx

ENV_OVERRIDE = "OCEANMC_VALIDATION_OVERRIDE"
ENV_CASES = "OCEANMC_VALIDATION_CASES"

__all__ = ["main", "run_case", "CASES", "ENV_OVERRIDE", "ENV_CASES"]


@dataclass
class Outcome:
    case: Case
    ctx: Ctx
    wall_s: float
    error: str | None = None

    @property
    def passed(self) -> bool:
        return self.error is None and self.ctx.passed


def _case_by_name(name: str) -> Case:
    for case in CASES:
        if case.name == name:
            return case
    raise KeyError(f"unknown validation case {name!r}; known: {[c.name for c in CASES]}")


def run_case(name: str, quick: bool = True, override: dict | None = None,
             fig_dir: Path | None = None, threads: int | None = None) -> Outcome:
    """Runs one case (no report); outcome.passed, outcome.ctx.checks hold the verdicts."""
    case = _case_by_name(name)
    ctx = Ctx(case.name, quick, fig_dir, override=override, threads=threads)
    t0 = time.perf_counter()
    error = None
    try:
        case.run(ctx)
        ctx.finalize()
    except Exception:   # a crashing case is a failing case, and the others still run
        error = traceback.format_exc()
        ctx.checks.append(Check(case.name, "case ran to completion", 0.0, None, 1.0, None, 0.0,
                                False, "exact", "", note=error.strip().splitlines()[-1]))
    return Outcome(case, ctx, time.perf_counter() - t0, error)


def _env_override() -> dict | None:
    text = os.environ.get(ENV_OVERRIDE, "").strip()
    if not text:
        return None
    value = json.loads(text)
    if not isinstance(value, dict):
        raise ValueError(f"{ENV_OVERRIDE} must be a JSON object, got {text!r}")
    return value


def main(out_dir: Path = Path("validation"), quick: bool = False, *,
         cases: list[str] | None = None, override: dict | None = None,
         threads: int | None = None) -> int:
    """Runs the validation cases and writes the report; returns 0 if every check passed, else 1."""
    from ..run.compiling import ready
    from .report import write_report, write_results

    out_dir = Path(out_dir)
    fig_dir = out_dir / "figures"
    fig_dir.mkdir(parents=True, exist_ok=True)
    if override is None:
        override = _env_override()
    if cases is None:
        env = os.environ.get(ENV_CASES, "").strip()
        cases = [c.strip() for c in env.split(",") if c.strip()] if env else None
    selected = [_case_by_name(n) for n in cases] if cases else list(CASES)
    for case in selected:   # stale figures of the cases about to run
        for old in fig_dir.glob(f"{case.name}_*.png"):
            old.unlink()

    t0 = time.perf_counter()
    # the cases' scenes hold every optional part of the photon loop between them: one
    # compilation (or load) of the whole loop serves them all, where a variant per set of parts
    # would be compiled one after another (kernel/variants.py)
    ready()
    outcomes = []
    for case in selected:
        outcome = run_case(case.name, quick=quick, override=override, fig_dir=fig_dir,
                           threads=threads)
        outcomes.append(outcome)
        n_fail = sum(not c.passed for c in outcome.ctx.checks)
        print(f"{case.name:16s} {'PASS' if outcome.passed else 'FAIL'}  worst |z| = "
              f"{outcome.ctx.worst_z:6.2f}  ({len(outcome.ctx.checks)} checks, {n_fail} failing, "
              f"{outcome.wall_s:.0f} s)" + ("  [raised an error]" if outcome.error else ""),
              flush=True)
    wall = time.perf_counter() - t0
    write_results(outcomes, out_dir / "results.json")
    write_report(outcomes, out_dir / "report.md", quick=quick, wall_s=wall, threads=threads,
                 override=override)
    ok = all(o.passed for o in outcomes)
    print(f"validation {'PASSED' if ok else 'FAILED'} in {wall:.0f} s; report: "
          f"{out_dir / 'report.md'}", flush=True)
    return 0 if ok else 1

