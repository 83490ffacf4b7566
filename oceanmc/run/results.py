"""Result: per-batch tallies turned into means and standard errors (hdf5.py writes and reads it).

Every quantity keeps its per-batch values (leading `batch` axis); the estimate is the mean over
batches and its standard error the sample standard deviation over sqrt(batches). Because the
batch values are stored, results of independent runs merge by concatenating batches.
"""
from __future__ import annotations

import json
import math
import textwrap
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..kernel import models


@dataclass
class Quantity:
    name: str                 # path in the file: "Ed", "air/Lw", "budget/water_leaving"
    dims: tuple[str, ...]     # dimensions of the estimate (without the batch axis)
    batches: np.ndarray       # (batch, *dims)
    units: str
    description: str

    @property
    def mean(self) -> np.ndarray:
        if self.batches.shape[0] == 0:   # a run stopped before its first batch was whole
            return np.full(self.batches.shape[1:], np.nan)
        return self.batches.mean(axis=0)

    @property
    def stderr(self) -> np.ndarray:
        n = self.batches.shape[0]
        if n < 2:
            return np.full(self.batches.shape[1:], np.nan)
        # the deviations are divided by their largest magnitude before they are squared:
        # squared unscaled, deviations below about 1e-154 underflow to 0 (a standard error of
        # exactly 0 for a tiny quantity) and those above about 1e154 overflow
        deviations = self.batches - self.batches.mean(axis=0)
        scale = np.abs(deviations).max(axis=0)
        safe = np.where(scale > 0.0, scale, 1.0)
        spread = np.sqrt(((deviations / safe) ** 2).sum(axis=0) / (n - 1))
        return scale * spread / math.sqrt(n)


@dataclass
class Result:
    coords: dict[str, np.ndarray]
    quantities: dict[str, Quantity]
    attrs: dict[str, object] = field(default_factory=dict)
    # a partial run's unfinished batches, from which --resume continues them (simulation.py)
    resume_state: dict[str, np.ndarray] | None = None
    # the IOPs the run used (optics.iops_table): a, b, bb, c (layer, wavelength) in 1/m and the
    # coordinates layer_top (m), layer_thickness (m), wavelength (nm), and the bottom's
    # reflectance (wavelength) where it has one; the file's group `iops`
    iops: dict[str, np.ndarray] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.quantities[name].mean

    def __contains__(self, name: str) -> bool:
        return name in self.quantities

    def stderr(self, name: str) -> np.ndarray:
        return self.quantities[name].stderr

    @property
    def config_yaml(self) -> str:
        return str(self.attrs["config_yaml"])

    def save(self, path: str | Path, overwrite: bool = True) -> Path:
        """overwrite=False: never replace an existing file (hdf5.place_atomically)."""
        from .hdf5 import save_result
        return save_result(self, path, overwrite)


# --- merging ------------------------------------------------------------------------------------

# ratios from_tallies leaves out of a Result where their denominator is 0 in a batch (there is
# no value to give: 0/0): air/t_up without upwelling light at 0-, air/rho_local without sky
# light. The wavelengths of a spectral run, and runs of one scene, may differ in these only (a
# batch of very absorbing water may have no upwelling photon where another has some)
UNDEFINED_RATIOS = frozenset({"air/t_up", "air/rho_local"})


def common_quantities(parts: list[Result]) -> set[str]:
    """The quantities every part holds: a ratio of UNDEFINED_RATIOS that some part (a
    wavelength of a spectral run, a run to merge) lacks is left out of the whole, as a run
    leaves it out when one of its batches lacks it."""
    return set.intersection(*(set(p.quantities) for p in parts))


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
    if not resume:
        attrs["seeds"] = ",".join(dict.fromkeys(str(r[0]) for r in ranges))
        attrs["batch_ranges"] = ",".join(f"{seed}:{lo}:{hi}" for seed, lo, hi, _ in ranges)
        attrs["merged_from"] = len(parts)
    # a resumed run's unfinished batches are those of its last part
    return Result(dict(first.coords), quantities, attrs,
                  parts[-1].resume_state if resume else None, dict(first.iops))


# --- building a Result from raw kernel tallies ------------------------------------------------

RAD_UNITS = "W m-2 sr-1 (per unit Ed0)"
IRR_UNITS = "W m-2 (per unit Ed0)"


def budget_terms(n_layers: int, inelastic: bool = False) -> list[tuple[int, str, str]]:
    """(column, name, description) of the budget's terms; with inelastic light, also what
    the processes take from each wavelength and give to it (kernel/channels/)."""
    terms = [
        (models.BUDGET_SURFACE_REFLECTION, "surface_reflection",
         "fraction of Ed(0+) reflected by the surface (sun glint and sky reflection)"),
        (models.BUDGET_WATER_LEAVING, "water_leaving", "fraction of Ed(0+) that leaves the water"),
    ]
    terms += [(models.BUDGET_LAYERS + i, f"absorbed_layer_{i + 1}",
               f"fraction of Ed(0+) absorbed in water layer {i + 1}") for i in range(n_layers)]
    terms += [
        (models.BUDGET_BOTTOM, "absorbed_bottom", "fraction of Ed(0+) absorbed by the bottom"),
        (models.BUDGET_LOST_BELOW, "lost_below",
         "fraction of Ed(0+) lost below an infinitely deep, non-absorbing water body"),
        (models.BUDGET_TRUNCATED, "truncated",
         "fraction of Ed(0+) still alive when photons reached estimator.max_events (should be 0)"),
    ]
    if inelastic:
        terms += [
            (models.BUDGET_SHIFTED_OUT, "shifted_out",
             "fraction of Ed(0+) that inelastic processes took from this wavelength (energy)"),
            (models.BUDGET_SHIFTED_IN, "shifted_in",
             "energy that inelastic processes gave to this wavelength, as a fraction of its "
             "Ed(0+); counted negative in budget/total"),
        ]
    return terms


def sun_of(config) -> tuple[float, float]:
    """(sun zenith in deg, direct Ed(0+)) of a scene, for from_tallies."""
    ill = config.illumination
    return ill.sun_zenith_deg, ill.Ed0 * (1.0 - ill.diffuse_fraction)


def from_tallies(raw: dict[str, np.ndarray], grid, depths: np.ndarray, n_per_batch: int,
                 ed0: float, n_layers: int, radiance: bool, attrs: dict,
                 directions: list = (), local_rows: list = (), nadir_local: bool = False,
                 sun: tuple[float, float] | None = None, inelastic: bool = False) -> Result:
    """Normalises raw per-batch weight sums (per launched photon, times Ed0; radiances also per
    quad solid angle) and derives the contract's quantities. directions: the (theta, phi) of the
    local estimates, local_rows: their (water row, air row) in raw["local"]; nadir_local: Lu,
    Lw_nadir and Rrs_nadir come from the local polar-cap estimate in raw["cap"]; sun: (its
    zenith angle in deg, direct Ed(0+)), for the sky radiance in rho (no rho without it);
    inelastic: the budget has the inelastic processes' terms."""
    scale = ed0 / n_per_batch
    omega = grid.solid_angle
    q: dict[str, Quantity] = {}

    def add(name, dims, values, units, description):
        q[name] = Quantity(name, dims, np.ascontiguousarray(values, dtype=np.float64), units,
                           description)

    n_depths = len(depths)
    flux = raw["flux"][:, :n_depths] * scale
    add("Ed", ("depth",), flux[:, :, models.FLUX_ED], IRR_UNITS, "downward plane irradiance")
    add("Eu", ("depth",), flux[:, :, models.FLUX_EU], IRR_UNITS, "upward plane irradiance")
    add("Eod", ("depth",), flux[:, :, models.FLUX_EOD], IRR_UNITS, "downward scalar irradiance")
    add("Eou", ("depth",), flux[:, :, models.FLUX_EOU], IRR_UNITS, "upward scalar irradiance")
    add("Eo", ("depth",), flux[:, :, models.FLUX_EOD] + flux[:, :, models.FLUX_EOU], IRR_UNITS,
        "scalar irradiance Eod + Eou")
    air = raw["flux"][:, n_depths] * scale
    leaving = raw["flux"][:, n_depths + 1] * scale
    add("air/Ed", (), air[:, models.FLUX_ED], IRR_UNITS,
        "downward plane irradiance just above the surface (0+): sun and sky")
    add("air/Eu", (), air[:, models.FLUX_EU], IRR_UNITS,
        "upward plane irradiance at 0+: surface-reflected plus water-leaving")
    add("air/Eod", (), air[:, models.FLUX_EOD], IRR_UNITS, "downward scalar irradiance at 0+")
    add("air/Eou", (), air[:, models.FLUX_EOU], IRR_UNITS, "upward scalar irradiance at 0+")
    add("air/Eu_water_leaving", (), leaving[:, models.FLUX_EU], IRR_UNITS,
        "upward plane irradiance at 0+ from light transmitted out of the water only")
    at_surface = np.nonzero(np.asarray(depths) == 0.0)[0]
    if len(at_surface) and np.all(flux[:, at_surface[0], models.FLUX_EU] > 0.0):
        add("air/t_up", (), leaving[:, models.FLUX_EU] / flux[:, at_surface[0], models.FLUX_EU],
            "1", "upward transmittance of the surface for this run's upwelling light: "
            "Eu_water_leaving(0+) / Eu(0-) (absent when a batch, at any wavelength, has no "
            "upwelling light)")
    if radiance:
        def per_quad(values):
            out = values * scale / omega
            caps = grid.is_cap
            out[..., caps, :] = out[..., caps, :1]  # a cap's one value in every phi column
            return out
        rad = per_quad(raw["radiance"])
        water_rad = rad[:, :n_depths]
        air_rad = rad[:, n_depths]
        lw = rad[:, n_depths + 1]
        add("radiance", ("depth", "theta", "phi"), water_rad, RAD_UNITS,
            "radiance on the (theta, phi) quads, quad average; theta from nadir of the direction "
            "of travel, phi from the sun's travel azimuth")
        add("Lu", ("depth",), water_rad[:, :, -1, 0], RAD_UNITS,
            "nadir-viewing radiance (upward travel), the polar-cap quad average")
        add("air/radiance", ("theta", "phi"), air_rad, RAD_UNITS,
            "radiance at 0+, all light: sun, sky, surface reflection, water-leaving")
        add("air/Lw", ("theta", "phi"), lw, RAD_UNITS,
            "water-leaving radiance at 0+ (surface-reflected light excluded); upward quads only")
        upward = (grid.theta > 90.0)[:, None]
        reflected = np.where(upward, air_rad - lw, 0.0)
        add("air/L_reflected", ("theta", "phi"), reflected, RAD_UNITS,
            "surface-reflected sun and sky radiance at 0+ (all light minus water-leaving); "
            "upward quads only")
        # the mirror of upward quad (theta, phi) is the downward quad (180 - theta, phi): its
        # sky radiance, less the sun's collimated beam where it falls (Ed0 (1 - f) / (mu_s Omega))
        edges = grid.theta_edges
        if sun is not None and np.allclose(edges, 180.0 - edges[::-1]):
            sky_down = air_rad[:, ::-1].copy()
            theta_s, e_direct = sun
            i = min(int(np.searchsorted(edges, theta_s, side="right")) - 1, len(edges) - 2)
            j = 0 if grid.is_cap[i] else int(np.searchsorted(grid.phi_edges, 0.0, "right")) - 1
            beam = e_direct / max(math.cos(math.radians(theta_s)), 1e-12) / omega[i, j]
            mirror = len(edges) - 2 - i
            sky_down[:, mirror, j] -= beam
            if grid.is_cap[i]:
                sky_down[:, mirror, :] -= beam
            # each batch's own ratio, so that batches stay independent and runs merge
            lit = upward & (sky_down > 1e-12 * ed0)
            rho = np.where(lit, reflected / np.where(lit, sky_down, 1.0), 0.0)
            add("air/rho", ("theta", "phi"), rho, "1",
                "sea-surface reflectance factor L_reflected / L_sky per batch, L_sky the mean "
                "sky radiance (sun excluded) of the quad a flat surface reflects into this one; "
                "upward quads, 0 where a batch has no sky light there (a ratio of batch means: "
                "biased where few photons reach a quad; rho_local is exact)")
        add("air/Lu", (), air_rad[:, -1, 0], RAD_UNITS,
            "nadir-viewing radiance at 0+ (water-leaving plus surface-reflected), polar cap")
        add("air/Lw_nadir", (), lw[:, -1, 0], RAD_UNITS,
            "nadir water-leaving radiance at 0+, polar-cap quad average")
        add("air/Rrs_nadir", (), lw[:, -1, 0] / ed0, "sr-1",
            "remote-sensing reflectance Lw_nadir / Ed(0+)")
    lu_method = "polar-cap quad average (theta 175-180 deg with HydroLight edges), crossing " \
                "estimator"
    if nadir_local:
        cap = raw["cap"] * scale
        for name in ("Lu", "air/Lw_nadir", "air/Rrs_nadir"):
            if name in q:  # the crossing estimate of the same cap average, for comparison
                crossing = q.pop(name)
                crossing.name = name + "_crossing"
                crossing.description += " (crossing estimator)"
                q[crossing.name] = crossing
        add("Lu", ("depth",), cap[:, :n_depths], RAD_UNITS,
            "nadir-viewing radiance (upward travel), the polar-cap quad average, local estimate")
        add("air/Lw_nadir", (), cap[:, n_depths], RAD_UNITS,
            "nadir water-leaving radiance at 0+, polar-cap quad average, local estimate")
        add("air/Rrs_nadir", (), cap[:, n_depths] / ed0, "sr-1",
            "remote-sensing reflectance Lw_nadir / Ed(0+)")
        lu_method = "polar-cap quad average (theta 175-180 deg with HydroLight edges), local " \
                    "(next-event) estimate; the crossing estimates of the same averages are " \
                    "Lu_crossing, air/Lw_nadir_crossing, air/Rrs_nadir_crossing"
    if len(directions):
        local = raw["local"] * scale
        water_rows = [w for w, _ in local_rows]
        air_rows = [a for _, a in local_rows]
        add("local_radiance", ("depth", "direction"), local[:, :n_depths][:, :, water_rows],
            RAD_UNITS, "radiance in the exact directions of local_directions_deg (theta, phi "
            "of travel), local (next-event) estimate")
        add("air/Lw_local", ("direction",), local[:, n_depths][:, air_rows], RAD_UNITS,
            "water-leaving radiance at 0+ in the exact directions of local_directions_deg, "
            "local (next-event) estimate")
        add("air/Rrs_local", ("direction",), local[:, n_depths][:, air_rows] / ed0, "sr-1",
            "Lw_local / Ed(0+)")
    if "reflected_local" in raw:   # per batch: (L_reflected, L_sky of the mirror direction)
        reflected, l_sky = raw["reflected_local"][..., 0], raw["reflected_local"][..., 1]
        add("air/L_reflected_local", ("direction",), reflected, RAD_UNITS,
            "surface-reflected sky and sun radiance at 0+ in the exact directions of "
            "local_directions_deg (sky: surface samples; sun: single-reflection glint)")
        if np.all(l_sky > 0.0):   # no sky, no rho
            add("air/rho_local", ("direction",), reflected / l_sky, "1",
                "sea-surface reflectance factor L_reflected_local / L_sky, L_sky the sky "
                "radiance (sun excluded) in the direction a flat surface reflects into the view")
    budget = raw["budget"] / n_per_batch
    terms = budget_terms(n_layers, inelastic)
    for column, name, description in terms:
        add(f"budget/{name}", (), budget[:, column], "1", description)
    # the kernel's columns for inelastic transfers (kernel/channels/) stay 0 without an
    # inelastic process, and are left out; what a process gives counts negative
    columns = sorted(column for column, _, _ in terms)
    signed = budget[:, columns] * np.where(np.array(columns) == models.BUDGET_SHIFTED_IN,
                                           -1.0, 1.0)
    add("budget/total", (), signed.sum(axis=1),
        "1", "sum of all budget terms: 1 up to Russian-roulette noise (an inelastic "
        "process's part: 0)")
    coords = {
        "depth": np.asarray(depths, dtype=np.float64),
        "theta": grid.theta, "phi": grid.phi,
        "theta_edges": grid.theta_edges, "phi_edges": grid.phi_edges,
        "direction": np.arange(len(directions)),
        "direction_theta": np.array([d[0] for d in directions], dtype=np.float64),
        "direction_phi": np.array([d[1] for d in directions], dtype=np.float64),
    }
    attrs = dict(attrs)
    attrs["Lu_method"] = lu_method
    return Result(coords, q, attrs)


# what is not split into the parts of the light (add_parts): ratios, not sums over photons
NOT_SPLIT = frozenset({"air/t_up", "air/rho", "air/rho_local"})


def add_parts(whole: Result, parts: dict[str, Result]) -> None:
    """Adds to `whole` every quantity of each part of the light (elastic, raman,
    chlorophyll_fluorescence: the parts of the tally row, kernel/channels/) under the part's
    name: raman/air/Rrs_nadir is the Raman light's Rrs, and the parts of a quantity add up to
    it batch by batch, so each part has its own standard error. Ratios are not split
    (NOT_SPLIT)."""
    for part_name, part in parts.items():
        for name, q in part.quantities.items():
            if name in NOT_SPLIT:
                continue
            whole.quantities[f"{part_name}/{name}"] = Quantity(
                f"{part_name}/{name}", q.dims, q.batches, q.units,
                f"{q.description} ({PART_DESCRIPTIONS[part_name]})")


PART_DESCRIPTIONS = {
    "elastic": "the light no inelastic process has emitted",
    "raman": "the light Raman scattering by water emitted",
    "chlorophyll_fluorescence": "the light phytoplankton fluoresced",
}


def stack_wavelengths(parts: list[Result], wavelengths: np.ndarray) -> Result:
    """One Result from the per-wavelength Results of a spectral run: every quantity gains a
    leading `wavelength` dimension (nm; the coordinate `wavelength`), after the batch axis. A
    ratio left out at some wavelength (UNDEFINED_RATIOS) is left out of the whole."""
    first = parts[0]
    kept = common_quantities(parts)
    quantities = {
        name: Quantity(name, ("wavelength",) + q.dims,
                       np.stack([p.quantities[name].batches for p in parts], axis=1),
                       q.units, q.description)
        for name, q in first.quantities.items() if name in kept}
    coords = dict(first.coords, wavelength=np.asarray(wavelengths, dtype=np.float64))
    return Result(coords, quantities, dict(first.attrs))


# --- the printed summary -----------------------------------------------------------------------

def nadir_estimate(result: Result) -> str:
    """How Lu, air/Lw_nadir and air/Rrs_nadir were estimated: 'local' (the polar cap's local,
    next-event estimate; with radiance quads the crossing estimates are beside them as
    *_crossing) or 'crossing' (the attribute Lu_method says which)."""
    method = str(result.attrs.get("Lu_method", ""))
    local = "local (next-event)" in method if method else "air/Rrs_nadir_crossing" in result
    return "local" if local else "crossing"


def direction_label(result: Result, k: int) -> str:
    """`180,0`: the exact direction k of local_directions_deg (theta, phi of travel, deg)."""
    return f"{result.coords['direction_theta'][k]:g},{result.coords['direction_phi'][k]:g}"


def local_directions(result: Result) -> range:
    """The indices of the exact directions with local estimates in air (none: empty)."""
    return range(len(result.coords.get("direction_theta", ())) if "air/Rrs_local" in result
                 else 0)


def summary_rows(result: Result) -> list[tuple[str, str, float, float]]:
    """(label, units, value, standard error) for the headline quantities of a run; the nadir
    quantities name their estimator (local or crossing), and each exact direction of
    local_directions_deg has its Rrs row."""
    rows = []
    how = f"({nadir_estimate(result)})"

    def row(label, name, units, index=None):
        if name not in result:
            return
        value, err = result[name], result.stderr(name)
        if index is not None:
            value, err = value[index], err[index]
        rows.append((label, units, float(value), float(err)))

    row("Ed(0+)", "air/Ed", "W/m2")
    row("Eu(0+)", "air/Eu", "W/m2")
    row("Lu(0+) nadir (crossing)", "air/Lu", "W/m2/sr")
    row(f"Lw nadir {how}", "air/Lw_nadir", "W/m2/sr")
    row(f"Rrs nadir {how}", "air/Rrs_nadir", "1/sr")
    for k in local_directions(result):
        row(f"Rrs {direction_label(result, k)} (local)", "air/Rrs_local", "1/sr", k)
    for i, depth in enumerate(result.coords["depth"]):
        where = "0-" if depth == 0.0 else f"{depth:g} m"
        row(f"Ed({where})", "Ed", "W/m2", i)
        row(f"Eu({where})", "Eu", "W/m2", i)
        row(f"Eo({where})", "Eo", "W/m2", i)
        row(f"Lu({where}) {how}", "Lu", "W/m2/sr", i)
    # the budget in the order of budget_terms, as a run makes it (a file read back lists its
    # datasets alphabetically): one order for `run` and `show`
    budget = [name for name in result.quantities if name.startswith("budget/")]
    n_layers = sum(name.startswith("budget/absorbed_layer_") for name in budget)
    order = [f"budget/{term}" for _, term, _ in budget_terms(n_layers)] + ["budget/total"]
    for name in order + [name for name in budget if name not in order]:
        row("budget " + name.split("/", 1)[1], name, "1")
    return rows


def estimator_lines(result: Result) -> list[str]:
    """What the nadir and exact-direction columns or rows are: their quantities, and their
    estimators."""
    edges = result.coords.get("theta_edges")
    cap = f"the {edges[-2]:g}-180 deg polar cap's average" if edges is not None \
        and len(edges) > 1 else "the nadir polar cap's average"
    said = []
    if "air/Rrs_nadir" in result:
        if nadir_estimate(result) == "local":
            said.append(f"Rrs nadir: air/Rrs_nadir, {cap}, local (next-event) estimate"
                        + (" (air/Rrs_nadir_crossing: the crossing estimate)"
                           if "air/Rrs_nadir_crossing" in result else ""))
        else:
            said.append(f"Rrs nadir: air/Rrs_nadir, {cap}, crossing estimate (photons leaving "
                        f"through the cap{local_nadir_hint(result)})")
    ks = local_directions(result)
    if len(ks):
        which = ", ".join(f"Rrs {direction_label(result, k)}" for k in ks)
        said.append(f"{which}: air/Rrs_local in the exact direction{'s' if len(ks) > 1 else ''} "
                    "(theta, phi of travel, deg) of tallies.local_directions_deg, local "
                    "(next-event) estimate: heavy-tailed with forward-peaked phase functions "
                    "(Petzold, Fournier-Forand), whose error bars may understate it")
    return [line for text in said
            for line in textwrap.wrap(text, 100, initial_indent="  ", subsequent_indent="    ")]


def local_nadir_hint(result: Result) -> str:
    """What the crossing estimate's summary line adds: how to get the cap's local estimate, or
    why the scene cannot have it."""
    import yaml
    from pydantic import TypeAdapter

    from ..config import Bottom, Surface, bottom_has_mirror
    from ..config.surface import MAX_CAP_MSS
    try:
        scene = yaml.safe_load(result.config_yaml)
        surface = Surface(**scene["surface"])
        bottom = TypeAdapter(Bottom).validate_python(scene["bottom"])
    except (KeyError, TypeError, ValueError, yaml.YAMLError):
        return ""
    if bottom_has_mirror(bottom):
        return "; a mirror bottom has no density for the local estimate"
    if not surface.cap_lobe_tabulated():
        return ("; the cap's local estimate through waves needs isotropic slopes (no "
                f"wind_direction_deg) of mean square slope <= {MAX_CAP_MSS}")
    return "; tallies.nadir_estimator: local gives the cap's local estimate"


def illumination_lines(result: Result) -> list[str]:
    """Where Ed(0+) came from, for a spectral file: the sun, the spectrum model or table and
    the sky's share of Ed(0+) over the band (none if the file does not say)."""
    import yaml
    try:
        light = yaml.safe_load(result.config_yaml)["illumination"]
        model = light["spectrum"]["model"]
        zenith = float(light["sun_zenith_deg"])
    except (KeyError, TypeError, ValueError, yaml.YAMLError):
        return []
    diffuse = np.atleast_1d(result.attrs.get("illumination_diffuse_fraction", []))
    wl = result.coords["wavelength"]
    where = "sun_position" if light.get("sun_position") else "sun_zenith_deg"
    line = f"illumination: sun at {zenith:.2f} deg from the zenith ({where}), spectrum {model}"
    if len(diffuse) == len(wl) and len(wl):
        line += (f"; sky share of Ed(0+) {diffuse[0]:.3f} at {wl[0]:g} nm .. {diffuse[-1]:.3f} "
                 f"at {wl[-1]:g} nm, mean {diffuse.mean():.3f}")
        if model != "flat":
            line += " (per wavelength: `oceanmc show FILE --config`)"
    return textwrap.wrap(line, 100, initial_indent="  ", subsequent_indent="    ")


# the columns of a spectral run's table: (heading, quantity, depth index or None); the exact
# directions of local_directions_deg follow Rrs nadir
SPECTRAL_COLUMNS = (("Ed(0+)", "air/Ed", None), ("Rrs nadir", "air/Rrs_nadir", None),
                    ("Eu(0+)", "air/Eu", None),
                    ("Ed(z1)", "Ed", 0), ("Eu(z1)", "Eu", 0), ("Eo(z1)", "Eo", 0),
                    ("leaving", "budget/water_leaving", None), ("total", "budget/total", None))


# the printed summary fits a terminal this wide: a spectral table's nm column (8 characters)
# and SPECTRAL_BLOCK columns of 16 (a value, its relative standard error)
SUMMARY_WIDTH = 100
SPECTRAL_BLOCK = (SUMMARY_WIDTH - 8) // 16


def value_cell(value: float, err: float) -> str:
    """A spectral table's cell of 15 characters: the value and its relative standard error in %
    (0.0% for a value of 0)."""
    rel = abs(err / value) if value != 0.0 else 0.0
    return f"{value:>9.4g} {rel:>5.1%}"


# the parts of the light (add_parts) as the summary's headings and the plots' legends name them
PART_LABELS = {"elastic": "elastic", "raman": "Raman",
               "chlorophyll_fluorescence": "fluorescence"}


def light_parts(result: Result) -> list[str]:
    """The parts of a run with inelastic light (attribute inelastic_parts: elastic, then each
    process); [] without inelastic light."""
    parts = str(result.attrs.get("inelastic_parts", "")).split()
    return parts if len(parts) > 1 else []


def lowest_requested(wavelengths: np.ndarray, added: np.ndarray) -> float:
    """The lowest wavelength (nm) the scene asked for, of a grid that also holds the wavelengths
    a run added for the excitation of inelastic light."""
    return float(min(w for w in wavelengths if not np.isclose(added, w).any()))


def wavelength_ranges(wavelengths: np.ndarray) -> str:
    """Sorted wavelengths in few words: runs of three or more at one step as '340-390 nm
    (10 nm steps)', the others one by one ('405 nm')."""
    pieces = []
    start = 0
    while start < len(wavelengths):
        end = start + 1   # the run is wavelengths[start:end]
        step = wavelengths[end] - wavelengths[start] if end < len(wavelengths) else 0.0
        while end < len(wavelengths) and np.isclose(wavelengths[end] - wavelengths[end - 1],
                                                    step):
            end += 1
        if end - start >= 3:
            pieces.append(f"{wavelengths[start]:g}-{wavelengths[end - 1]:g} nm ({step:g} nm "
                          "steps)")
        else:   # two at one step: the first alone, the second may begin a run
            end = start + 1
            pieces.append(f"{wavelengths[start]:g} nm")
        start = end
    return ", ".join(pieces)


def process_descriptions(result: Result) -> list[str]:
    """Each inelastic process of a run with its settings, as the stored scene has them (with
    the defaults filled in), so that a comparison (e.g. with HydroLight) can check them; the
    parts' names alone where the stored scene cannot be read."""
    import yaml

    from ..config.inelastic import Inelastic
    try:
        inelastic = Inelastic(**yaml.safe_load(result.config_yaml)["water"]["inelastic"])
    except (KeyError, TypeError, ValueError, yaml.YAMLError):
        return [PART_LABELS.get(part, part) for part in light_parts(result)[1:]]
    said = []
    for name, process in inelastic.processes():
        if name == "raman":
            said.append(f"Raman scattering by water (b_R {process.b488_per_m:g} 1/m at 488 nm, "
                        f"as (488/l)^{process.exponent:g})")
        elif name == "chlorophyll_fluorescence":
            low, high = process.excitation_range_nm
            said.append(f"chlorophyll fluorescence (quantum yield {process.quantum_yield:g}, "
                        f"{process.peak_nm:g} nm, sigma {process.sigma_nm:g} nm, excited "
                        f"{low:g}-{high:g} nm)")
        else:
            said.append(PART_LABELS.get(name, name))
    return said


def inelastic_lines(result: Result) -> list[str]:
    """For a run with inelastic light: the processes that were on, the parts every quantity is
    split into, and the wavelengths traced beyond those asked for (attribute
    wavelengths_added_nm), whose own inelastic light lacks what would be excited below the
    traced grid (Raman light at 370 nm comes from 323-335 nm). [] without inelastic light."""
    parts = light_parts(result)
    if not parts:
        return []
    said = [f"inelastic light: {', '.join(process_descriptions(result))}; every quantity but "
            "the ratios is also split into parts that add up to it: "
            f"{', '.join(p + '/' for p in parts)} (e.g. {parts[1]}/air/Rrs_nadir)"]
    if "wavelengths_added_nm" in result.attrs:
        added = np.atleast_1d(np.asarray(result.attrs["wavelengths_added_nm"], dtype=float))
        wavelengths = result.coords["wavelength"]
        if len(added) == 0:
            said.append("traced no wavelength beyond those asked for: they hold the excitation "
                        "of the inelastic light")
        else:
            first = lowest_requested(wavelengths, added)
            below = f", though those below {first:g} nm lack the inelastic light excited " \
                f"below {wavelengths[0]:g} nm" if (added < first).any() else ""
            said.append(f"traced also {wavelength_ranges(np.sort(added))} for the excitation "
                        f"of inelastic light; reported with the rest{below}")
    return [line for text in said
            for line in textwrap.wrap(text, SUMMARY_WIDTH, initial_indent="  ",
                                      subsequent_indent="    ")]


def rrs_parts_table(result: Result) -> list[str]:
    """For a run with inelastic light: Rrs nadir of each part of the light per wavelength, its
    relative standard error and its share of the whole Rrs nadir; [] without inelastic light or
    without Rrs nadir. The elastic part and both processes fit SUMMARY_WIDTH (77 characters)."""
    parts = [part for part in light_parts(result) if f"{part}/air/Rrs_nadir" in result]
    if not parts or "air/Rrs_nadir" not in result:
        return []
    whole = result["air/Rrs_nadir"]
    head = ("Rrs nadir by part of the light: value, relative standard error and share of the "
            f"whole ({', '.join(f'{p}/air/Rrs_nadir' for p in parts)})")
    lines = [""] + textwrap.wrap(head, SUMMARY_WIDTH, initial_indent="  ",
                                 subsequent_indent="  ")
    lines.append(f"  {'nm':>6}" + "".join(f" {PART_LABELS.get(p, p):>15} {'share':>6}"
                                          for p in parts))
    for k, wavelength in enumerate(result.coords["wavelength"]):
        row = f"  {wavelength:>6g}"
        for part in parts:
            value = result[f"{part}/air/Rrs_nadir"][k]
            share = value / whole[k] if whole[k] != 0.0 else 0.0
            row += f" {value_cell(value, result.stderr(f'{part}/air/Rrs_nadir')[k]):>15}" \
                f" {share:>6.1%}"
        lines.append(row)
    return lines


def format_spectrum(result: Result) -> list[str]:
    """A spectral run as a table: one row per wavelength, the headline quantities in columns
    (z1: the first tally depth), each value with its relative standard error in %, in blocks of
    columns no wider than SUMMARY_WIDTH, and with inelastic light Rrs nadir by part of the light;
    then what the Rrs columns are (their estimators), the inelastic processes and the wavelengths
    added for them, and where the light came from."""
    depths = result.coords["depth"]
    first = "0-" if depths[0] == 0.0 else f"{depths[0]:g} m"
    columns = []
    for head, name, index in SPECTRAL_COLUMNS:
        if name in result:
            columns.append((head.replace("z1", first), name, (slice(None), index)))
        if name == "air/Rrs_nadir":
            columns += [(f"Rrs {direction_label(result, k)}", "air/Rrs_local", (slice(None), k))
                        for k in local_directions(result)]
    cells = []   # per column: its cell per wavelength
    for _, name, (_, index) in columns:
        column = []
        for k in range(len(result.coords["wavelength"])):
            value, err = result[name][k], result.stderr(name)[k]
            if index is not None:
                value, err = value[index], err[index]
            column.append(value_cell(value, err))
        cells.append(column)
    # the table is printed in blocks of at most SPECTRAL_BLOCK columns, each after the nm
    # column, so that a line fits a terminal of SUMMARY_WIDTH characters: the quantities at
    # the surface (Ed(0+), the Rrs columns, Eu(0+)) first, then those in the water and the budget
    surface = next(i for i, (_, name, _) in enumerate(columns + [("", "Ed", 0)])
                   if name in ("Ed", "Eu", "Eo") or name.startswith("budget/"))
    blocks = [range(start, min(start + SPECTRAL_BLOCK, end))
              for begin, end in ((0, surface), (surface, len(columns)))
              for start in range(begin, end, SPECTRAL_BLOCK)]
    lines = []
    for b, block in enumerate(blocks):
        if b:
            lines.append("")
        lines.append(f"  {'nm':>6}" + "".join(f" {columns[c][0]:>15}" for c in block))
        lines += [f"  {wavelength:>6g}" + "".join(f" {cells[c][k]:>15}" for c in block)
                  for k, wavelength in enumerate(result.coords["wavelength"])]
    lines += rrs_parts_table(result)
    lines += estimator_lines(result)
    lines += inelastic_lines(result)
    lines += illumination_lines(result)
    lines.append("  (value and relative standard error; irradiances in the units of Ed(0+), "
                 "Rrs in 1/sr,")
    lines.append("  budget fractions of Ed(0+); every quantity per wavelength in the file)")
    return lines


# standard errors from fewer batches than this are themselves too uncertain to trust: from n
# batches the standard error's own relative error is about 1 / sqrt(2 (n - 1)), 38% at 4
RELIABLE_BATCHES = 8


def completeness_line(result: Result) -> str | None:
    """One line on a partial file (N of M batches whole) and on standard errors from fewer than
    RELIABLE_BATCHES batches; None for a complete file of enough batches."""
    a = result.attrs
    done = int(a["batches"])
    if not a.get("partial", False) and done >= RELIABLE_BATCHES:
        return None
    import yaml
    total = None
    try:
        total = int(yaml.safe_load(result.config_yaml)["batches"])
    except (KeyError, TypeError, ValueError, yaml.YAMLError):
        pass
    of = f" of {total}" if total is not None else ""
    head = f"  PARTIAL: {done}{of} batches whole (a stopped run; the estimates use them only)" \
        if a.get("partial", False) else f"  note: {done} batches"
    if done == 0:
        return head + "; no batch is whole yet: the file holds no estimate, only the state to " \
            "resume from"
    if done < RELIABLE_BATCHES:
        return head + f"; standard errors from fewer than {RELIABLE_BATCHES} batches are " \
            "unreliable"
    return head


def format_summary(result: Result) -> str:
    a = result.attrs
    lines = [
        f"{a.get('name', '')}",
        f"  {a['photons']:,} photons in {a['batches']} batches on {a['threads']} thread(s): "
        f"{a['wall_time_s']:.2f} s, {a['photons_per_s']:,.0f} photons/s "
        f"(start-up {a['startup_time_s']:.2f} s)",
    ]
    said = completeness_line(result)
    if said is not None:
        lines.append(said)
    if "wavelength" in result.coords:
        return "\n".join(lines + format_spectrum(result))
    lines.append(f"  {'quantity':<28}{'units':<9}{'value':>13}{'std err':>12}{'rel err':>10}")
    for label, units, value, err in summary_rows(result):
        rel = abs(err / value) if value != 0.0 else 0.0
        lines.append(f"  {label:<28}{units:<9}{value:>13.6g}{err:>12.3g}{rel:>10.2%}")
    return "\n".join(lines)
