"""The air-water surface packer: the SURFACE record (kernel/records.py) and its float pool (the
rough surface's table, scene/surface_table.py)."""
from __future__ import annotations

import functools
import math
import os

import numpy as np

from .. import config as cfg
from .. import registry
from ..kernel.records import SURFACE, record
from . import sky_maps, surface_table


def pack(surface: cfg.Surface, n_water: float) -> np.ndarray:
    """The SURFACE record; a tabulated rough surface's table is at offset 0 of pool()'s."""
    if surface.model != "cox_munk":
        return record(SURFACE, model=registry.surface_id(surface.model), n_water=float(n_water),
                      schlick=int(surface.fresnel == "schlick"), delta=1, alpha_u=0.0,
                      alpha_c=0.0, wind_cos=1.0, wind_sin=0.0, tabulated=0, table=0)
    upwind, crosswind = surface.slope_variances()
    azimuth = math.radians(surface.wind_direction_deg or 0.0)
    # Beckmann's alpha^2 is twice a slope component's variance (p ~ exp(-z^2 / alpha^2))
    return record(SURFACE, model=registry.surface_id(surface.model), n_water=float(n_water),
                  schlick=0, delta=0, alpha_u=math.sqrt(2.0 * upwind),
                  alpha_c=math.sqrt(2.0 * crosswind), wind_cos=math.cos(azimuth),
                  wind_sin=math.sin(azimuth), tabulated=int(surface.tabulated()), table=0)


def pool(surface: cfg.Surface, packed: np.ndarray) -> np.ndarray:
    """The record's float pool: the table of a tabulated rough surface (from the disk cache,
    or built), else empty."""
    if not packed[0]["tabulated"]:
        return np.zeros(0)
    return surface_table.table(float(packed[0]["alpha_u"]), float(packed[0]["n_water"]))


# walks per batch and view direction for the reflected-radiance estimates (a few ms each)
REFLECTED_SAMPLES = 4000


def _sky_map(sky: cfg.SkyMap) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A sky map's cells (the run's packing has read and checked the file), read once while
    the file stays the same: sky_radiance reads them for every batch of the reflected-radiance
    estimates."""
    stat = os.stat(sky.map)
    return _read_sky_map(sky.map, sky.dataset, sky.layout, stat.st_mtime_ns, stat.st_size)


@functools.lru_cache(maxsize=4)
def _read_sky_map(path: str, dataset: str, layout: str, mtime_ns: int, size: int
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return sky_maps.read_sky_map(path, dataset, layout)


def sky_radiance(ill: cfg.Illumination, dirs: np.ndarray, e_sky: float = 1.0) -> np.ndarray:
    """The radiance (sun excluded) of a sky of irradiance e_sky arriving in directions of
    travel dirs (downward): uniform E_sky / pi; cardioidal (overcast) E_sky 3 (1 + 2 cos) /
    (7 pi); Harrison-Coombes and a map normalised so that integral L cos = E_sky (a map: each
    direction's cell, sky_maps.map_radiance)."""
    if isinstance(ill.sky, cfg.SkyMap):
        return e_sky * sky_maps.map_radiance(*_sky_map(ill.sky), dirs)
    if ill.sky == "uniform":
        return np.full(len(dirs), e_sky / math.pi)
    if ill.sky in ("cardioidal", "overcast"):
        return e_sky * 3.0 * (1.0 + 2.0 * dirs[:, 2]) / (7.0 * math.pi)
    # harrison_coombes
    sun = sky_maps.sun_travel(ill.sun_zenith_deg)
    cos_sun = max(sun[2], 1e-6)
    # (numpy's own sum, not BLAS's, whose result depends on its threads: inelastic transfer)
    return e_sky / _harrison_coombes_irradiance(ill.sun_zenith_deg) * sky_maps.harrison_coombes(
        dirs[:, 2], np.einsum("dk,k->d", dirs, sun), cos_sun)


@functools.lru_cache(maxsize=8)
def _harrison_coombes_irradiance(sun_zenith_deg: float) -> float:
    """integral L cos dOmega of the Harrison-Coombes sky in its relative units (midpoint rule,
    400 x 720 cells), once per sun: sky_radiance runs for every batch of the reflected-radiance
    estimates."""
    sun = sky_maps.sun_travel(sun_zenith_deg)
    cos_sun = max(sun[2], 1e-6)
    mu = (np.arange(400) + 0.5) / 400
    phi = (np.arange(720) + 0.5) * (2.0 * math.pi / 720)
    s = np.sqrt(1.0 - mu * mu)[:, None]
    cos_psi = s * np.cos(phi)[None, :] * sun[0] + mu[:, None] * sun[2]
    return float((sky_maps.harrison_coombes(mu[:, None], cos_psi, cos_sun) * mu[:, None]).sum()
                 * (1.0 / 400) * (2.0 * math.pi / 720))


# directions per quad, along mu and along phi, over which sky_quad_radiance averages a sky
QUAD_SAMPLES = 24


def sky_quad_radiance(ill: cfg.Illumination, theta_edges: np.ndarray, phi_edges: np.ndarray,
                      is_cap: np.ndarray) -> np.ndarray:
    """(theta, phi): the radiance of a sky of unit irradiance (sun excluded) averaged over each
    quad of the tally grid whose light travels down (theta < 90 deg from nadir), 0 elsewhere
    (a polar cap's average in every phi column): air/rho's denominator for the mirror quads,
    exact up to the midpoint rule on QUAD_SAMPLES^2 directions evenly spread in solid angle
    (a map's cells are read at each of them: sky_radiance)."""
    n_theta, n_phi = len(theta_edges) - 1, len(phi_edges) - 1
    out = np.zeros((n_theta, n_phi))
    steps = (np.arange(QUAD_SAMPLES) + 0.5) / QUAD_SAMPLES
    quads, dirs = [], []
    for i in range(n_theta):
        if theta_edges[i + 1] > 90.0:
            continue
        mu_top, mu_bottom = np.cos(np.radians(theta_edges[i:i + 2]))
        mu = mu_bottom + steps * (mu_top - mu_bottom)
        sin_t = np.sqrt(1.0 - mu * mu)
        for j in range(1 if is_cap[i] else n_phi):
            low, high = (-180.0, 180.0) if is_cap[i] else phi_edges[j:j + 2]
            phi = np.radians(low + steps * (high - low))
            quads.append((i, j))
            dirs.append(np.stack([(sin_t[:, None] * np.cos(phi)[None, :]).ravel(),
                                  (sin_t[:, None] * np.sin(phi)[None, :]).ravel(),
                                  np.repeat(mu, QUAD_SAMPLES)], axis=1))
    radiance = sky_radiance(ill, np.concatenate(dirs) if dirs else np.zeros((0, 3)))
    for (i, j), values in zip(quads, radiance.reshape(len(quads), -1)):
        if is_cap[i]:
            out[i, :] = values.mean()
        else:
            out[i, j] = values.mean()
    return out


def reflected_local(config: cfg.SceneConfig, surface: np.ndarray, first_batch: int,
                    batches: int) -> np.ndarray:
    """(batches, directions, 3): per batch, in each exact air direction of
    local_directions_deg (upward ones), the surface-reflected radiance of a sky of unit
    irradiance, that of a sun of unit direct irradiance Ed0 (1 - f), and the unit sky's
    radiance L_sky in the direction a flat surface reflects into it (rho's denominator, DESIGN
    7.3); reflected_at scales them to a wavelength's light; NaN for a direction that is not
    upward. The sky part is a Monte Carlo average over REFLECTED_SAMPLES
    surface samples per batch (own streams from (seed, batch, 1)); the sun's part is the
    single-reflection glint (cox_munk.glint_single, exact up to the light the sun sends by two
    facets or more), 0 for a delta surface."""
    from ..kernel.surface import cox_munk
    from ..kernel.surface.dispatch import reflected_from
    ill = config.illumination
    out = np.zeros((batches, len(config.tallies.local_directions_deg), 3))
    theta_s = math.radians(ill.sun_zenith_deg)
    sun = (math.sin(theta_s), 0.0, math.cos(theta_s))
    for k, (theta_deg, phi_deg) in enumerate(config.tallies.local_directions_deg):
        t, p = math.radians(theta_deg), math.radians(phi_deg)
        o = (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))
        if o[2] >= 0.0:
            out[:, k] = np.nan
            continue
        mirror = np.array([[o[0], o[1], -o[2]]])
        l_sky_mirror = sky_radiance(ill, mirror)
        glint = 0.0 if surface["delta"] else cox_munk.glint_single(surface, *sun, *o) / max(
            math.cos(theta_s), 1e-12)
        for b in range(batches):
            state = np.random.SeedSequence(config.seed, spawn_key=(first_batch + b, 1)
                                           ).generate_state(4, np.uint64)
            came = reflected_from(surface, *o, REFLECTED_SAMPLES, state)
            hit = ~np.isnan(came[:, 0])
            sky = np.zeros(REFLECTED_SAMPLES)
            if hit.any():
                sky[hit] = sky_radiance(ill, came[hit])
            out[b, k] = sky.mean(), glint, l_sky_mirror[0]
    return out


def reflected_at(unit: np.ndarray, ed0: float, diffuse_fraction: float) -> np.ndarray:
    """(batches, directions, 2): reflected_local's unit radiances for a wavelength's light
    (Ed0 at 0+, its diffuse fraction f): the reflected sky and sun radiance, and L_sky."""
    e_sky = ed0 * diffuse_fraction
    e_sun = ed0 * (1.0 - diffuse_fraction)
    return np.stack([unit[..., 0] * e_sky + unit[..., 1] * e_sun, unit[..., 2] * e_sky],
                    axis=-1)
