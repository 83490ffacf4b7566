"""The water-column packer: the MEDIUM record and its pools (kernel/records.py): planes and
segments, per-layer optical properties, the phase-function components of each layer and their
tables, and the per-layer upward-bias fractions."""
from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np

from .. import config as cfg
from .. import optics, registry
from ..kernel import models, spectral
from ..kernel.records import MEDIUM, Pool, record
from . import phase_tables, weight_window

PURE_WATER_BETA = 0.835   # 0.06225 (1 + 0.835 cos^2): Morel (1974)
RAYLEIGH_BETA = 1.0


@dataclass(frozen=True)
class Column:
    """What the other packers need to know of the water column."""
    surface_level: int         # the tally level at 0- (or -1)
    depths: np.ndarray         # tally depths, snapped onto layer boundaries
    level_tau: np.ndarray      # optical depth of each tally depth (n_wl, n_depths)
    albedo: np.ndarray         # per layer
    layers: tuple              # optics.LayerIOPs of each layer (a depth profile is resolved
    #                            into several layers of one configured layer)
    windows: weight_window.DepthWindows   # depth splitting: whether, and why
    window: np.ndarray         # the window weight of each segment between planes (1: none)
    upward: float | None       # the upward bias the scene runs with (None: off)


def _mixture(phase: cfg.Mixture) -> list:
    total = sum(c.b for c in phase.components)
    out = []
    for comp in phase.components:
        share = comp.b / total if total > 0.0 else 1.0 / len(phase.components)
        out += [(share * w, m, p, t) for w, m, p, t in phase_components(comp.phase)]
    return out


# schema phase model -> its kernel components (registry.PHASE lists the kernel models of each)
COMPONENTS = {
    "isotropic": lambda phase: [(1.0, models.PHASE_ISOTROPIC, [], None)],
    "rayleigh": lambda phase: [(1.0, models.PHASE_QUADRATIC, [RAYLEIGH_BETA], None)],
    "pure_water": lambda phase: [(1.0, models.PHASE_QUADRATIC, [PURE_WATER_BETA], None)],
    "henyey_greenstein": lambda phase: [(1.0, models.PHASE_HG, [phase.g], None)],
    "two_term_hg": lambda phase: [(phase.alpha, models.PHASE_HG, [phase.g1], None),
                                  (1.0 - phase.alpha, models.PHASE_HG, [phase.g2], None)],
    "fournier_forand": lambda phase: [(1.0, models.PHASE_TABULATED, [],
                                       phase_tables.fournier_forand_table(phase.bb_ratio))],
    "petzold": lambda phase: [(1.0, models.PHASE_TABULATED, [], phase_tables.petzold_table())],
    "table": lambda phase: [(1.0, models.PHASE_TABULATED, [],
                             phase_tables.user_table(phase.file))],
    "mixture": _mixture,
}


def phase_components(phase) -> list[tuple[float, int, list[float], tuple | None]]:
    """(relative weight, kernel model id, params, table) for each component of a layer's
    phase function."""
    return COMPONENTS[phase.model](phase)


def planes(config: cfg.SceneConfig, layers: list[optics.LayerIOPs], added=()):
    """Plane depths (surface first, bottom or inf last), the tally level at each plane (-1 for
    none), the layer of each segment between planes, the level tallied at 0- (or -1), and the
    tally depths (snapped onto layer boundaries they differ from only by rounding). added:
    depths of further planes without a tally (the depth windows': weight_window.py)."""
    bounds = [0.0]
    for layer in layers:
        bounds.append(bounds[-1] + layer.thickness_m)
    # a tally depth that differs from a layer boundary only by rounding (the sum of many thin
    # layers) is that boundary, not a sliver of a segment beside it
    edges = np.array(bounds)
    depths = []
    for d in config.tallies.depths_m:
        near = int(np.argmin(np.abs(edges - d)))
        depths.append(bounds[near] if abs(edges[near] - d) <= 1e-9 * max(1.0, d) else d)
    plane_z = np.array(sorted(set(bounds) | set(depths) | set(map(float, added))),
                       dtype=np.float64)
    level_of = {d: i for i, d in enumerate(depths)}
    plane_tally = np.array([level_of.get(z, -1) for z in plane_z], dtype=np.int64)
    tops = np.array(bounds[:-1])
    mids = np.where(np.isinf(plane_z[1:]), plane_z[:-1] + 1.0, 0.5 * (plane_z[1:] + plane_z[:-1]))
    segment_layer = (np.searchsorted(tops, mids, side="right") - 1).astype(np.int64)
    return plane_z, plane_tally, segment_layer, int(plane_tally[0]), np.array(depths)


def optical_depths(plane_z: np.ndarray, segment_layer: np.ndarray, c: np.ndarray) -> np.ndarray:
    """tau = integral of c dz from the surface to each plane (inf below an infinite layer)."""
    with np.errstate(invalid="ignore"):
        steps = np.where(np.isinf(plane_z[1:]), np.inf,
                         c[segment_layer] * (plane_z[1:] - plane_z[:-1]))
    return np.concatenate([[0.0], np.cumsum(steps)])


# the spectral walk's smallest b at one wavelength relative to the layer's largest
B_SPREAD_LIMIT = 1e-12
# below this at every wavelength (1/m) a layer is packed as not scattering
B_FLOOR = 1e-100


def upward_fractions(upward: float | None, albedo: np.ndarray) -> np.ndarray:
    """Scattering biased toward straight up (kernel/upward.py; upward: the scene's fraction,
    weight_window.upward_fraction): a layer's fraction is at most 1 - w0, so that no
    scattering event makes a packet heavier; 0 in a layer leaves it out."""
    fraction = np.minimum(float(upward or 0.0), 1.0 - albedo)
    fraction[albedo <= 0.0] = 0.0
    return fraction


# 1 - w0 below this counts as this in hero_probabilities: no wavelength has more than 1 / this
# times the hero probability of the least scattering one
HERO_LEAST_ABSORBED_FRACTION = 0.01


def hero_probabilities(albedo: np.ndarray, exponent: float) -> np.ndarray:
    """Each wavelength's probability of being a spectral photon's hero (kernel/spectral.py),
    from the top layer's single-scattering albedo w0 (n_wl): in proportion to
    (1 / (1 - w0))^exponent, 1 / (1 - w0) being the collisions a monochromatic walk makes
    there; 1 - w0 is taken as at least HERO_LEAST_ABSORBED_FRACTION. Any positive choice is
    unbiased (one-sample MIS with the balance heuristic); exponent 0 is uniform."""
    collisions = 1.0 / np.maximum(HERO_LEAST_ABSORBED_FRACTION, 1.0 - albedo)
    weight = collisions ** exponent
    return weight / weight.sum()


def settle_paths(layer_c: np.ndarray) -> np.ndarray:
    """Per layer, the free path after which a spectral packet settles whatever its K
    (kernel/spectral.py): the deferred factors exp(-(c_j - c_h) D) stay within
    exp(+-DEFERRED_EXPONENT_BOUND) of 1; inf in a layer of one c at every wavelength."""
    spread = layer_c.max(axis=1) - layer_c.min(axis=1)
    return np.divide(spectral.DEFERRED_EXPONENT_BOUND, spread, out=np.full(len(spread), np.inf),
                     where=spread > 0.0)


def _spectral_checks(config: cfg.SceneConfig, layers: list[optics.LayerIOPs]) -> None:
    """What the one-history spectral walk (kernel/spectral.py) does not carry: one line each."""
    for layer in layers:
        scatters = layer.b > 0.0
        if scatters.any() and not scatters.all():
            raise cfg.ConfigError(
                f"water.layers[{layer.config_layer}].b is 0 at some wavelengths and not at "
                "others: the spectral walk needs a layer to scatter at every wavelength or at "
                "none (give a small b > 0)")
        if scatters.any() and layer.b.min() < B_SPREAD_LIMIT * layer.b.max():
            raise cfg.ConfigError(
                f"water.layers[{layer.config_layer}].b is {layer.b.min():.3g} 1/m at "
                f"{config.wavelengths[int(np.argmin(layer.b))]:g} nm and "
                f"{layer.b.max():.3g} 1/m at another wavelength: the spectral walk needs b "
                f"within a factor {1 / B_SPREAD_LIMIT:.0e} of its largest value at every "
                "wavelength (its ratios of scattering would overflow)")


def scattering_terms(share: np.ndarray, comp_start: list[int], comp_count: list[int],
                     layer_b: np.ndarray, comp_model: list[int], tables: list
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(mix_ptr, mix_comp, mix_at, mix_coef): each wavelength's volume scattering function
    beta_j = b_j sum_k share_jk p_k in layer L as the terms mix_ptr[L] .. mix_ptr[L + 1] - 1,
    each with all wavelengths side by side (kernel/spectral.py reads them in one pass): an
    analytic component k = mix_comp[e] with the row b_j share_jk at mix_coef[mix_at[e]:], or
    all the tables on one angle grid mixed into one, node-major (n_nodes x n_wl) at
    mix_coef[mix_at[e]:] (mix_comp[e]: one of them, for the grid). Tables on a grid mix exactly:
    each is linear between the same nodes. A Case-1 water has two terms: pure water and the
    particles' Fournier-Forand tables of every wavelength."""
    n_wl = share.shape[0]
    ptr, comp, at, parts = [0], [], [], []
    size = 0
    for layer, (first, count) in enumerate(zip(comp_start, comp_count)):
        grids: dict[int, int] = {}      # psi offset -> term index
        for k in range(first, first + count):
            coef = layer_b[layer] * share[:, k]
            if not coef.any():
                continue
            if comp_model[k] != models.PHASE_TABULATED:
                comp.append(k)
                at.append(size)
                parts.append(coef)
                size += n_wl
                continue
            psi_at, q = tables[k]
            if psi_at not in grids:
                grids[psi_at] = len(comp)
                comp.append(k)
                at.append(size)
                parts.append(np.zeros((len(q), n_wl)))
                size += len(q) * n_wl
            parts[grids[psi_at]] += np.outer(q, coef)
        ptr.append(len(comp))
    coefs = np.concatenate([part.ravel() for part in parts]) if parts else np.zeros(0)
    return (np.array(ptr, dtype=np.int64), np.array(comp, dtype=np.int64),
            np.array(at, dtype=np.int64), coefs)


def _emits(transfer: np.ndarray) -> list[int]:
    """The first wavelength a channel emits at and the one after its last."""
    lit = np.nonzero(transfer.max(axis=0) > 0.0)[0]
    return [int(lit[0]), int(lit[-1]) + 1] if len(lit) else [0, 0]


def pack(config: cfg.SceneConfig, ed0: np.ndarray | None = None
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray, Column]:
    """(MEDIUM record, float pool, int pool, Column). Per-layer optics are layer-major, n_wl
    values per layer; optical depths wavelength-major (the local estimates read them); the
    Column's albedo is the largest of each layer's wavelengths' (it caps the upward bias, which
    a spectral walk applies at every wavelength: kernel/upward.py). Collision channels
    (kernel/channels/): elastic scattering, which takes all of b, then the inelastic processes
    of water.inelastic (optics/inelastic/), whose transfer needs the illumination's Ed0 per
    wavelength (computed here if not given)."""
    layers = optics.column_iops(config)
    n_wl = len(config.wavelengths)
    if n_wl > 1:
        _spectral_checks(config, layers)
    comp_start, comp_count, shares, comp_model, comp_params = [], [], [], [], []
    tab_start, tab_len, psi_start, q_parts, cdf_parts, guide_parts = [], [], [], [], [], []
    comp_tables: list = []      # (grid offset, q) of each tabulated component
    tab_offset = 0
    # each distinct table once, known by its content. By id() of its angle array, as before,
    # the pool depended on where tables happened to be allocated: Fournier-Forand's tables
    # leave phase_tables' cache after 64, a re-made one is a new object, and a freed one's
    # address may be taken by another. The deep chlorophyll column packed a table more or
    # less from one build to the next in one process (and 79 against 78 cap tables), and with
    # depth windows the same seed gave other results; the content is the same every time.
    table_at: dict[bytes, tuple[int, int]] = {}
    # each distinct angle grid once (the Fournier-Forand tables of every wavelength share one),
    # so that one search locates an angle in all of a layer's tables (phase/dispatch.py)
    grid_at: dict[bytes, int] = {}
    grid_parts: list[np.ndarray] = []
    grid_offset = 0
    for layer in layers:
        # the components of every phase that scatters at some wavelength; each wavelength
        # weights them by its own shares (a row of zeros for phases it does not use)
        used = [k for k in range(len(layer.phases)) if layer.weights[:, k].max() > 0.0]
        comp_start.append(len(comp_model))
        for k in used:
            for weight, model, params, table in phase_components(layer.phases[k]):
                shares.append(layer.weights[:, k] * weight)
                comp_model.append(model)
                comp_params.append(list(params) + [0.0] * (2 - len(params)))
                if table is None:
                    tab_start.append(0)
                    tab_len.append(0)
                    psi_start.append(0)
                    comp_tables.append(None)
                    continue
                key = hashlib.sha1(np.ascontiguousarray(table[0]).tobytes()
                                   + np.ascontiguousarray(table[1]).tobytes()).digest()
                if key not in table_at:
                    table_at[key] = (tab_offset, len(table[0]))
                    q_parts.append(table[1])
                    cdf_parts.append(table[2])
                    guide_parts.append(phase_tables.guide(table[2]))
                    tab_offset += len(table[0])
                psi_key = np.ascontiguousarray(table[0]).tobytes()
                if psi_key not in grid_at:
                    grid_at[psi_key] = grid_offset
                    grid_parts.append(table[0])
                    grid_offset += len(table[0])
                tab_start.append(table_at[key][0])
                tab_len.append(table_at[key][1])
                psi_start.append(grid_at[psi_key])
                comp_tables.append((grid_at[psi_key], table[1]))
        comp_count.append(len(comp_model) - comp_start[-1])
    # shares within each layer, one row per wavelength; cumulative, the last exactly 1
    share = np.array(shares).T.reshape(n_wl, len(comp_model))
    cumweight = np.empty_like(share)
    for first, count in zip(comp_start, comp_count):
        part = share[:, first:first + count]
        total = part.sum(axis=1, keepdims=True)
        part = np.where(total > 0.0, part / np.where(total > 0.0, total, 1.0), 1.0 / count)
        share[:, first:first + count] = part
        cumweight[:, first:first + count] = np.cumsum(part, axis=1)
        cumweight[:, first + count - 1] = 1.0
    layer_b = np.array([layer.b for layer in layers], dtype=np.float64)       # (n_layers, n_wl)
    # a layer whose b stays below B_FLOOR at every wavelength scatters nothing in any water
    # column (a mean free path of 1e100 m): packed as not scattering, since the spectral
    # walk's ratios of beta (b 1e-308: subnormal) would overflow
    layer_b[layer_b.max(axis=1) < B_FLOOR] = 0.0
    mix_ptr, mix_comp, mix_at, mix_coef = scattering_terms(
        share, comp_start, comp_count, layer_b, comp_model, comp_tables)

    plane_z, plane_tally, segment_layer, surface_level, depths = planes(config, layers)
    windows = weight_window.choose(config, layers)
    upward = weight_window.upward_fraction(config, windows)
    added = weight_window.added_planes(windows, layers, plane_z)
    if added.size:
        plane_z, plane_tally, segment_layer, surface_level, depths = planes(config, layers,
                                                                            added)
    layer_c = np.array([layer.c for layer in layers], dtype=np.float64)       # (n_layers, n_wl)
    albedo_all = np.divide(layer_b, layer_c, out=np.zeros_like(layer_c), where=layer_b > 0.0)
    albedo = albedo_all.max(axis=1)
    plane_tau = np.array([optical_depths(plane_z, segment_layer, layer_c[:, j])
                          for j in range(n_wl)])                             # (n_wl, n_planes)
    level_tau = plane_tau[:, np.searchsorted(plane_z, depths)]              # (n_wl, n_depths)
    fraction = upward_fractions(upward, albedo)
    hero_p = hero_probabilities(albedo_all[0], config.estimator.hero_exponent)
    cone = math.radians(config.estimator.upward_cone_deg)
    up_cos = math.cos(cone)
    up_solid_angle = 4.0 * math.pi * math.sin(cone / 2.0) ** 2  # 2 pi (1 - cos A), no cancelling

    if ed0 is None:
        ed0 = optics.illumination_spectrum(config)[0]
    inelastic = optics.inelastic.channels(config, layers, ed0)
    separable = [optics.inelastic.factors(ch.transfer) for ch in inelastic]
    f, i = Pool(np.float64), Pool(np.int64)
    rec = record(
        MEDIUM, n_planes=len(plane_z), n_layers=len(layers), n_wl=n_wl,
        n_comps=len(comp_model), n_channels=1 + len(inelastic), up_cos=up_cos,
        plane_z=f.add(plane_z), plane_tau=f.add(plane_tau), layer_c=f.add(layer_c),
        layer_inv_c=f.add(np.divide(1.0, layer_c, out=np.zeros_like(layer_c),
                                    where=layer_c > 0.0)),
        layer_albedo=f.add(albedo_all),
        hero_cdf=f.add(np.cumsum(hero_p)), hero_k=f.add(n_wl * hero_p),
        layer_c_over_b=f.add(np.divide(layer_c, layer_b, out=np.zeros_like(layer_c),
                                       where=layer_b > 0.0)),
        layer_settle_path=f.add(settle_paths(layer_c)),
        up_fraction=f.add(fraction),
        up_density=f.add(fraction / up_solid_angle),
        up_keep=f.add(1.0 - fraction), comp_cumweight=f.add(cumweight),
        comp_params=f.add(comp_params),
        tab_psi=f.add(np.concatenate(grid_parts) if grid_parts else np.zeros(0)),
        tab_q=f.add(np.concatenate(q_parts) if q_parts else np.zeros(0)),
        tab_cdf=f.add(np.concatenate(cdf_parts) if cdf_parts else np.zeros(0)),
        plane_tally=i.add(plane_tally), segment_layer=i.add(segment_layer),
        comp_start=i.add(comp_start), comp_count=i.add(comp_count),
        comp_model=i.add(comp_model), comp_tab_start=i.add(tab_start),
        comp_tab_len=i.add(tab_len), comp_psi_start=i.add(psi_start),
        tab_guide=i.add(np.concatenate(guide_parts) if guide_parts else np.zeros(0, np.int64)),
        mix_ptr=i.add(mix_ptr), mix_comp=i.add(mix_comp), mix_at=i.add(mix_at),
        mix_coef=f.add(mix_coef),
        channel_model=i.add([registry.CHANNEL[name][0]
                             for name in ["elastic"] + [ch.name for ch in inelastic]]),
        channel_beta=f.add([0.0] + [ch.phase_beta for ch in inelastic]),
        channel_sigma=f.add([ch.sigma for ch in inelastic]),
        channel_reach=f.add([ch.transfer.sum(axis=1) for ch in inelastic]),
        channel_transfer=f.add([ch.transfer for ch in inelastic]),
        channel_band=i.add([optics.inelastic.band(ch.transfer) for ch in inelastic]),
        channel_emits=i.add([_emits(ch.transfer) for ch in inelastic]),
        channel_separable=i.add([factors is not None for factors in separable]),
        channel_factors=f.add([np.zeros(2 * n_wl) if factors is None else np.concatenate(factors)
                               for factors in separable]))
    column = Column(surface_level, depths, level_tau, albedo, tuple(layers), windows,
                    weight_window.segment_windows(windows, layers, plane_z), upward)
    return rec, f.array(), i.array(), column
