"""Derivation: a run's tallies -> the quantities of its Result. The kernel's per-batch weight
sums, per wavelength and per part of the light (scene/grid.py tally_views), are normalised per
launched photon and Ed(0+) (radiances also per quad solid angle) into the contract's quantities,
each part of the light beside the whole, the wavelengths stacked. (derived.py then computes the
apparent optical properties from a Result.)"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..kernel import models
from .result import Quantity, Result, common_quantities

if TYPE_CHECKING:   # the scene's packers (0.5 s to import) stay out of `oceanmc show`
    from ..config import SceneConfig
    from ..scene import Grid, Scene


@dataclass(frozen=True)
class RunFacts:
    """What the derivation needs to know of a run, fixed for the whole run (of(): once)."""
    grid: Grid                  # the angular grid: quads' solid angles, polar caps, band edges
    depths: np.ndarray          # the tally depths (m)
    photons_per_batch: int
    n_layers: int               # configured water layers: the budget's absorbed_layer_N terms
    config_layer: np.ndarray    # the configured layer of each kernel layer (a depth profile
    #                             resolves one into several)
    radiance: bool              # tallies.radiance: the (theta, phi) quads are tallied
    directions: list            # local_directions_deg: (theta, phi) of the exact directions
    local_rows: list            # each direction's (water row, air row) in the tally `local`
    nadir_local: bool           # the nadir cap's local estimate gives Lu, Lw_nadir, Rrs_nadir
    parts: tuple[str, ...]      # the parts of the tally row: elastic, then each inelastic process
    wavelengths: np.ndarray     # (n_wl,) nm
    ed0: np.ndarray             # (n_wl,) Ed(0+) at each wavelength (the illumination spectrum)
    diffuse: np.ndarray         # (n_wl,) the sky's share of it
    sky_quads: np.ndarray | None  # (theta, phi) a unit sky's radiance over each downward quad
    #                               (scene.surface.sky_quad_radiance); None without radiance
    units: tuple[str, str]      # (irradiance, radiance) units (UNITS_BY_SPECTRUM)

    @classmethod
    def of(cls, config: SceneConfig, sc: Scene, ed0: np.ndarray,
           diffuse: np.ndarray) -> RunFacts:
        """The facts of a validated scene, its packed form and its illumination spectrum
        (optics.illumination_spectrum's Ed0 and diffuse share)."""
        from ..scene.surface import sky_quad_radiance
        light = config.illumination
        inelastic = config.water.inelastic
        grid = sc.angles
        return cls(
            grid=grid, depths=np.array(config.tallies.depths_m),
            photons_per_batch=math.ceil(config.photons / config.batches),
            n_layers=len(config.water.layers),
            config_layer=np.array([layer.config_layer for layer in sc.layers], dtype=np.int64),
            radiance=config.tallies.radiance, directions=config.tallies.local_directions_deg,
            local_rows=sc.local_rows, nadir_local=config.nadir_local,
            parts=("elastic",) + (tuple(name for name, _ in inelastic.processes())
                                  if inelastic is not None else ()),
            wavelengths=config.wavelengths, ed0=ed0, diffuse=diffuse,
            sky_quads=sky_quad_radiance(light, grid.theta_edges, grid.phi_edges, grid.is_cap)
            if config.tallies.radiance else None,
            units=UNITS_BY_SPECTRUM[light.spectrum.model])

    @property
    def inelastic(self) -> bool:
        """The run has inelastic light: its quantities are split into parts, its budget has the
        processes' terms."""
        return len(self.parts) > 1


def run_result(views: list[dict[str, np.ndarray]], done: int, facts: RunFacts, attrs: dict,
               reflected: list[np.ndarray] | None) -> Result:
    """The Result of a run's leading `done` whole batches from its tally views (one per
    wavelength): each wavelength's parts of the light (part<i>/ in the view, the elastic
    light's unprefixed) and their sum, the whole, derived by from_tallies and, with inelastic
    light, the parts added beside the whole (add_parts); one wavelength keeps the
    monochromatic layout (no wavelength dimension). reflected: per wavelength, the
    surface-reflected radiances of the exact directions (scene.surface.reflected_at), or None."""
    per_wavelength = []
    for k, view in enumerate(views):
        parts = [{name.removeprefix(f"part{i}/"): values[:done]
                  for name, values in view.items()
                  if (name.startswith(f"part{i}/") if i else "/" not in name)}
                 for i in range(len(facts.parts))]
        for part in parts:
            part["budget"] = per_config_layer(part["budget"], facts.config_layer, facts.n_layers)
        whole = {name: sum(part[name] for part in parts) for name in parts[0]}
        if reflected is not None:
            parts[0]["reflected_local"] = whole["reflected_local"] = reflected[k]
        result = from_tallies(whole, facts, k, attrs)
        if facts.inelastic:
            add_parts(result, {name: from_tallies(part, facts, k, attrs)
                               for name, part in zip(facts.parts, parts)})
        per_wavelength.append(result)
    return per_wavelength[0] if len(views) == 1 else \
        stack_wavelengths(per_wavelength, facts.wavelengths)


def per_config_layer(budget: np.ndarray, config_layer: np.ndarray, n_layers: int) -> np.ndarray:
    """The budget with the absorption of the sublayers of a depth profile summed into the
    configured layer they resolve."""
    if len(config_layer) == n_layers:
        return budget
    out = np.zeros(budget.shape[:-1] + (models.BUDGET_LAYERS + n_layers,))
    out[..., :models.BUDGET_LAYERS] = budget[..., :models.BUDGET_LAYERS]
    np.add.at(out.T, models.BUDGET_LAYERS + config_layer, budget[..., models.BUDGET_LAYERS:].T)
    return out


# (irradiance, radiance) units by illumination.spectrum model: a flat spectrum's Ed0 is Ed(0+)
# itself, SPECTRL2 gives W m-2 nm-1 times Ed0 (a flat spectrum's units were written for it too
# until 2026-11-29: a user's review), a table its own Ed0 column's units
UNITS_BY_SPECTRUM = {
    "flat": ("W m-2 (per unit Ed0)", "W m-2 sr-1 (per unit Ed0)"),
    "spectrl2": ("W m-2 nm-1 (SPECTRL2 times Ed0)", "W m-2 nm-1 sr-1 (SPECTRL2 times Ed0)"),
    "table": ("the units of the spectrum table's Ed0",
              "the units of the spectrum table's Ed0, per sr"),
}


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


class Quantities(dict):
    """The quantities of a Result as from_tallies derives them, by name, in the order added."""

    def add(self, name: str, dims: tuple[str, ...], values: np.ndarray, units: str,
            description: str) -> None:
        self[name] = Quantity(name, dims, np.ascontiguousarray(values, dtype=np.float64), units,
                              description)


LU_CROSSING = "polar-cap quad average (theta 175-180 deg with HydroLight edges), crossing " \
              "estimator"
LU_LOCAL = "polar-cap quad average (theta 175-180 deg with HydroLight edges), local " \
           "(next-event) estimate; the crossing estimates of the same averages are " \
           "Lu_crossing, air/Lw_nadir_crossing, air/Rrs_nadir_crossing"


def from_tallies(raw: dict[str, np.ndarray], facts: RunFacts, wavelength: int,
                 attrs: dict) -> Result:
    """Normalises the raw per-batch weight sums of wavelength index `wavelength` (per launched
    photon, times its Ed(0+); radiances also per quad solid angle) and derives the contract's
    quantities:
    the irradiances, the radiances on the quads (facts.radiance), Lu, Lw_nadir and Rrs_nadir
    from the local polar-cap estimate in raw["cap"] (facts.nadir_local), the exact directions'
    local estimates in raw["local"] and their surface-reflected radiance in
    raw["reflected_local"], and the budget. attrs: the run's, with Lu_method added."""
    ed0 = float(facts.ed0[wavelength])
    scale = ed0 / facts.photons_per_batch
    q = Quantities()
    irradiance_units, radiance_units = facts.units
    add_irradiances(q, raw["flux"], facts.depths, scale, irradiance_units)
    if facts.radiance:
        # the sun's direct Ed(0+) at this wavelength (a spectrum's own diffuse share)
        direct = ed0 * (1.0 - float(facts.diffuse[wavelength]))
        add_radiances(q, raw["radiance"], facts, scale, ed0, direct)
    if facts.nadir_local:
        add_nadir_local(q, raw["cap"] * scale, len(facts.depths), ed0, radiance_units)
    if len(facts.directions):
        add_exact_directions(q, raw["local"] * scale, facts, ed0)
    if "reflected_local" in raw:
        add_reflected_local(q, raw["reflected_local"], radiance_units)
    add_budget(q, raw["budget"] / facts.photons_per_batch, facts)
    grid = facts.grid
    coords = {
        "depth": np.asarray(facts.depths, dtype=np.float64),
        "theta": grid.theta, "phi": grid.phi,
        "theta_edges": grid.theta_edges, "phi_edges": grid.phi_edges,
        "direction": np.arange(len(facts.directions)),
        "direction_theta": np.array([d[0] for d in facts.directions], dtype=np.float64),
        "direction_phi": np.array([d[1] for d in facts.directions], dtype=np.float64),
    }
    attrs = dict(attrs)
    attrs["Lu_method"] = LU_LOCAL if facts.nadir_local else LU_CROSSING
    return Result(coords, dict(q), attrs)


def add_irradiances(q: Quantities, raw_flux: np.ndarray, depths: np.ndarray,
                    scale: float, units: str) -> None:
    """The plane and scalar irradiances at the tally depths and at 0+ (all light, and the
    water-leaving light alone; the surface's upward transmittance, their ratio, is derived from
    the batch means: run/derived.py t_up)."""
    n_depths = len(depths)
    flux = raw_flux[:, :n_depths] * scale
    q.add("Ed", ("depth",), flux[:, :, models.FLUX_ED], units, "downward plane irradiance")
    q.add("Eu", ("depth",), flux[:, :, models.FLUX_EU], units, "upward plane irradiance")
    q.add("Eod", ("depth",), flux[:, :, models.FLUX_EOD], units,
          "downward scalar irradiance")
    q.add("Eou", ("depth",), flux[:, :, models.FLUX_EOU], units, "upward scalar irradiance")
    q.add("Eo", ("depth",), flux[:, :, models.FLUX_EOD] + flux[:, :, models.FLUX_EOU],
          units, "scalar irradiance Eod + Eou")
    air = raw_flux[:, n_depths] * scale
    leaving = raw_flux[:, n_depths + 1] * scale
    q.add("air/Ed", (), air[:, models.FLUX_ED], units,
          "downward plane irradiance just above the surface (0+): sun and sky")
    q.add("air/Eu", (), air[:, models.FLUX_EU], units,
          "upward plane irradiance at 0+: surface-reflected plus water-leaving")
    q.add("air/Eod", (), air[:, models.FLUX_EOD], units, "downward scalar irradiance at 0+")
    q.add("air/Eou", (), air[:, models.FLUX_EOU], units, "upward scalar irradiance at 0+")
    q.add("air/Eu_water_leaving", (), leaving[:, models.FLUX_EU], units,
          "upward plane irradiance at 0+ from light transmitted out of the water only")


def add_radiances(q: Quantities, raw_radiance: np.ndarray, facts: RunFacts, scale: float,
                  ed0: float, direct: float) -> None:
    """The radiance on the (theta, phi) quads at the tally depths and at 0+ (all light, the
    water-leaving light, the surface-reflected light and its reflectance factor rho, whose sky
    has the irradiance Ed(0+) less the sun's direct `direct` at this wavelength), and the nadir
    quantities from their polar cap (crossing estimates)."""
    grid, n_depths = facts.grid, len(facts.depths)
    units = facts.units[1]
    omega = grid.solid_angle
    rad = raw_radiance * scale / omega
    rad[..., grid.is_cap, :] = rad[..., grid.is_cap, :1]  # a cap's one value in every phi column
    water_rad = rad[:, :n_depths]
    air_rad = rad[:, n_depths]
    lw = rad[:, n_depths + 1]
    q.add("radiance", ("depth", "theta", "phi"), water_rad, units,
          "radiance on the (theta, phi) quads, quad average; theta from nadir of the direction "
          "of travel, phi from the sun's travel azimuth")
    q.add("Lu", ("depth",), water_rad[:, :, -1, 0], units,
          "nadir-viewing radiance (upward travel), the polar-cap quad average")
    q.add("air/radiance", ("theta", "phi"), air_rad, units,
          "radiance at 0+, all light: sun, sky, surface reflection, water-leaving")
    q.add("air/Lw", ("theta", "phi"), lw, units,
          "water-leaving radiance at 0+ (surface-reflected light excluded); upward quads only")
    upward = (grid.theta > 90.0)[:, None]
    reflected = np.where(upward, air_rad - lw, 0.0)
    q.add("air/L_reflected", ("theta", "phi"), reflected, units,
          "surface-reflected sun and sky radiance at 0+ (all light minus water-leaving); "
          "upward quads only")
    # the mirror of upward quad (theta, phi) is the downward quad (180 - theta, phi)
    if np.allclose(grid.theta_edges, 180.0 - grid.theta_edges[::-1]):
        # the sky's own radiance over the mirror quad (its irradiance Ed0 f): exact, so each
        # batch's rho is its L_reflected over a constant, and the mean over batches is
        # unbiased. (The run's own estimate of it made each batch's rho a ratio of two
        # estimates, 0 where a batch put no sky photon in the mirror quad: 0.0073 +- 0.0018
        # for a flat surface's Fresnel 0.0211 at nadir with 10^4 photons; a user's review,
        # 2026-11-29)
        sky_down = np.broadcast_to((ed0 - direct) * facts.sky_quads[::-1], air_rad.shape)
        lit = upward & (sky_down > 1e-12 * ed0)
        rho = np.where(lit, reflected / np.where(lit, sky_down, 1.0), 0.0)
        q.add("air/rho", ("theta", "phi"), rho, "1",
              "sea-surface reflectance factor L_reflected / L_sky per batch, L_sky the sky's "
              "radiance (sun excluded) averaged over the quad a flat surface reflects into this "
              "one; upward quads, 0 where there is no sky light")
    q.add("air/Lu", (), air_rad[:, -1, 0], units,
          "nadir-viewing radiance at 0+ (water-leaving plus surface-reflected), polar cap")
    q.add("air/Lw_nadir", (), lw[:, -1, 0], units,
          "nadir water-leaving radiance at 0+, polar-cap quad average")
    q.add("air/Rrs_nadir", (), lw[:, -1, 0] / ed0, "sr-1",
          "remote-sensing reflectance Lw_nadir / Ed(0+)")


def add_nadir_local(q: Quantities, cap: np.ndarray, n_depths: int, ed0: float,
                    units: str) -> None:
    """Lu, Lw_nadir and Rrs_nadir from the polar cap's local estimate (normalised `cap`); the
    crossing estimates of the quads, where tallied, stay beside them as *_crossing."""
    for name in ("Lu", "air/Lw_nadir", "air/Rrs_nadir"):
        if name in q:  # the crossing estimate of the same cap average, for comparison
            crossing = q.pop(name)
            crossing.name = name + "_crossing"
            crossing.description += " (crossing estimator)"
            q[crossing.name] = crossing
    q.add("Lu", ("depth",), cap[:, :n_depths], units,
          "nadir-viewing radiance (upward travel), the polar-cap quad average, local estimate")
    q.add("air/Lw_nadir", (), cap[:, n_depths], units,
          "nadir water-leaving radiance at 0+, polar-cap quad average, local estimate")
    q.add("air/Rrs_nadir", (), cap[:, n_depths] / ed0, "sr-1",
          "remote-sensing reflectance Lw_nadir / Ed(0+)")


def add_exact_directions(q: Quantities, local: np.ndarray, facts: RunFacts, ed0: float) -> None:
    """The radiances of the exact directions of local_directions_deg (normalised `local`) at
    the tally depths and leaving the water, and their Rrs."""
    n_depths = len(facts.depths)
    units = facts.units[1]
    water_rows = [w for w, _ in facts.local_rows]
    air_rows = [a for _, a in facts.local_rows]
    q.add("local_radiance", ("depth", "direction"), local[:, :n_depths][:, :, water_rows],
          units, "radiance in the exact directions of local_directions_deg (theta, phi "
          "of travel), local (next-event) estimate")
    q.add("air/Lw_local", ("direction",), local[:, n_depths][:, air_rows], units,
          "water-leaving radiance at 0+ in the exact directions of local_directions_deg, "
          "local (next-event) estimate")
    q.add("air/Rrs_local", ("direction",), local[:, n_depths][:, air_rows] / ed0, "sr-1",
          "Lw_local / Ed(0+)")


def add_reflected_local(q: Quantities, reflected_local: np.ndarray, units: str) -> None:
    """The surface-reflected radiance of the exact directions and its reflectance factor
    rho_local, from per batch (L_reflected, L_sky of the mirror direction)."""
    reflected, l_sky = reflected_local[..., 0], reflected_local[..., 1]
    q.add("air/L_reflected_local", ("direction",), reflected, units,
          "surface-reflected sky and sun radiance at 0+ in the exact directions of "
          "local_directions_deg (sky: surface samples; sun: single-reflection glint)")
    if np.all(l_sky > 0.0):   # no sky, no rho
        q.add("air/rho_local", ("direction",), reflected / l_sky, "1",
              "sea-surface reflectance factor L_reflected_local / L_sky, L_sky the sky "
              "radiance (sun excluded) in the direction a flat surface reflects into the view")


def add_budget(q: Quantities, budget: np.ndarray, facts: RunFacts) -> None:
    """The budget's terms (budget_terms; per launched photon in `budget`) and their total."""
    terms = budget_terms(facts.n_layers, facts.inelastic)
    for column, name, description in terms:
        q.add(f"budget/{name}", (), budget[:, column], "1", description)
    # the kernel's columns for inelastic transfers (kernel/channels/) stay 0 without an
    # inelastic process, and are left out; what a process gives counts negative
    columns = sorted(column for column, _, _ in terms)
    signed = budget[:, columns] * np.where(np.array(columns) == models.BUDGET_SHIFTED_IN,
                                           -1.0, 1.0)
    q.add("budget/total", (), signed.sum(axis=1),
          "1", "sum of all budget terms: 1 up to Russian-roulette noise (an inelastic "
          "process's part: 0)")


# what is not split into the parts of the light (add_parts): ratios, not sums over photons
NOT_SPLIT = frozenset({"air/rho", "air/rho_local"})


def add_parts(whole: Result, parts: dict[str, Result]) -> None:
    """Adds to `whole` every quantity of each part of the light (elastic, raman,
    chlorophyll_fluorescence, cdom_fluorescence: the parts of the tally row, kernel/channels/)
    under the part's name: raman/air/Rrs_nadir is the Raman light's Rrs, and the parts of a
    quantity add up to it batch by batch, so each part has its own standard error. Ratios are
    not split (NOT_SPLIT)."""
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
    "cdom_fluorescence": "the light CDOM fluoresced",
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


