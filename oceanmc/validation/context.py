"""The machinery each validation case uses: running scenes (with an optional override), recording
checks with their z-scores and tolerances, and collecting figures and notes for the report."""
from __future__ import annotations

import copy
import math
import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..plot import close, save
from .stats import (FAMILY_ALPHA, JK, MIN_Z_TOL, chi2_z, hotelling_z, summary_tolerance, z_score,
                    z_tolerance)


@dataclass
class Check:
    case: str
    quantity: str
    value: float
    stderr: float | None
    reference: float
    z: float | None
    tolerance: float
    passed: bool
    kind: str = "z"                 # z | chi2 | exact
    group: str = ""
    ref_error: float = 0.0
    rel_error: float | None = None
    rel_stderr: float | None = None
    rel_stderr_cap: float | None = None
    note: str = ""
    n_batches: int | None = None    # z checks: the batches behind the standard error
    other_ok: bool = True           # everything but the z bound (precision cap, finite members)

    def record(self) -> dict:
        def num(x):
            if x is None:
                return None
            x = float(x)
            return x if math.isfinite(x) else None
        return {"case": self.case, "quantity": self.quantity, "value": num(self.value),
                "stderr": num(self.stderr), "reference": num(self.reference), "z": num(self.z),
                "tolerance": num(self.tolerance), "pass": bool(self.passed), "kind": self.kind,
                "group": self.group, "ref_error": num(self.ref_error),
                "rel_error": num(self.rel_error), "rel_stderr": num(self.rel_stderr),
                "rel_stderr_cap": num(self.rel_stderr_cap), "note": self.note}


@dataclass
class SceneRun:
    name: str
    photons: int
    batches: int
    wall_s: float
    photons_per_s: float


def deep_merge(base: dict, override: dict | None) -> dict:
    """A copy of base with override's keys laid over it (dicts merged recursively)."""
    out = copy.deepcopy(base)
    for key, value in (override or {}).items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


@dataclass
class Ctx:
    case: str
    quick: bool
    fig_dir: Path | None
    override: dict | None = None
    threads: int | None = None
    checks: list[Check] = field(default_factory=list)
    runs: list[SceneRun] = field(default_factory=list)
    figures: list[tuple[str, str]] = field(default_factory=list)   # (file name, caption)
    notes: list[str] = field(default_factory=list)
    _seed_counter: int = 0

    # --- running scenes -----------------------------------------------------------------------

    @property
    def batches(self) -> int:
        return 32 if self.quick else 64

    def pick(self, full, quick):
        return quick if self.quick else full

    def next_seed(self) -> int:
        self._seed_counter += 1
        return (zlib.crc32(self.case.encode()) % 100_000) * 1000 + self._seed_counter

    def simulate(self, config: dict):
        import oceanmc
        config = deep_merge(config, self.override)
        config.setdefault("batches", self.batches)
        config.setdefault("seed", self.next_seed())
        t0 = time.perf_counter()
        result = oceanmc.simulate(config, threads=self.threads)
        wall = time.perf_counter() - t0
        self.runs.append(SceneRun(config.get("name", "scene"), int(result.attrs["photons"]),
                                  int(result.attrs["batches"]), wall,
                                  float(result.attrs["photons_per_s"])))
        return result

    # --- checks -------------------------------------------------------------------------------

    def _add(self, check: Check) -> Check:
        self.checks.append(check)
        return check

    def compare(self, quantity: str, value, stderr, reference, *, ref_error=0.0,
                rel_cap: float | None = None, labels=None, group: str | None = None,
                n_batches: int | None = None, note: str = "", counts=None,
                min_count: float = 10.0, loo=None) -> list[Check]:
        """z-score checks of estimates against references. A single quantity must have
        |z| within its bound (and stderr/|reference| <= rel_cap when given). A group of N
        quantities gets a bound for each member and a summary record: the chi-square of the
        members' z as a one-sided normal z, with the median relative standard error, which must
        not exceed rel_cap. The bounds set here are the group's own (Bonferroni over its members);
        finalize() then sets them for the whole case. With the members' leave-one-batch-out replicates (loo, batch
        axis first) and few enough members, the summary is Hotelling's T^2 with their estimated
        covariance instead (members of one run, e.g. depths, are correlated). counts (optional):
        the expected number of photons per batch that score each member; members below
        min_count are left out, since a batch mean of a handful of photons is far from normal
        and its batch standard error is unreliable."""
        value = np.atleast_1d(np.asarray(value, dtype=np.float64)).ravel()
        stderr = np.broadcast_to(np.asarray(stderr, dtype=np.float64), value.shape).ravel() \
            if np.ndim(stderr) else np.full(value.shape, float(stderr))
        reference = np.broadcast_to(np.asarray(reference, dtype=np.float64), value.shape).ravel()
        ref_error = np.broadcast_to(np.asarray(ref_error, dtype=np.float64), value.shape).ravel()
        if labels is None:
            labels = [""] * value.size if value.size == 1 else [f"[{i}]" for i in range(value.size)]
        dropped = 0
        if counts is not None:
            keep = np.broadcast_to(np.asarray(counts, dtype=np.float64), value.shape).ravel() \
                >= min_count
            dropped = int(np.sum(~keep))
            value, stderr, reference, ref_error = (x[keep] for x in (value, stderr, reference,
                                                                      ref_error))
            if loo is not None:
                loo = np.asarray(loo).reshape(np.shape(loo)[0], -1)[:, keep]
            labels = [lab for lab, k in zip(labels, keep) if k]
            if dropped:
                note = (note + "; " if note else "") + f"{dropped} members with fewer than " \
                    f"{min_count:g} expected photons per batch left out"
        n = value.size
        nb = n_batches or self.batches
        tol = z_tolerance(n, nb)
        z = z_score(value, stderr, reference, ref_error)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel_err = np.where(reference != 0, (value - reference) / np.abs(reference), np.nan)
            rel_se = np.where(reference != 0, np.sqrt(stderr ** 2 + ref_error ** 2)
                              / np.abs(reference), np.nan)
        grp = group if group is not None else (quantity if n > 1 else "")
        out = []
        for i in range(n):
            cap = rel_cap if n == 1 else None
            cap_ok = cap is None or (np.isfinite(rel_se[i]) and rel_se[i] <= cap)
            passed = bool(np.isfinite(z[i]) and abs(z[i]) <= tol and cap_ok)
            name = f"{quantity} {labels[i]}".strip()
            out.append(self._add(Check(self.case, name, value[i], stderr[i], reference[i], z[i],
                                       tol, passed, "z", grp, ref_error[i], rel_err[i],
                                       rel_se[i], cap, note, nb, bool(cap_ok))))
        if n > 1:
            hz = None
            if loo is not None:
                hz = hotelling_z(value - reference, np.asarray(loo).reshape(
                    np.shape(loo)[0], -1), ref_error)
            cz = chi2_z(z, nb) if hz is None else hz
            med = float(np.nanmedian(rel_se)) if np.any(np.isfinite(rel_se)) else float("nan")
            cap_ok = rel_cap is None or (np.isfinite(med) and med <= rel_cap)
            finite = bool(np.all(np.isfinite(z)))
            what = (f"[Hotelling T^2 over {n}]" if hz is not None else f"[sum of z^2 over {n}]")
            out.append(self._add(Check(
                self.case, f"{quantity} {what}",
                float(np.sum(z[np.isfinite(z)] ** 2) / n), None,
                (nb - 1) / (nb - 3.0), cz, MIN_Z_TOL, bool(finite and cz <= MIN_Z_TOL and cap_ok),
                "chi2", grp, 0.0, float(np.nanmax(np.abs(rel_err))) if np.any(np.isfinite(
                    rel_err)) else None, med, rel_cap,
                ("value: mean z^2; reference: its expectation for Student-t z; z: Hotelling's "
                 "T^2 with the batch covariance as a one-sided normal z" if hz is not None else
                 "value: mean z^2; reference: its expectation for Student-t z; z: the "
                 "chi-square of the members' normal equivalents as a one-sided normal z")
                + "; rel_stderr: median over the group"
                + (f"; {note}" if note else ""), None, bool(finite and cap_ok))))
        return out

    def finalize(self, alpha: float = FAMILY_ALPHA) -> None:
        """Sets every statistical check's bound so that the whole case raises a false alarm with
        probability at most alpha (Bonferroni): half of alpha over the members of groups (Student
        t bounds), half over the single quantities and the groups' summaries (which carry the
        power against a bias spread over a group); all of it to one kind if the other is absent.
        run_case calls it once the case has run; before, each group has its own bound (stricter)."""
        stat = [c for c in self.checks if c.kind in ("z", "chi2")]
        members = [c for c in stat if c.kind == "z" and c.group]
        heads = [c for c in stat if not (c.kind == "z" and c.group)]
        share = alpha / 2.0 if members and heads else alpha
        for c in members:
            c.tolerance = z_tolerance(len(members), c.n_batches or self.batches, share)
        for c in heads:
            c.tolerance = (z_tolerance(len(heads), c.n_batches or self.batches, share)
                           if c.kind == "z" else summary_tolerance(len(heads), share))
        for c in stat:
            within = c.z is not None and math.isfinite(c.z) and (
                abs(c.z) <= c.tolerance if c.kind == "z" else c.z <= c.tolerance)
            c.passed = bool(within and c.other_ok)

    def compare_jk(self, quantity: str, est: JK, reference, **kw) -> list[Check]:
        return self.compare(quantity, est.value, est.stderr, reference, n_batches=est.n,
                            loo=est.loo.reshape(est.n, -1), **kw)

    def exact(self, quantity: str, value, reference, *, rtol: float = 0.0, atol: float = 0.0,
              note: str = "", group: str = "") -> Check:
        """A deterministic check: |value - reference| <= atol + rtol |reference| (for arrays the
        worst element is recorded)."""
        value = np.atleast_1d(np.asarray(value, dtype=np.float64)).ravel()
        reference = np.broadcast_to(np.asarray(reference, dtype=np.float64), value.shape).ravel()
        allowed = atol + rtol * np.abs(reference)
        excess = np.abs(value - reference) - allowed
        bad = ~np.isfinite(value) | (excess > 0)
        i = int(np.argmax(np.where(np.isfinite(excess), excess, np.inf)))
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = (value[i] - reference[i]) / abs(reference[i]) if reference[i] != 0 else None
        label = quantity if value.size == 1 else f"{quantity} (worst of {value.size})"
        return self._add(Check(self.case, label, value[i], None, reference[i], None,
                               float(allowed[i]), not bool(np.any(bad)), "exact", group, 0.0,
                               rel, None, None, note or f"deterministic: |diff| <= {atol:g} + "
                               f"{rtol:g} |ref|"))

    # --- report material ----------------------------------------------------------------------

    def figure(self, fig, name: str, caption: str) -> None:
        if self.fig_dir is None:
            close(fig)
            return
        self.fig_dir.mkdir(parents=True, exist_ok=True)
        file = f"{self.case}_{name}.png"
        save(fig, self.fig_dir / file, crop=True)
        self.figures.append((file, caption))

    def note(self, text: str) -> None:
        self.notes.append(text)

    @property
    def passed(self) -> bool:
        return bool(self.checks) and all(c.passed for c in self.checks)

    @property
    def worst_z(self) -> float:
        zs = []
        for c in self.checks:
            if c.kind not in ("z", "chi2"):
                continue
            if c.z is None or not math.isfinite(c.z):
                zs.append(math.inf)
            else:
                zs.append(max(c.z, 0.0) if c.kind == "chi2" else abs(c.z))
        return max(zs) if zs else 0.0
