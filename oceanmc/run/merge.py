"""Merging: one Result from several runs of one scene by concatenating their batches, with the
checks that they are runs of the same scene (scene_difference, the data files' hashes) whose
batches are independent (merge_results) or continue one another (resume=True; check_resumable).
"""
from __future__ import annotations

import json
from typing import Any

import numpy as np

from .result import UNDEFINED_RATIOS, Quantity, Result, common_quantities

RHO = "air/rho"


class MergeError(ValueError):
    """Results that cannot be combined; the message says why."""


def scene_difference(config_yaml: str, other_yaml: str, *ignored: str) -> str:
    """"" when the two stored scenes agree (but for the ignored top-level keys), else "KEY
    differs" naming the first key path where they do, so that a refusal says what to compare."""
    def first(a: Any, b: Any, path: str) -> str | None:
        if isinstance(a, dict) and isinstance(b, dict):
            for key in list(a) + [k for k in b if k not in a]:
                if path == "" and key in ignored:
                    continue
                where = f"{path}.{key}" if path else str(key)
                if key not in a or key not in b:
                    return where
                found = first(a[key], b[key], where)
                if found:
                    return found
            return None
        if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
            for i, (x, y) in enumerate(zip(a, b)):
                found = first(x, y, f"{path}[{i}]")
                if found:
                    return found
            return None
        return None if a == b else (path or "(top level)")

    import yaml
    found = first(yaml.safe_load(config_yaml), yaml.safe_load(other_yaml), "")
    return f"{found} differs" if found else ""


def _batch_ranges(part: Result) -> list[tuple[int, int, int]]:
    """(seed, first batch, end) of each run a result holds: batch b of seed s is the same photons
    in every run (rng.batch_state). A merge records them in attribute batch_ranges; a merged
    file from before that attribute counts as all the batches of each of its seeds."""
    if "batch_ranges" in part.attrs:
        return [tuple(int(x) for x in r.split(":"))
                for r in str(part.attrs["batch_ranges"]).split(",")]
    if "seeds" in part.attrs:
        return [(int(s), 0, 2**62) for s in str(part.attrs["seeds"]).split(",")]
    first = int(part.attrs.get("first_batch", 0))
    return [(int(part.attrs["seed"]), first, first + int(part.attrs["batches"]))]


def check_same_data_files(stored: dict, current: dict, what: str) -> None:
    """Raises MergeError naming the data file whose content (sha256 in data_files_sha256)
    differs between two results' attrs; `what` names the second one in the message."""
    try:
        ours, theirs = (json.loads(str(attrs.get("data_files_sha256", "{}")))
                        for attrs in (stored, current))
        paths = sorted(set(ours) | set(theirs))
    except (ValueError, TypeError):
        raise MergeError(f"{what}: data_files_sha256 is not a mapping of file hashes") from None
    for path in paths:
        if ours.get(path) != theirs.get(path):
            raise MergeError(f"the content of {path} differs for {what} (sha256): the results "
                             "would mix two different scenes")


def check_resumable(part: Result) -> None:
    """Raises MergeError when part holds several runs (a merge): their unfinished batches are
    not kept and their batch ranges are not one run's, so it cannot be continued; or when its
    unfinished batches are the raw tally rows an earlier oceanmc stored (run/hdf5.py), whose
    layout cannot be known."""
    if "merged_from" in part.attrs or "seeds" in part.attrs:
        raise MergeError(f"it merges {part.attrs.get('merged_from', 'several')} runs (seeds "
                         f"{part.attrs.get('seeds')}) and cannot be continued: resume each "
                         "partial run in its own file, then merge them")
    if part.resume_state is not None and "tally" in part.resume_state:
        raise MergeError("its unfinished batches were stored by an earlier oceanmc as raw tally "
                         "rows, which this one cannot read, and cannot be continued: its "
                         f"{part.attrs['batches']} whole batches stay readable (oceanmc show, "
                         "oceanmc merge); run the scene again for the rest")


def merge_results(parts: list[Result], *, resume: bool = False) -> Result:
    """One Result from several runs of the same scene, by concatenating their batches (the
    standard errors then come from all batches together).

    Independent runs (resume=False) must not share a batch (the same seed and batch index) and
    must agree on everything else but the photon count; photons per batch must match so that
    the batches are alike. A resumed run
    (resume=True) continues the batches of the same seed: the scenes must be identical and the
    batch ranges contiguous."""
    if len(parts) < 2:
        raise MergeError("need at least two results to merge")
    first = parts[0]
    if resume:
        check_resumable(first)
        for part in parts[1:]:
            differs = scene_difference(first.config_yaml, part.config_yaml)
            if differs:
                raise MergeError(f"the stored scene differs from the one being resumed "
                                 f"({differs})")
            check_same_data_files(first.attrs, part.attrs, "the resumed part")
        expected = int(first.attrs.get("first_batch", 0))
        for i, part in enumerate(parts):
            if int(part.attrs.get("first_batch", 0)) != expected:
                raise MergeError(f"result {i + 1} starts at batch {part.attrs.get('first_batch')}"
                                 f", expected {expected}")
            expected += int(part.attrs["batches"])
    else:
        ranges: list[tuple[int, int, int, int]] = []   # (seed, first, end, result number)
        for i, part in enumerate(parts):
            differs = scene_difference(first.config_yaml, part.config_yaml,
                                       "seed", "photons", "name")
            if differs:
                raise MergeError(f"result {i + 1} is a different scene from result 1 "
                                 f"({differs})")
            check_same_data_files(first.attrs, part.attrs, f"result {i + 1}")
            if part.attrs.get("photons_per_batch") != first.attrs.get("photons_per_batch"):
                raise MergeError(f"result {i + 1} has {part.attrs.get('photons_per_batch')} "
                                 f"photons per batch, result 1 has "
                                 f"{first.attrs.get('photons_per_batch')}: batches must be alike")
            for seed, lo, hi in _batch_ranges(part):
                for other_seed, other_lo, other_hi, j in ranges:
                    if seed == other_seed and max(lo, other_lo) < min(hi, other_hi):
                        raise MergeError(
                            f"batches {max(lo, other_lo)}..{min(hi, other_hi) - 1} of seed {seed} "
                            f"are in both result {j} and result {i + 1}: the same photons, not "
                            "independent ones")
                ranges.append((seed, lo, hi, i + 1))
    kept = common_quantities(parts)
    differing = set().union(*(p.quantities for p in parts)) - kept
    if len({p.quantities[RHO].description for p in parts if RHO in p.quantities}) > 1:
        # air/rho by two definitions (a file written before its denominator became the sky's
        # own radiance over the mirror quad, 2026-11-29, holds batches biased low at few
        # photons): left out rather than joined, as a ratio some run lacks is
        kept.discard(RHO)
    if differing - UNDEFINED_RATIOS:
        raise MergeError(f"the results hold different quantities "
                         f"({', '.join(sorted(differing - UNDEFINED_RATIOS))})")
    quantities = {
        name: Quantity(name, q.dims, np.concatenate([p.quantities[name].batches for p in parts]),
                       q.units, q.description)
        for name, q in first.quantities.items() if name in kept
    }
    attrs = dict(first.attrs)
    for key in ("photons", "batches", "scattering_events"):
        attrs[key] = sum(int(p.attrs[key]) for p in parts)
    for key in ("wall_time_s", "startup_time_s"):
        attrs[key] = sum(float(p.attrs[key]) for p in parts)
    attrs["photons_per_s"] = attrs["photons"] / attrs["wall_time_s"] \
        if attrs["wall_time_s"] > 0 else float("inf")
    attrs["partial"] = bool(parts[-1].attrs.get("partial", False)) if resume else \
        any(bool(p.attrs.get("partial", False)) for p in parts)
    if resume:   # the threads of the run that continued it, which its summary reports
        attrs["threads"] = parts[-1].attrs["threads"]
    if not resume:
        attrs["seeds"] = ",".join(dict.fromkeys(str(r[0]) for r in ranges))
        attrs["batch_ranges"] = ",".join(f"{seed}:{lo}:{hi}" for seed, lo, hi, _ in ranges)
        attrs["merged_from"] = len(parts)
    # a resumed run's unfinished batches are those of its last part
    return Result(dict(first.coords), quantities, attrs,
                  parts[-1].resume_state if resume else None, dict(first.iops))
