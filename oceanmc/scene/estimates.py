"""The local-estimate packer: the ESTIMATES record and its pools (kernel/records.py): the rows
of the exact upward directions, and the tables of the nadir polar-cap estimate (cap_tables.py)
for each distinct layer phase function."""
from __future__ import annotations

import functools
import hashlib
import math
from pathlib import Path

import numpy as np

from .. import config as cfg
from ..kernel.compile import CACHE_DIR
from ..kernel.phase import quadratic
from ..kernel.phase.dispatch import component_density
from ..kernel.records import ESTIMATES, Pool, record
from ..kernel.surface.dispatch import transmittance
from ..kernel.surface.fresnel import fresnel
from . import cap_tables
from .disk_cache import save_atomically
from .grid import Grid
from .medium import Column


def local_directions(config: cfg.SceneConfig, surface: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[tuple[int, int]]]:
    """Kernel rows for the requested local-estimate directions (theta, phi of travel; in water at
    the tally depths, in air at 0+): unit in-water directions, whether a row scores the water
    levels, its factor t/n^2 at 0+ (0: not scored there; t from the surface component), and for
    each requested direction its (water row, air row)."""
    n = config.n_water
    dirs, water, air, rows = [], [], [], []
    for theta_deg, phi_deg in config.tallies.local_directions_deg:
        theta, phi = math.radians(theta_deg), math.radians(phi_deg)
        in_water = (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi),
                    math.cos(theta))
        sin_w = math.sin(theta) / n               # Snell: the in-water direction seen at 0+
        cos_w = math.sqrt(1.0 - sin_w * sin_w)
        refracted = (sin_w * math.cos(phi), sin_w * math.sin(phi), -cos_w)
        # through the rough surface the facet walk decides what leaves (local_estimate.py)
        delta = bool(surface[0]["delta"])
        factor = (transmittance(surface[0], cos_w) if delta else 1.0) / (n * n)
        if delta and np.allclose(in_water, refracted, atol=1e-15):
            rows.append((len(dirs), len(dirs)))
            dirs.append(in_water), water.append(True), air.append(factor)
        else:
            rows.append((len(dirs), len(dirs) + 1))
            dirs += [in_water, refracted]
            water += [True, False]
            air += [0.0, factor]
    return (np.array(dirs, dtype=np.float64).reshape(-1, 3), np.array(water, dtype=np.int64),
            np.array(air, dtype=np.float64), rows)


_CAP_CACHE: dict[bytes, list[np.ndarray]] = {}
# the moments of each phase function and cap, kept on disk beside the kernel's compile cache
# (0.5 s of numpy per phase function, the largest part of a cached start otherwise), keyed by
# the phase function, the geometry and the source of cap_tables.py
_CAP_DIR = CACHE_DIR.parent / "cap-moments"
_CAP_FILES_KEPT = 256   # 83 kB each
_CAP_SOURCE = hashlib.sha1(Path(cap_tables.__file__).read_bytes()).digest()


def _save(path: Path, table: np.ndarray) -> None:
    """Keeps a table in the disk cache (disk_cache.save_atomically), and the newest
    _CAP_FILES_KEPT files only."""
    if not save_atomically(path, table):
        return
    try:
        kept = sorted(_CAP_DIR.glob("*.npy"), key=lambda p: p.stat().st_mtime)
        for old in kept[:-_CAP_FILES_KEPT]:
            old.unlink(missing_ok=True)
    except OSError:
        pass   # another run pruned the same file first


def _remembered(kept: dict, key: bytes, path: Path, compute) -> np.ndarray:
    """kept[key]: from the process's memory, else from the disk cache's file `path` where it is
    there and readable, else compute() (then kept there too); the newest 64 kept in memory."""
    if key not in kept:
        try:
            kept[key] = np.load(path)
        except (OSError, ValueError):   # missing or unreadable: computed again
            kept[key] = compute()
            _save(path, kept[key])
        if len(kept) > 64:
            kept.pop(next(iter(kept)))
    return kept[key]


def component_table(m, mf: np.ndarray, mi: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """(psi, q) of phase function component k's table in the pools (empty for an analytic
    component; tables on one angle grid share its psi: kernel/phase/dispatch.py table_at)."""
    start, length = mi[m["comp_tab_start"] + k], mi[m["comp_tab_len"] + k]
    psi_start = m["tab_psi"] + mi[m["comp_psi_start"] + k]
    return (mf[psi_start:psi_start + length],
            mf[m["tab_q"] + start:m["tab_q"] + start + length])


def component_key(m, mf: np.ndarray, mi: np.ndarray, k: int) -> bytes:
    """A digest of phase function component k: its model, parameters and table."""
    psi, q = component_table(m, mf, mi, k)
    return hashlib.sha1(np.array([mi[m["comp_model"] + k], mf[m["comp_params"] + 2 * k],
                                  mf[m["comp_params"] + 2 * k + 1]]).tobytes()
                        + psi.tobytes() + q.tobytes()).digest()


def layer_key(medium: np.ndarray, mf: np.ndarray, mi: np.ndarray, layer: int) -> bytes:
    """A digest of the layer's phase functions: its components' models, weights at every
    wavelength, parameters and tables."""
    m = medium[0]
    first, count = mi[m["comp_start"] + layer], mi[m["comp_count"] + layer]
    n_comps = int(m["n_comps"])
    digest = hashlib.sha1()
    for k in range(first, first + count):
        weights = mf[m["comp_cumweight"] + k:m["comp_cumweight"] + n_comps * int(m["n_wl"]):
                     n_comps]
        digest.update(weights.tobytes() + component_key(m, mf, mi, k))
    return digest.digest()


_COMPONENT_MOMENTS: dict[bytes, np.ndarray] = {}


def component_moments(m, mf, mi, k: int, caps, geometry_key: bytes) -> np.ndarray:
    """(4, n_alpha): M0 and M1 of the water cap and of the air cap's water side for phase
    function component k alone (caps(): the two caps' geometries), remembered within the
    process by its content and the geometry."""
    key = hashlib.sha1(geometry_key + component_key(m, mf, mi, k)).digest()
    if key not in _COMPONENT_MOMENTS:
        table = cap_tables.cumulative(lambda angles: component_density(m, mf, mi, k, angles),
                                      component_table(m, mf, mi, k)[0])
        water, air = caps()
        _COMPONENT_MOMENTS[key] = np.array([*water.moments(table), *air.moments(table)])
        if len(_COMPONENT_MOMENTS) > 64:
            _COMPONENT_MOMENTS.pop(next(iter(_COMPONENT_MOMENTS)))
    return _COMPONENT_MOMENTS[key]


def layer_cap_moments(medium, mf, mi, layer: int, caps, key: bytes,
                      geometry_key: bytes) -> np.ndarray:
    """(4, n_alpha, n_wl): M0 and M1 of the water cap and of the air cap's water side for the
    layer's phase function at each wavelength (caps(): the two caps' cap_tables.cap_geometry,
    built only if some table is), remembered by key (the phase functions' content and the
    geometry) within the process and on disk."""
    def mixed() -> np.ndarray:
        m = medium[0]
        first, count = mi[m["comp_start"] + layer], mi[m["comp_count"] + layer]
        n_wl, n_comps = int(m["n_wl"]), int(m["n_comps"])
        # the moments are linear in the phase function: each wavelength's are its components'
        # mixed with that wavelength's shares (a profile's sublayers and a spectrum's
        # wavelengths share their components' tables)
        parts = np.array([component_moments(m, mf, mi, k, caps, geometry_key)
                          for k in range(first, first + count)])      # (count, 4, n_alpha)
        cumulative = mf[m["comp_cumweight"]:m["comp_cumweight"] + n_wl * n_comps].reshape(
            n_wl, n_comps)[:, first:first + count]
        shares = np.diff(cumulative, axis=1, prepend=0.0)              # (n_wl, count)
        return np.einsum("wk,kma->maw", shares, parts)

    return _remembered(_CAP_CACHE, key, _CAP_DIR / f"{key.hex()}.npy", mixed)


def emission_moments(beta_quadratic: float, caps, geometry_key: bytes) -> np.ndarray:
    """(4, n_alpha): the cap moments (as component_moments) of an inelastic emission's phase
    function (1 + beta cos^2), the same at every wavelength (kernel/channels/inelastic.py),
    remembered within the process and on disk as a layer's are (building the caps' geometry
    for them took 0.5 s of every start of an inelastic scene)."""
    key = hashlib.sha1(geometry_key + np.array([beta_quadratic]).tobytes()).digest()

    def moments() -> np.ndarray:
        params = np.array([beta_quadratic])
        table = cap_tables.cumulative(
            lambda angles: 2.0 * math.pi * np.sin(angles) * np.array(
                [quadratic.evaluate(params, math.cos(a)) for a in angles]), np.zeros(0))
        water, air = caps()
        return np.array([*water.moments(table), *air.moments(table)])

    return _remembered(_COMPONENT_MOMENTS, key, _CAP_DIR / f"emission-{key.hex()}.npy", moments)


# The rough sea's lobe K is about (n - 1) alpha wide in the air (alpha the Beckmann roughness,
# the root of the mean square slope; a facet tilted by alpha turns the refracted light by
# about (n - 1) alpha). Narrower than this, the quadrature over the air cap
# (cap_tables.ROUGH_POLAR_NODES x ROUGH_AZIMUTHS) does not resolve it: with n = 1.34, Rrs nadir
# by the cap's estimate read 6% low at mean square slope 3e-5, 38% at 1e-5 and 74% at 1e-6 (a
# Lambertian bottom at 5 m, HG 0.9; flat 0.01703 +- 0.00015), and n = 1 (no refraction) failed
# with an IndexError. There the cap tables are the flat surface's, the limit K tends to: their
# difference is of order alpha squared (at 1e-4, where both work: 0.01708 +- 0.00011 through
# the lobe). The width at n = 1.34 and mean square slope 1e-4:
MIN_LOBE_WIDTH = 0.34 * 0.01


def rough_mean_cosine(enabled: bool, roughness: float, n: float, beta: float,
                      alphas: np.ndarray, caps) -> float:
    """The mean cosine of the rough sea's lobe K (cap_tables.RoughCap), remembered on disk
    with the moments (so that a start whose tables are cached builds no geometry); 1 when the
    cap estimate is off."""
    if not enabled:
        return 1.0
    key = hashlib.sha1(_CAP_SOURCE + np.array([roughness, n, beta]).tobytes()
                       + alphas.tobytes()).hexdigest()
    path = _CAP_DIR / f"mu-{key}.npy"
    try:
        return float(np.load(path)[0])
    except (OSError, ValueError, IndexError):
        mu_bar = caps()[1].mu_bar
    _save(path, np.array([mu_bar]))
    return mu_bar


def pack(config: cfg.SceneConfig, medium: np.ndarray, mf: np.ndarray, mi: np.ndarray,
         surface: np.ndarray, column: Column, grid: Grid,
         directions: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ESTIMATES record, float pool, int pool); directions: local_directions' first three."""
    dirs, in_water, air_factor = directions
    beta = math.radians(180.0 - grid.theta_edges[-2])
    n = config.n_water
    beta_w = math.asin(math.sin(beta) / n)
    mu_w = 0.5 * (1.0 + math.cos(beta))
    mu_a = 0.5 * (1.0 + math.cos(beta_w))
    fine_end, fine_step, coarse_step, fine_nodes = cap_tables.alpha_grid(beta)
    alphas = cap_tables.alpha_nodes(beta)
    enabled = config.nadir_local
    n_wl = len(config.wavelengths)
    # through the rough sea (isotropic slopes: config/scene.py) the air cap's light comes from
    # the in-water lobe K of kernel/rough_cap.py (cap_tables.RoughCap); a sea nearly flat
    # takes the flat surface's tables (MIN_LOBE_WIDTH)
    roughness = 0.0 if surface[0]["delta"] else float(surface[0]["alpha_u"])
    if (n - 1.0) * roughness < MIN_LOBE_WIDTH:
        roughness = 0.0
    geometry = (beta, mu_w, beta_w, mu_a, roughness, n)

    @functools.cache
    def caps():
        return (cap_tables.cap_geometry(beta, mu_w, alphas),
                cap_tables.rough_cap_geometry(alphas, roughness, n, beta) if roughness
                else cap_tables.cap_geometry(beta_w, mu_a, alphas))

    geometry_key = _CAP_SOURCE + np.array(geometry).tobytes() + alphas.tobytes()
    tables: dict[bytes, int] = {}
    table_of_layer = []
    moments = []    # per table (4, n_alpha, n_wl): M0, M1 of the water cap, then the air cap
    for layer in range(len(column.albedo)):
        key = hashlib.sha1(geometry_key + layer_key(medium, mf, mi, layer)).digest() \
            if enabled else b""
        if key not in tables:
            tables[key] = len(tables)
            moments.append(layer_cap_moments(medium, mf, mi, layer, caps, key, geometry_key)
                           if enabled else np.zeros((4, len(alphas), n_wl)))
        table_of_layer.append(tables[key])
    # then one table per inelastic channel's emission (channel k at emission_tables + k - 1)
    emission_tables = len(moments)
    m = medium[0]
    for channel in range(1, int(m["n_channels"])):
        moments.append(np.repeat(
            emission_moments(float(mf[m["channel_beta"] + channel]), caps, geometry_key)
            [:, :, None], n_wl, axis=2) if enabled else np.zeros((4, len(alphas), n_wl)))
    cap_solid_angle = 4.0 * math.pi * math.sin(beta / 2.0) ** 2  # 2 pi (1 - cos beta), stably
    if roughness:
        # K holds the surface's transmission and 1 / dOmega_a: g = exp(-tau/mu) / mu about
        # K's mean cosine (the mean of K alone: the tables' M1 is taken about it)
        mu_a = rough_mean_cosine(enabled, roughness, n, beta, alphas, caps)
        h, dh, air_solid_angle = 1.0 / mu_a, -1.0 / (mu_a * mu_a), 1.0
    else:
        step = 1e-6
        # (a nearly flat rough sea: the flat interface's Fresnel transmittance)
        hs = cap_tables.air_factor(
            np.array([mu_a - step, mu_a, mu_a + step]), n,
            (lambda mu: transmittance(surface[0], mu)) if surface[0]["delta"]
            else (lambda mu: 1.0 - fresnel(n, 1.0, mu)[0]))
        h, dh, air_solid_angle = float(hs[1]), float((hs[2] - hs[0]) / (2.0 * step)), \
            cap_solid_angle
    f, i = Pool(np.float64), Pool(np.int64)
    level_tau = column.level_tau
    rec = record(
        ESTIMATES, directions_on=int(len(dirs) > 0), cap_on=int(enabled), n_dirs=len(dirs),
        n_alpha=len(alphas), fine_end=fine_end, fine_step=fine_step, coarse_step=coarse_step,
        fine_nodes=int(fine_nodes), mu_w=mu_w, omega_w=cap_solid_angle,
        cos_water=math.cos(beta), mu_a=mu_a, omega_a=air_solid_angle,
        cos_air=math.cos(beta), h=h, dh=dh,
        dirs=f.add(dirs), air_factor=f.add(air_factor),
        # table-major, then alpha, then wavelength: a packet reads a row of n_wl
        **{f"cap_{name}": f.add(np.array([t[m] for t in moments]))
           for m, name in enumerate(("m0w", "m1w", "m0a", "m1a"))},
        # transmission along mu_w from each level to the one above it (the first: unused),
        # per wavelength (n_depths x n_wl: a level's wavelengths side by side)
        level_decay=f.add(np.exp(-np.diff(level_tau, axis=1, prepend=level_tau[:, :1])
                                 / mu_w).T),
        in_water=i.add(in_water), table_of_layer=i.add(table_of_layer),
        emission_tables=emission_tables)
    return rec, f.array(), i.array()
