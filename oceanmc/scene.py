"""Config -> scene arrays: everything the compiled kernel needs, as numpy arrays, floats and
integer model ids. No Python object crosses into the kernel."""
from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np

from . import config as cfg
from . import brdf_tables, cap_tables, phase_tables, sky_maps
from .kernel import models
from .kernel.interface import fresnel
from .kernel.phase.dispatch import layer_density
from .kernel.scene_arrays import SceneArrays

PURE_WATER_BETA = 0.835   # 0.06225 (1 + 0.835 cos^2): Morel (1974)
RAYLEIGH_BETA = 1.0


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
        mu = np.cos(np.radians(self.theta_edges))
        band = np.abs(mu[:-1] - mu[1:])
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


def _phase_components(phase) -> list[tuple[float, int, list[float], tuple | None]]:
    """(relative weight, model id, params, table) for each component of a layer's phase."""
    if isinstance(phase, cfg.Mixture):
        total = sum(c.b for c in phase.components)
        out = []
        for comp in phase.components:
            share = comp.b / total if total > 0.0 else 1.0 / len(phase.components)
            out += [(share * w, m, p, t) for w, m, p, t in _phase_components(comp.phase)]
        return out
    if isinstance(phase, cfg.Isotropic):
        return [(1.0, models.PHASE_ISOTROPIC, [], None)]
    if isinstance(phase, cfg.Rayleigh):
        return [(1.0, models.PHASE_QUADRATIC, [RAYLEIGH_BETA], None)]
    if isinstance(phase, cfg.PureWater):
        return [(1.0, models.PHASE_QUADRATIC, [PURE_WATER_BETA], None)]
    if isinstance(phase, cfg.HenyeyGreenstein):
        return [(1.0, models.PHASE_HG, [phase.g], None)]
    if isinstance(phase, cfg.TwoTermHG):
        return [(phase.alpha, models.PHASE_HG, [phase.g1], None),
                (1.0 - phase.alpha, models.PHASE_HG, [phase.g2], None)]
    if isinstance(phase, cfg.FournierForand):
        return [(1.0, models.PHASE_TABULATED, [], phase_tables.fournier_forand_table(phase.bb_ratio))]
    if isinstance(phase, cfg.Petzold):
        return [(1.0, models.PHASE_TABULATED, [], phase_tables.petzold_table())]
    if isinstance(phase, cfg.TablePhase):
        return [(1.0, models.PHASE_TABULATED, [], phase_tables.user_table(phase.file))]
    raise AssertionError(f"unhandled phase model {phase!r}")


def _planes(config: cfg.SceneConfig):
    """Plane depths (surface first, bottom or inf last), the tally level at each plane (-1 for
    none), the layer of each segment between planes, the level tallied at 0- (or -1), and the
    tally depths (snapped onto layer boundaries they differ from only by rounding)."""
    bounds = [0.0]
    for layer in config.water.layers:
        bounds.append(bounds[-1] + layer.thickness_m)
    # a tally depth that differs from a layer boundary only by rounding (the sum of many thin
    # layers) is that boundary, not a sliver of a segment beside it
    edges = np.array(bounds)
    depths = []
    for d in config.tallies.depths_m:
        near = int(np.argmin(np.abs(edges - d)))
        depths.append(bounds[near] if abs(edges[near] - d) <= 1e-9 * max(1.0, d) else d)
    plane_z = np.array(sorted(set(bounds) | set(depths)), dtype=np.float64)
    level_of = {d: i for i, d in enumerate(depths)}
    plane_tally = np.array([level_of.get(z, -1) for z in plane_z], dtype=np.int64)
    tops = np.array(bounds[:-1])
    mids = np.where(np.isinf(plane_z[1:]), plane_z[:-1] + 1.0, 0.5 * (plane_z[1:] + plane_z[:-1]))
    segment_layer = (np.searchsorted(tops, mids, side="right") - 1).astype(np.int64)
    return plane_z, plane_tally, segment_layer, int(plane_tally[0]), np.array(depths)


def _optical_depths(plane_z: np.ndarray, segment_layer: np.ndarray, c: np.ndarray) -> np.ndarray:
    """tau = integral of c dz from the surface to each plane (inf below an infinite layer)."""
    with np.errstate(invalid="ignore"):
        steps = np.where(np.isinf(plane_z[1:]), np.inf,
                         c[segment_layer] * (plane_z[1:] - plane_z[:-1]))
    return np.concatenate([[0.0], np.cumsum(steps)])


def local_directions(config: cfg.SceneConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                         list[tuple[int, int]]]:
    """Kernel rows for the requested local-estimate directions (theta, phi of travel; in water at
    the tally depths, in air at 0+): unit in-water directions, whether a row scores the water
    levels, its factor t/n^2 at 0+ (0: not scored there), and for each requested direction its
    (water row, air row)."""
    n = config.n_water
    dirs, water, air, rows = [], [], [], []
    for theta_deg, phi_deg in config.tallies.local_directions_deg:
        theta, phi = math.radians(theta_deg), math.radians(phi_deg)
        in_water = (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi),
                    math.cos(theta))
        sin_w = math.sin(theta) / n               # Snell: the in-water direction seen at 0+
        cos_w = math.sqrt(1.0 - sin_w * sin_w)
        refracted = (sin_w * math.cos(phi), sin_w * math.sin(phi), -cos_w)
        if config.surface.model == "flat":
            r, _ = fresnel(n, 1.0, cos_w)
            factor = (1.0 - r) / (n * n)
        else:
            factor = 1.0
        if np.allclose(in_water, refracted, atol=1e-15):
            rows.append((len(dirs), len(dirs)))
            dirs.append(in_water), water.append(True), air.append(factor)
        else:
            rows.append((len(dirs), len(dirs) + 1))
            dirs += [in_water, refracted]
            water += [True, False]
            air += [0.0, factor]
    return (np.array(dirs, dtype=np.float64).reshape(-1, 3), np.array(water, dtype=np.bool_),
            np.array(air, dtype=np.float64), rows)


def _bottom(bottom) -> tuple[int, np.ndarray]:
    """(model id, packed parameter array): scalars, measured tables, the general sampler's
    tables; the BRDF's physical checks run here (brdf_tables.py)."""
    return brdf_tables.bottom_arrays(bottom)


def _mu_edges(theta_edges: np.ndarray) -> np.ndarray:
    mu = np.cos(np.radians(theta_edges))
    mu[theta_edges == 90.0] = 0.0  # exact, so no downward photon lands in an upward band
    return mu


_CAP_CACHE: dict[bytes, list[np.ndarray]] = {}


def _layer_cap_moments(sc: SceneArrays, layer: int, breaks: np.ndarray, geometry: tuple,
                       alphas: np.ndarray) -> list[np.ndarray]:
    """[M0, M1] of the water cap and of the air cap's water side for one layer's phase function,
    remembered within the process by the phase function's content (scenes of a batch, tests)."""
    first, count = sc.layer_comp_start[layer], sc.layer_comp_count[layer]
    digest = hashlib.sha1(np.array(geometry).tobytes())
    for k in range(first, first + count):
        digest.update(np.array([sc.comp_model[k], sc.comp_cumweight[k]]).tobytes())
        digest.update(sc.comp_params[k].tobytes())
        start, length = sc.comp_tab_start[k], sc.comp_tab_len[k]
        digest.update(sc.tab_q[start:start + length].tobytes())
        digest.update(sc.tab_psi[start:start + length].tobytes())
    key = digest.digest()
    if key not in _CAP_CACHE:
        beta, mu_w, beta_w, mu_a = geometry
        table = cap_tables.cumulative(lambda psi: layer_density(sc, layer, psi), breaks)
        _CAP_CACHE[key] = [*cap_tables.cap_moments(table, beta, mu_w, alphas),
                           *cap_tables.cap_moments(table, beta_w, mu_a, alphas)]
        if len(_CAP_CACHE) > 64:
            _CAP_CACHE.pop(next(iter(_CAP_CACHE)))
    return _CAP_CACHE[key]


def _upward_fields(estimator: cfg.Estimator, albedo: np.ndarray) -> dict:
    """Scattering biased toward straight up (kernel/upward.py): a layer's fraction is at most
    1 - w0, so that no scattering event makes a packet heavier; 0 in a layer leaves it out."""
    fraction = np.minimum(float(estimator.upward_fraction or 0.0), 1.0 - albedo)
    fraction[albedo <= 0.0] = 0.0
    cos_cone = math.cos(math.radians(estimator.upward_cone_deg))
    return dict(layer_up_fraction=fraction,
                layer_up_density=fraction / (2.0 * math.pi * (1.0 - cos_cone)),
                layer_up_keep=1.0 - fraction, up_cos=cos_cone)


def _cap_fields(config: cfg.SceneConfig, sc: SceneArrays, grid: Grid) -> dict:
    """The nadir polar-cap local-estimate tables and constants (cap_tables.py)."""
    beta = math.radians(180.0 - grid.theta_edges[-2])
    n = config.n_water
    beta_w = math.asin(math.sin(beta) / n)
    mu_w = 0.5 * (1.0 + math.cos(beta))
    mu_a = 0.5 * (1.0 + math.cos(beta_w))
    fine_end, fine_step, coarse_step, fine_nodes = cap_tables.alpha_grid(beta)
    alphas = cap_tables.alpha_nodes(beta)
    tables: dict[tuple, int] = {}
    table_of_layer = []
    rows = {"m0w": [], "m1w": [], "m0a": [], "m1a": []}
    enabled = config.nadir_local
    for layer in range(len(config.water.layers)):
        first, count = sc.layer_comp_start[layer], sc.layer_comp_count[layer]
        key = tuple((int(sc.comp_model[k]), tuple(sc.comp_params[k]), int(sc.comp_tab_start[k]),
                     float(sc.comp_cumweight[k])) for k in range(first, first + count))
        if key not in tables and (enabled or not tables):
            tables[key] = len(tables)
            if enabled:
                breaks = np.concatenate([sc.tab_psi[sc.comp_tab_start[k]:sc.comp_tab_start[k]
                                                    + sc.comp_tab_len[k]]
                                         for k in range(first, first + count)] + [np.zeros(0)])
                moments = _layer_cap_moments(sc, layer, breaks, (beta, mu_w, beta_w, mu_a),
                                             alphas)
            else:
                moments = [np.zeros(len(alphas))] * 4
            for name, values in zip(("m0w", "m1w", "m0a", "m1a"), moments):
                rows[name].append(values)
        table_of_layer.append(tables.get(key, 0))
    step = 1e-6
    h = cap_tables.air_factor(np.array([mu_a - step, mu_a, mu_a + step]), n,
                              config.surface.model == "flat")
    return dict(
        cap_estimates=enabled, cap_table_of_layer=np.array(table_of_layer, dtype=np.int64),
        cap_m0w=np.array(rows["m0w"]), cap_m1w=np.array(rows["m1w"]),
        cap_m0a=np.array(rows["m0a"]), cap_m1a=np.array(rows["m1a"]),
        cap_fine_end=fine_end, cap_fine_step=fine_step, cap_coarse_step=coarse_step,
        cap_fine_nodes=int(fine_nodes),
        cap_mu_w=mu_w, cap_omega_w=2.0 * math.pi * (1.0 - math.cos(beta)),
        # transmission along mu_w from each level to the one above it (the first: unused)
        cap_level_decay=np.exp(-np.diff(sc.level_tau, prepend=sc.level_tau[:1]) / mu_w),
        cap_cos_water=math.cos(beta), cap_mu_a=mu_a,
        cap_omega_a=2.0 * math.pi * (1.0 - math.cos(beta)), cap_cos_air=math.cos(beta),
        cap_h=float(h[1]), cap_dh=float((h[2] - h[0]) / (2.0 * step)))


THETA_LOOKUP_CELLS = 4096


def _theta_lookup(mu_edges: np.ndarray) -> np.ndarray:
    """For each of THETA_LOOKUP_CELLS equal cells of uz in [-1, 1], the band (index into the
    falling mu_edges) of the cell's top value (see kernel.tally.theta_band_fast)."""
    top = -1.0 + 2.0 * (np.arange(THETA_LOOKUP_CELLS) + 1) / THETA_LOOKUP_CELLS
    top = np.minimum(top, 1.0)
    bands = np.searchsorted(-mu_edges, -top, side="left") - 1
    return np.clip(bands, 0, len(mu_edges) - 2).astype(np.int64)


def build(config: cfg.SceneConfig) -> tuple[SceneArrays, Grid]:
    """The kernel's view of a validated scene, and the tally grid. Raises TableError (a
    ConfigError) for unusable auxiliary files."""
    layers = config.water.layers
    comp_start, comp_count, cumweight, comp_model, comp_params = [], [], [], [], []
    tab_start, tab_len, psi_parts, q_parts, cdf_parts = [], [], [], [], []
    tab_offset = 0
    table_cache: dict[int, tuple[int, int]] = {}
    for layer in layers:
        comps = _phase_components(layer.phase)
        comp_start.append(len(comp_model))
        comp_count.append(len(comps))
        total = sum(w for w, *_ in comps)
        running = 0.0
        for weight, model, params, table in comps:
            running += weight / total
            cumweight.append(running)
            comp_model.append(model)
            comp_params.append(list(params) + [0.0] * (2 - len(params)))
            if table is None:
                tab_start.append(0)
                tab_len.append(0)
                continue
            key = id(table[0])
            if key not in table_cache:
                table_cache[key] = (tab_offset, len(table[0]))
                psi_parts.append(table[0])
                q_parts.append(table[1])
                cdf_parts.append(table[2])
                tab_offset += len(table[0])
            tab_start.append(table_cache[key][0])
            tab_len.append(table_cache[key][1])
        cumweight[-1] = 1.0

    def flat(parts):
        return np.concatenate(parts) if parts else np.zeros(1)

    plane_z, plane_tally, segment_layer, surface_tally, depths = _planes(config)
    layer_c = np.array([layer.a + layer.b for layer in layers], dtype=np.float64)
    albedo = np.array([layer.b / (layer.a + layer.b) if layer.b > 0.0 else 0.0
                       for layer in layers], dtype=np.float64)
    plane_tau = _optical_depths(plane_z, segment_layer, layer_c)
    level_tau = np.array([plane_tau[np.searchsorted(plane_z, d)] for d in depths],
                         dtype=np.float64)
    le_dirs, le_water, le_air_factor, _ = local_directions(config)
    bottom_model, bottom_params = _bottom(config.bottom)
    grid = make_grid(config.tallies)
    ill = config.illumination
    theta_s = math.radians(ill.sun_zenith_deg)
    sc = SceneArrays(
        sun_mu=math.cos(theta_s), sun_sin=math.sin(theta_s),
        diffuse_fraction=float(ill.diffuse_fraction),
        **sky_maps.sky_fields(ill),
        surface_flat=config.surface.model == "flat", n_water=float(config.n_water),
        fresnel_schlick=config.surface.fresnel == "schlick",
        plane_z=plane_z, plane_tally=plane_tally, segment_layer=segment_layer,
        layer_c=layer_c,
        layer_inv_c=np.divide(1.0, layer_c, out=np.zeros_like(layer_c), where=layer_c > 0.0),
        layer_albedo=albedo,
        layer_comp_start=np.array(comp_start, dtype=np.int64),
        layer_comp_count=np.array(comp_count, dtype=np.int64),
        comp_cumweight=np.array(cumweight, dtype=np.float64),
        comp_model=np.array(comp_model, dtype=np.int64),
        comp_params=np.array(comp_params, dtype=np.float64),
        comp_tab_start=np.array(tab_start, dtype=np.int64),
        comp_tab_len=np.array(tab_len, dtype=np.int64),
        tab_psi=flat(psi_parts), tab_q=flat(q_parts), tab_cdf=flat(cdf_parts),
        bottom_model=bottom_model, bottom_params=bottom_params,
        theta_mu_edges=_mu_edges(grid.theta_edges),
        theta_lookup=_theta_lookup(_mu_edges(grid.theta_edges)),
        theta_is_cap=grid.is_cap, n_phi=int(config.tallies.phi_bands),
        phi_edge_cos=np.cos(np.radians(grid.phi_edges[:-1])),
        phi_edge_sin=np.sin(np.radians(grid.phi_edges[:-1])),
        tally_radiance=bool(config.tallies.radiance), surface_tally=surface_tally,
        air_level=len(config.tallies.depths_m),
        mu_cut=float(config.tallies.grazing_mu_cut),
        level_z=depths.astype(np.float64), level_tau=level_tau, plane_tau=plane_tau,
        local_estimates=len(le_dirs) > 0, le_dirs=le_dirs, le_water=le_water,
        le_air_factor=le_air_factor,
        analog=config.estimator.mode == "analog",
        roulette_weight=float(config.estimator.roulette_weight),
        roulette_survival=float(config.estimator.roulette_survival),
        max_events=int(config.estimator.max_events),
        split_weight=float(config.estimator.split_weight or math.inf),
        **_upward_fields(config.estimator, albedo),
        **{name: 0 for name in SceneArrays._fields if name.startswith("cap_")},
    )
    return sc._replace(**_cap_fields(config, sc, grid)), grid
