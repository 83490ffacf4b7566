"""The tally-grid packer: the angular grid of the radiance tallies, the GRID record and its
pools (kernel/records.py), and the named score arrays of one batch's flat tally row."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import config as cfg
from ..kernel import models
from ..kernel.records import GRID, Pool, record

THETA_LOOKUP_CELLS = 4096


@dataclass(frozen=True)
class Grid:
    """The angular grid of the radiance tallies (deg). Bands touching a pole are polar caps,
    not split in azimuth (HydroLight's quads)."""
    theta_edges: np.ndarray
    phi_edges: np.ndarray
    is_cap: np.ndarray

    @property
    def theta(self) -> np.ndarray:
        return 0.5 * (self.theta_edges[1:] + self.theta_edges[:-1])

    @property
    def phi(self) -> np.ndarray:
        return 0.5 * (self.phi_edges[1:] + self.phi_edges[:-1])

    @property
    def solid_angle(self) -> np.ndarray:
        """(theta, phi) quad solid angles in sr; a cap's full solid angle in every phi column."""
        # cos a - cos b = 2 sin((a + b) / 2) sin((b - a) / 2): no cancelling for narrow bands
        theta = np.radians(self.theta_edges)
        band = np.abs(2.0 * np.sin(0.5 * (theta[1:] + theta[:-1]))
                      * np.sin(0.5 * (theta[1:] - theta[:-1])))
        dphi = np.radians(np.diff(self.phi_edges))
        omega = band[:, None] * dphi[None, :]
        omega[self.is_cap, :] = 2.0 * math.pi * band[self.is_cap, None]
        return omega


def make_grid(tallies: cfg.Tallies) -> Grid:
    edges = np.array(tallies.theta_edges, dtype=np.float64)
    n = tallies.phi_bands
    step = 360.0 / n
    phi_edges = -0.5 * step + step * np.arange(n + 1)
    is_cap = np.zeros(len(edges) - 1, dtype=np.bool_)
    is_cap[0] = True
    is_cap[-1] = True
    return Grid(edges, phi_edges, is_cap)


def mu_edges(theta_edges: np.ndarray) -> np.ndarray:
    mu = np.cos(np.radians(theta_edges))
    mu[theta_edges == 90.0] = 0.0  # exact, so no downward photon lands in an upward band
    return mu


def theta_lookup(mu: np.ndarray) -> np.ndarray:
    """For each of THETA_LOOKUP_CELLS equal cells of uz in [-1, 1], the band (index into the
    falling mu edges) of the cell's top value (see kernel.tally.theta_band_fast)."""
    top = -1.0 + 2.0 * (np.arange(THETA_LOOKUP_CELLS) + 1) / THETA_LOOKUP_CELLS
    top = np.minimum(top, 1.0)
    bands = np.searchsorted(-mu, -top, side="left") - 1
    return np.clip(bands, 0, len(mu) - 2).astype(np.int64)


def stratified_fraction(diffuse_fraction: np.ndarray) -> float:
    """The share of a batch's photons that come from the sky (kernel/transport.py): the mean
    of the wavelengths' diffuse fractions, so that each source is sampled in proportion to its
    mean share of Ed0."""
    return float(np.mean(diffuse_fraction))


def source_shares(diffuse_fraction: np.ndarray) -> np.ndarray:
    """source_q (2, n_wl): each wavelength's weight of a sun (row 0) or sky (row 1) photon
    relative to the weight the stratification gives it, (1 - f_l) / (1 - f) and f_l / f (f:
    stratified_fraction; kernel/spectral.py)."""
    f = stratified_fraction(diffuse_fraction)
    sun = (1.0 - diffuse_fraction) / (1.0 - f) if f < 1.0 else np.ones_like(diffuse_fraction)
    sky = diffuse_fraction / f if f > 0.0 else np.ones_like(diffuse_fraction)
    return np.array([sun, sky])


def pack(config: cfg.SceneConfig, depths: np.ndarray, level_tau: np.ndarray,
         surface_level: int, n_dirs: int, n_layers: int, diffuse: np.ndarray,
         bottom_shares: np.ndarray | None = None
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray, Grid]:
    """(GRID record, float pool, int pool, Grid); diffuse: the illumination's diffuse share
    per wavelength (optics.illumination_spectrum). Tally levels: the depths, then 0+ (all
    light), then 0+ (water-leaving light); n_dirs local-estimate rows; n_layers the medium's
    (a depth profile's sublayers each absorb into a budget column of their own). The row holds
    scores only (the packet's state is the packet's: kernel/packet.py), every score with its
    wavelengths side by side; bottom_shares: (2, n_wl) each wavelength's bottom reflectance
    relative to the packed BRDF's (default 1), row 1 for a lambertian_specular bottom's mirror
    lobe (optics/bottom.py kernel_bottom). The row holds one part of `size` scores per collision
    channel: the elastic light's, then each inelastic process's."""
    grid = make_grid(config.tallies)
    mu = mu_edges(grid.theta_edges)
    n_depths = len(depths)
    n_levels = n_depths + 2
    radiance_on = bool(config.tallies.radiance)
    theta_cols, phi_cols = (len(grid.theta), len(grid.phi)) if radiance_on else (1, 1)
    n_budget = models.BUDGET_LAYERS + n_layers
    n_wl = len(config.wavelengths)
    # the local estimates' scores (wavelength fastest), then the others
    local = 0
    cap = local + (n_depths + 1) * n_dirs * n_wl
    size = shared_size = cap + (n_depths + 1) * n_wl
    layout = {"local": local, "cap": cap}
    for name, length in (("flux", 4 * n_levels), ("radiance", n_levels * theta_cols * phi_cols),
                         ("budget", n_budget)):
        layout[name] = size
        size += length
    # every score with its wavelengths side by side (kernel/tally.py spectral_at): a crossing
    # or a settle adds to all wavelengths of a score at once, a few cache lines instead of one
    # per wavelength
    size = shared_size + n_wl * (size - shared_size)
    source_q = source_shares(diffuse)
    f, i = Pool(np.float64), Pool(np.int64)
    inelastic = config.water.inelastic
    n_parts = 1 + (len(inelastic.processes()) if inelastic is not None else 0)
    rec = record(
        GRID, n_wl=n_wl, n_parts=n_parts, scores=shared_size,
        source_q=f.add(source_q),
        bottom_q=f.add(np.ones(2 * n_wl) if bottom_shares is None
                       else np.ravel(bottom_shares)),
        n_depths=n_depths, air_level=n_depths, surface_level=surface_level,
        mu_cut=float(config.tallies.grazing_mu_cut), radiance_on=int(radiance_on),
        n_theta=len(grid.theta), n_phi=int(config.tallies.phi_bands),
        n_lookup=THETA_LOOKUP_CELLS, theta_cols=theta_cols, phi_cols=phi_cols,
        theta_mu_edges=f.add(mu), phi_edge_cos=f.add(np.cos(np.radians(grid.phi_edges[:-1]))),
        phi_edge_sin=f.add(np.sin(np.radians(grid.phi_edges[:-1]))),
        level_z=f.add(depths), level_tau=f.add(level_tau.T),
        theta_lookup=i.add(theta_lookup(mu)), theta_is_cap=i.add(grid.is_cap),
        n_dirs=n_dirs, n_budget=n_budget, part_size=size, **layout)
    return rec, f.array(), i.array(), grid


def tally_arrays(grid_record: np.ndarray, tallies: np.ndarray) -> dict[str, np.ndarray]:
    """The scores of the per-batch tally rows (batch, n_parts x size) as named views into
    them, batch axis first and wavelength axis last: flux (level, 4, wl), radiance (level,
    theta, phi, wl), local (level, direction, wl), cap (level, wl), budget (n_budget, wl); the
    elastic light's under these names, part k's (light inelastic channel k emitted) under
    `part{k}/` these names. Only the GRID record's score offsets are read: what else the row
    holds, and where, is the kernel's business. Writing into the views writes the rows
    (write_tally_arrays)."""
    g = grid_record[0]
    nb = tallies.shape[0]
    n_levels = int(g["n_depths"]) + 2
    n_wl = int(g["n_wl"])
    scores = int(g["scores"])
    size = int(g["part_size"])
    out = {}
    for k in range(int(g["n_parts"])):
        prefix = f"part{k}/" if k else ""

        def part(at, shape):
            """The score array at row offset `at` of part k, its wavelengths side by side."""
            length = int(np.prod(shape)) * n_wl
            at += k * size
            # a slice of each row split into axes: a view (numpy reshapes a contiguous axis
            # without copying), so that reading it later sees what the kernel has added since
            return tallies[:, at:at + length].reshape((nb,) + shape + (n_wl,))

        def spectral(name, shape):
            """A score of the per-wavelength layout: GRID gives one wavelength's offset
            (kernel/tally.py spectral_at)."""
            return part(scores + (int(g[name]) - scores) * n_wl, shape)

        out.update({
            prefix + "flux": spectral("flux", (n_levels, 4)),
            prefix + "radiance": spectral("radiance", (n_levels, int(g["theta_cols"]),
                                                       int(g["phi_cols"]))),
            prefix + "local": part(int(g["local"]), (n_levels - 1, int(g["n_dirs"]))),
            prefix + "cap": part(int(g["cap"]), (n_levels - 1,)),
            prefix + "budget": spectral("budget", (int(g["n_budget"]),))})
    return out


def write_tally_arrays(grid_record: np.ndarray, arrays: dict[str, np.ndarray],
                       tallies: np.ndarray) -> None:
    """The inverse of tally_arrays: writes the named score arrays (each with the batch axis
    first and the wavelength axis last) into the rows `tallies` (batch, size). Raises
    ValueError when their names or shapes are not those of this grid."""
    views = tally_arrays(grid_record, tallies)
    if set(arrays) != set(views):
        raise ValueError(f"the tally holds {sorted(arrays)}, this scene's {sorted(views)}")
    for name, view in views.items():
        if np.shape(arrays[name]) != view.shape:
            raise ValueError(f"tally {name} is {np.shape(arrays[name])}, this scene's "
                             f"{view.shape} (batch, ..., wavelength)")
    for name, view in views.items():
        view[...] = arrays[name]


def tally_views(grid_record: np.ndarray, tallies: np.ndarray,
                wavelength: int = 0) -> dict[str, np.ndarray]:
    """The named score arrays of tally_arrays at wavelength index `wavelength` (views into the
    rows)."""
    return {name: values[..., wavelength]
            for name, values in tally_arrays(grid_record, tallies).items()}
