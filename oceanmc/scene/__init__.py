"""Config -> the kernel's records and pools: one packer per component (medium, surface, bottom,
sky, tally grid, local estimates), each producing its record (kernel/records.py) and pools of its
own, which build() merges into the scene's one float pool and one int pool. No Python object
crosses into the kernel."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import config as cfg
from .. import optics, registry
from ..kernel import models
from ..kernel.records import ESTIMATOR, SPLIT_STACK_ROWS, merge, record
from ..kernel.variants import CLOSED_FORM_BOTTOMS, Variant
from . import bottom, estimates, grid, medium, sky, surface, weight_window
from .grid import Grid, make_grid  # noqa: F401  (the run and the tests use them from here)


@dataclass(frozen=True)
class Scene:
    """The packed scene: records (one-row arrays of the kernel/records.py dtypes) and the two
    pools, in the order the photon loop takes them (kernel_args), the angular grid, and for
    each requested local direction its (water row, air row)."""
    medium: np.ndarray
    surface: np.ndarray
    bottom: np.ndarray
    sky: np.ndarray
    grid: np.ndarray
    estimates: np.ndarray
    estimator: np.ndarray
    floats: np.ndarray
    ints: np.ndarray
    angles: Grid
    local_rows: list
    layers: tuple               # optics.LayerIOPs of each kernel layer
    # (n_wl,) the bottom's reflectance at each wavelength (optics/bottom.py; a mixture's
    # fraction-weighted), None for a bottom without one (black, ggx, hapke, table, ...)
    bottom_reflectance: np.ndarray | None = None
    # estimator.depth_splitting as decided for the scene, and why (weight_window.choose)
    depth_splitting: str = "off"
    # the upward bias it runs with, 0 for none (weight_window.upward_fraction)
    upward_fraction: float = 0.0

    def kernel_args(self) -> tuple:
        return (self.medium, self.surface, self.bottom, self.sky, self.grid, self.estimates,
                self.estimator, self.floats, self.ints)

    @property
    def tally_size(self) -> int:
        """Floats of one batch's tally row: n_parts parts of `size` (records.py GRID)."""
        return int(self.grid[0]["part_size"]) * int(self.grid[0]["n_parts"])

    @property
    def stack_rows(self) -> int:
        """Rows of the stack that split copies and emitted packets wait on (one, unused,
        without either)."""
        ctrl = self.estimator[0]
        uses = ctrl["splitting"] or ctrl["depth_windows"] or self.medium[0]["n_channels"] > 1
        return SPLIT_STACK_ROWS if uses else 1

    @property
    def variant(self) -> Variant:
        """The optional parts of the photon loop that this scene's records may run
        (kernel/variants.py): trace it only on a variant that holds them."""
        g, est, bottom = self.grid[0], self.estimates[0], self.bottom[0]
        inelastic = bool(self.medium[0]["n_channels"] > 1 or g["n_parts"] > 1)
        rough = not self.surface[0]["delta"]
        reflects = bool(bottom["reflects"])
        # (the kernel settles inelastic light through the spectral walk's functions: a scene
        # with inelastic light uses both parts, whatever its number of wavelengths)
        return Variant(spectral=bool(g["n_wl"] > 1) or inelastic, inelastic=inelastic,
                       rough_surface=rough,
                       facet_walk=rough and not self.surface[0]["tabulated"],
                       reflecting_bottom=reflects,
                       detailed_bottom=reflects and (
                           int(bottom["model"]) not in CLOSED_FORM_BOTTOMS
                           or bool(self.floats[bottom["params"] + models.BRDF_SAMPLER] > 0.0)),
                       local_estimates=bool(est["directions_on"] or est["cap_on"]),
                       exact_directions=bool(est["directions_on"]))


def predicted_variant(config: cfg.SceneConfig) -> Variant:
    """The optional parts of the photon loop that the scene will use, from its config alone:
    the loop is compiled before (or while) the scenes are packed. Only a prediction: the run
    checks it against the packed scene's own (Scene.variant), and a part it missed costs a
    second compilation, never a wrong result."""
    asked = config.water.inelastic
    inelastic = asked is not None and bool(asked.processes())
    sea = surface.pack(config.surface, config.n_water)[0]
    bottom = config.bottom
    # (a mixture is packed as the Lambertian or Minnaert bottom of its shape: optics/bottom.py)
    shape = bottom.components[0].model if bottom.model == "mixture" else bottom.model
    reflects = shape not in ("none", "black")
    return Variant(spectral=len(config.wavelengths) > 1 or inelastic, inelastic=inelastic,
                   rough_surface=not sea["delta"],
                   facet_walk=not sea["delta"] and not sea["tabulated"],
                   reflecting_bottom=reflects,
                   detailed_bottom=reflects and (
                       registry.bottom_id(shape) not in CLOSED_FORM_BOTTOMS
                       or getattr(bottom, "sampling", "auto") == "tabulated"),
                   local_estimates=bool(config.tallies.local_directions_deg)
                   or config.nadir_local,
                   exact_directions=bool(config.tallies.local_directions_deg))


def pack_estimator(est: cfg.Estimator, column: medium.Column) -> np.ndarray:
    """The ESTIMATOR records, one per segment of the column: under depth windows each holds its
    segment's window weight W and the roulette threshold at collisions there, max(roulette_weight,
    weight_window.ROULETTE_WEIGHT) x W (scene/weight_window.py)."""
    upward = medium.upward_fractions(column.upward, column.albedo)
    rows = np.repeat(record(ESTIMATOR, analog=int(est.mode == "analog"),
                            roulette_weight=float(est.roulette_weight),
                            roulette_survival=float(est.roulette_survival),
                            max_events=int(est.max_events),
                            split_weight=float(est.split_weight or np.inf),
                            splitting=int(est.split_weight is not None),
                            upward=int(upward.max(initial=0.0) > 0.0),
                            emission_weight=float(est.emission_weight),
                            carry_emissions=int(est.emitted_light == "carried"),
                            depth_windows=int(column.windows.on), window=1.0),
                     len(column.window))
    if column.windows.on:
        rows["window"] = column.window
        rows["roulette_weight"] = max(est.roulette_weight, weight_window.ROULETTE_WEIGHT) * \
            column.window
    return rows


def build(config: cfg.SceneConfig,
          illumination: tuple[np.ndarray, np.ndarray] | None = None) -> Scene:
    """The kernel's view of a validated scene; illumination: its (Ed0, diffuse fraction) per
    wavelength (optics.illumination_spectrum), computed here if not given. Raises TableError
    (a ConfigError) for unusable auxiliary files."""
    ed0, diffuse = illumination if illumination is not None else \
        optics.illumination_spectrum(config)[:2]
    med, mf, mi, column = medium.pack(config, ed0)
    surf = surface.pack(config.surface, config.n_water)
    bot, bp, bottom_shares = bottom.pack(config.bottom, config.wavelengths)
    sk, sf = sky.pack(optics.monochromatic_illumination(config, (ed0, diffuse)))
    # the sky's share of the photons: the wavelengths' mean diffuse fraction (grid.source_q
    # gives each wavelength its own)
    sk[0]["diffuse_fraction"] = grid.stratified_fraction(diffuse)
    *directions, local_rows = estimates.local_directions(config, surf)
    gr, gf, gi, angles = grid.pack(config, column.depths, column.level_tau, column.surface_level,
                                   len(directions[0]), len(column.albedo), diffuse,
                                   bottom_shares)
    est, ef, ei = estimates.pack(config, med, mf, mi, surf, column, angles, tuple(directions))
    no_ints = np.zeros(0, dtype=np.int64)
    (med, bot, sk, gr, est, surf), floats, ints = merge(
        [(med, mf, mi), (bot, bp, no_ints), (sk, sf, no_ints), (gr, gf, gi), (est, ef, ei),
         (surf, surface.pool(config.surface, surf), no_ints)])
    return Scene(med, surf, bot, sk, gr, est, pack_estimator(config.estimator, column),
                 floats, ints, angles, local_rows, column.layers,
                 optics.bottom_spectrum(config.bottom, config.wavelengths), column.windows.why,
                 float(column.upward or 0.0))


__all__ = ["Scene", "Grid", "build", "make_grid", "predicted_variant"]
