"""The scene as the compiled code sees it: one narrow record per component, and two flat pools.

Each component (medium, surface, bottom, sky, tally grid, local estimates, estimator) is one
numpy structured scalar of a fixed dtype below, passed to the kernel as a one-row array. Its
scalar fields are read directly; its tables live in the scene's two flat pools, one float64 and
one int64, and the record holds their offsets: a field named like a table (plane_z, layer_c,
...) is the offset of that table in its pool (each record's `floats_at` and `ints_at` name
them). So every scene, whatever its number of layers, tables or tally depths, has the same
types, each compiled function is compiled once, and a function below the photon loop takes the
records it needs and the two pools (MC/DC's records plus one flat data array,
CEMeNT-PSAAP/MCDC). Each packer fills pools of its own with offsets from 0 (Pool); merge()
appends them to the scene's pools and moves the records' offsets with them. Offsets stored
inside a pool are relative to a record's offset (mix_at to mix_coef, comp_tab_start to tab_q,
the BRDF's header to its params), so they move with it.

The packet is a record too (PACKET) with its spectral state in a float row of its own
(packet_state_size: kernel/packet.py); the split stack holds rows of both. One event's
scratch (work_size) is a third row, kept by no packet.

The tallies of one batch are one flat float64 row of scores and nothing else; the GRID record
holds where each score's array starts (flux, radiance, local, cap, budget) and its shape.

Nothing here is compiled: the packers (oceanmc/scene/) fill these, the kernel reads them.
"""
import numpy as np

I8 = np.int64
F8 = np.float64
# each record dtype's offset fields: (into the float pool, into the int pool)
POOL_OFFSETS: dict[np.dtype, tuple[tuple[str, ...], tuple[str, ...]]] = {}


def _record(*fields: str, ints: tuple[str, ...] = (), floats_at: tuple[str, ...] = (),
            ints_at: tuple[str, ...] = ()) -> np.dtype:
    """A record dtype of the scalar fields (int64 if named in ints, else float64) and the
    offsets of its tables in the float pool (floats_at) and the int pool (ints_at). Its scalars
    are np.record (attribute access, also in plain Python under NUMBA_DISABLE_JIT=1); to Numba
    the same type as the plain structured dtype."""
    offsets = set(floats_at) | set(ints_at)
    dtype = np.dtype((np.record, np.dtype(
        [(name, I8 if name in ints or name in offsets else F8)
         for name in fields + floats_at + ints_at], align=True)))
    POOL_OFFSETS[dtype] = (floats_at, ints_at)
    return dtype


# Water column: planes (surface first, then layer boundaries and tally depths, bottom last; z =
# inf below an infinitely deep last layer), the segments between them, the layers, the phase
# function components of each layer and their tables, and the upward bias per layer. The
# per-layer optics hold n_wl values per layer, layer-major (a packet reads layer * n_wl + its
# `wavelength`, the hero wavelength of a spectral walk, kernel/spectral.py, which reads a
# layer's wavelengths in a row).
#   float pool: plane_z (n_planes), plane_tau (n_wl x n_planes); layer_c, layer_inv_c,
#               layer_albedo, layer_c_over_b (n_layers x n_wl); layer_settle_path,
#               up_fraction, up_density, up_keep (n_layers); comp_cumweight (n_wl x n_comps;
#               cumulative within each layer), comp_params (2 each); tab_psi (each distinct
#               angle grid once, at a component's psi_start), tab_q, tab_cdf (each table at
#               its component's tab_start); mix_coef; the inelastic channels 1 ..
#               n_channels - 1 (kernel/channels/inelastic.py): channel_beta (n_channels: the
#               emission's phase function (1 + beta cos^2), 0 isotropic), channel_sigma
#               ((n_channels - 1) x n_layers x n_wl: what each takes per unit weight and
#               length), channel_reach ((n_channels - 1) x n_wl: the row sums of its
#               transfer), channel_transfer ((n_channels - 1) x n_wl x n_wl, excitation-major),
#               channel_factors ((n_channels - 1) x 2 x n_wl: a then b of a separable
#               transfer, T_ji = a_j b_i; zeros for one that is not)
#               hero_cdf (n_wl: the cumulative probabilities of each wavelength being a
#               spectral photon's hero), hero_k (n_wl: n_wl times them, a new photon's K;
#               kernel/spectral.py)
#   int pool:   plane_tally (n_planes; -1: no tally level), segment_layer (n_planes - 1);
#               comp_start, comp_count (n_layers); comp_model, comp_tab_start, comp_tab_len,
#               comp_psi_start (n_comps); tab_guide (each table's guide for sampling, at its
#               tab_start, as long as the table: phase/tabulated.py); mix_ptr (n_layers + 1),
#               mix_comp, mix_at: the terms of each layer's volume scattering functions, all
#               wavelengths side by side (scene/medium.py scattering_terms, kernel/spectral.py);
#               channel_model (n_channels: registry.CHANNEL ids; channel 0 is elastic);
#               channel_band ((n_channels - 1) x n_wl x 2: each excitation row's emission
#               columns first .. last - 1), channel_emits ((n_channels - 1) x 2: the columns
#               any row emits into), channel_separable ((n_channels - 1): 1 where the
#               transfer is separable, optics/inelastic factors)
MEDIUM = _record(
    "n_planes", "n_layers", "n_wl", "n_comps", "n_channels", "up_cos",
    ints=("n_planes", "n_layers", "n_wl", "n_comps", "n_channels"),
    floats_at=("plane_z", "plane_tau", "layer_c", "layer_inv_c", "layer_albedo",
               "layer_c_over_b", "layer_settle_path", "up_fraction", "up_density", "up_keep",
               "comp_cumweight", "comp_params", "tab_psi", "tab_q", "tab_cdf", "mix_coef",
               "channel_beta", "channel_sigma", "channel_reach", "channel_transfer",
               "channel_factors", "hero_cdf", "hero_k"),
    ints_at=("plane_tally", "segment_layer", "comp_start", "comp_count", "comp_model",
             "comp_tab_start", "comp_tab_len", "comp_psi_start", "tab_guide", "mix_ptr",
             "mix_comp", "mix_at", "channel_model", "channel_band", "channel_emits",
             "channel_separable"))

# The air-water surface (kernel/surface/): model id and its parameters.
# delta: a delta BSDF (flat, none; split() applies); alpha_u, alpha_c: the facets' Beckmann
# roughness along the wind and across it (alpha^2 = 2 x slope variance); wind_cos, wind_sin:
# the wind's azimuth (cox_munk.py); tabulated: the rough surface is sampled from its table
# (cox_munk_table.py: TABLE_SIZE floats at `table` in the float pool), else by its facet walk
SURFACE = _record("model", "n_water", "schlick", "delta", "alpha_u", "alpha_c", "wind_cos",
                  "wind_sin", "tabulated", ints=("model", "schlick", "delta", "tabulated"),
                  floats_at=("table",))

# The bottom (kernel/brdf/): model id; params: its parameters (scene/brdf_tables.py layout,
# whose offsets are relative to params) in the float pool.
BOTTOM = _record("model", "reflects", "mirror", ints=("model", "reflects", "mirror"),
                 floats_at=("params",))

# Sun and sky (kernel/sources.py).
#   float pool: s_edges (n_rows + 1; sin^2 of the view zenith), phi_edges (n_cols + 1; rad),
#               row_cdf (n_rows), cell_cdf and cell_l (n_rows x n_cols, row-major), params (8)
SKY = _record(
    "sun_mu", "sun_sin", "diffuse_fraction", "model", "n_rows", "n_cols",
    ints=("model", "n_rows", "n_cols"),
    floats_at=("s_edges", "phi_edges", "row_cdf", "cell_cdf", "cell_l", "params"))

# Tally grid and the layout of one batch's tally row (kernel/tally.py).
#   levels: the in-water tally depths (n_depths), then air (0+, all light), then air_leaving
#   (0+, water-leaving light only).
#   float pool: theta_mu_edges (n_theta + 1, falling from 1 to -1), phi_edge_cos,
#               phi_edge_sin (n_phi), level_z (n_depths), level_tau (n_depths x n_wl:
#               a level's wavelengths side by side, which the cap scores read as one
#               contiguous row),
#               source_q (2 x n_wl: sun, sky), bottom_q (2 x n_wl: every lobe, a
#               lambertian_specular bottom's mirror lobe) (kernel/spectral.py)
#   int pool:   theta_lookup (n_lookup), theta_is_cap (n_theta)
#   tally row:  the local estimates' scores, local ((n_depths + 1) x n_dirs x n_wl) and cap
#               ((n_depths + 1) x n_wl); then, from `scores` on, flux (n_levels x 4),
#               radiance (n_levels x n_theta_cols x n_phi_cols), budget (n_budget), each
#               score with its n_wl wavelengths side by side: the offsets below are those of
#               one wavelength's layout, and the score at offset i of wavelength j lies at
#               scores + (i - scores) n_wl + j (tally.py spectral_at: the same address when
#               n_wl = 1). That is one part, `part_size` long; the row holds n_parts of them, one
#               per collision channel: the elastic light's, then each inelastic process's
#               (the light it emitted; kernel/channels/inelastic.py)
GRID = _record(
    "n_wl", "n_parts", "scores", "n_depths", "air_level", "surface_level", "mu_cut", "radiance_on",
    "n_theta", "n_phi", "n_lookup", "theta_cols", "phi_cols",
    "flux", "radiance", "local", "cap", "budget", "n_dirs", "n_budget", "part_size",
    ints=("n_wl", "n_parts", "scores", "n_depths", "air_level", "surface_level", "radiance_on", "n_theta",
          "n_phi", "n_lookup", "theta_cols", "phi_cols", "flux", "radiance", "local", "cap",
          "budget", "n_dirs", "n_budget", "part_size"),
    floats_at=("source_q", "bottom_q", "theta_mu_edges", "phi_edge_cos", "phi_edge_sin",
               "level_z", "level_tau"),
    ints_at=("theta_lookup", "theta_is_cap"))

# Local (next-event) estimates (kernel/local_estimate.py): exact upward directions, and the
# nadir polar-cap average (tables from scene/estimates.py).
#   float pool: dirs (n_dirs x 3), air_factor (n_dirs), cap_m0w, cap_m1w, cap_m0a, cap_m1a
#               (n_tables x n_alpha x n_wl each; a table holds all wavelengths of a layer;
#               after the layers' tables, one per inelastic channel's emission, from
#               emission_tables on),
#               level_decay (n_depths x n_wl, as level_tau)
#   int pool:   in_water (n_dirs), table_of_layer (n_layers)
ESTIMATES = _record(
    "directions_on", "cap_on", "n_dirs", "n_alpha",
    "fine_end", "fine_step", "coarse_step", "fine_nodes",
    "mu_w", "omega_w", "cos_water", "mu_a", "omega_a", "cos_air", "h", "dh",
    "emission_tables",
    ints=("directions_on", "cap_on", "n_dirs", "n_alpha", "fine_nodes", "emission_tables"),
    floats_at=("dirs", "air_factor", "cap_m0w", "cap_m1w", "cap_m0a", "cap_m1a", "level_decay"),
    ints_at=("in_water", "table_of_layer"))

# How weights evolve (kernel/transport.py), one row per segment of the water column (between
# its planes, MEDIUM plane_z): the rows differ only where depth windows change them
# (kernel/weight_window.py, scene/weight_window.py).
# emission_weight: the least weight of a packet an inelastic process emits (lighter emissions
# play roulette up to it); carry_emissions: the packet that emits light carries it on
# (kernel/channels/inelastic.py); depth_windows: packets are split on entering a segment whose
# window weight `window` they exceed (never with inelastic light); roulette_weight: the
# roulette threshold at collisions in the segment (the configured one times the window)
ESTIMATOR = _record("analog", "roulette_weight", "roulette_survival", "max_events",
                    "split_weight", "splitting", "upward", "emission_weight", "carry_emissions",
                    "depth_windows", "window",
                    ints=("analog", "max_events", "splitting", "upward", "carry_emissions",
                          "depth_windows"))

# A photon packet: position (depth z and the segment it is in or on), weight, direction of
# travel, whether it still belongs to the collimated solar beam, its wavelength's index (in
# a spectral walk, the hero's, and the reference wavelength's: kernel/spectral.py scatter),
# and the part of the tally row it scores in (0: elastic light; k: light that channel k
# emitted, kernel/channels/inelastic.py).
PACKET = _record("z", "w", "ux", "uy", "uz", "seg", "beam", "wavelength", "reference", "part",
                 ints=("seg", "beam", "wavelength", "reference", "part"))

# Rows on the stack of one batch: split copies and emitted packets (kernel/transport.py)
SPLIT_STACK_ROWS = 64


def packet_state_size(n_wl: int, n_parts: int = 1) -> int:
    """Floats of a packet's spectral state (kernel/spectral.py state: K, G and F at the last
    settle, n_wl each, then the free path D since it; with inelastic processes, n_parts > 1,
    then each part's share of the packet's light at each wavelength, n_parts x n_wl:
    kernel/packet.py); one wavelength keeps none, but the row is never empty."""
    if n_wl == 1:
        return 1
    return 3 * n_wl + 1 + (n_parts * n_wl if n_parts > 1 else 0)


def work_size(n_wl: int, n_parts: int = 1) -> int:
    """Floats of one event's scratch: a collision's volume scattering function at every
    wavelength (kernel/spectral.py), then a local estimate's weight, optical depth and phase
    function at every wavelength (kernel/local_estimate.py). An inelastic emission's weights
    per unit coefficient and what it takes use the first and second of these rows, and an
    emission that starts a packet of its own the fourth (the third holds the collision point's
    optical depths, which its local estimates read: local_estimate.collision_depths); what each
    inelastic process emits at a collision for the packet to carry on is made in one more row
    each, where it waits until the packet has turned (kernel/channels/inelastic.py); last, the
    event's cap transmissions, to the level above and to 0+, and what the first cap score at
    the point found (CAP_POINT_FLOATS; local_estimate.cap_transmissions), a cap score's values
    and the transmissions it carries up (local_estimate.cap_scratch), and, with inelastic
    light, the hero's posterior at a collision (spectral.posterior_at)."""
    return (8 if n_parts == 1 else 8 + n_parts) * n_wl + CAP_POINT_FLOATS


# the floats after a point's cap transmissions in the scratch row: whether the point's cap
# scores are set up, its alpha node, the fraction to the next, the levels above it and the cap
# roulette's factor (local_estimate.cap_transmissions)
CAP_POINT_FLOATS = 5


def record(dtype: np.dtype, **values) -> np.ndarray:
    """A one-row array of the record dtype with the given fields (the rest 0); every field of
    the dtype must be named, so a packer cannot forget one."""
    missing = set(dtype.names) - set(values)
    unknown = set(values) - set(dtype.names)
    if missing or unknown:
        raise ValueError(f"record fields missing {sorted(missing)}, unknown {sorted(unknown)}")
    out = np.zeros(1, dtype=dtype)
    for name, value in values.items():
        out[name][0] = value
    return out


class Pool:
    """A flat pool being filled: add(array) appends it and returns its offset."""

    def __init__(self, dtype) -> None:
        self.dtype = dtype
        self.parts: list[np.ndarray] = []
        self.size = 0

    def add(self, values) -> int:
        values = np.ascontiguousarray(values, dtype=self.dtype).ravel()
        offset = self.size
        self.parts.append(values)
        self.size += values.size
        return offset

    def array(self) -> np.ndarray:
        """The pool (one element at least, so that an empty pool is still an array)."""
        if not self.parts:
            return np.zeros(1, dtype=self.dtype)
        return np.concatenate(self.parts + [np.zeros(1, dtype=self.dtype)])


def merge(parts: list[tuple[np.ndarray, np.ndarray, np.ndarray]]
          ) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The scene's records, float pool and int pool from each component's (record, float pool,
    int pool), whose offsets count from 0: each component's pools are appended in turn and its
    record's offsets (POOL_OFFSETS) moved by where they start."""
    floats, ints = Pool(F8), Pool(I8)
    records = []
    for rec, part_floats, part_ints in parts:
        rec = rec.copy()
        float_base = floats.add(part_floats)
        int_base = ints.add(part_ints)
        floats_at, ints_at = POOL_OFFSETS[rec.dtype]
        for name in floats_at:
            rec[name] += float_base
        for name in ints_at:
            rec[name] += int_base
        records.append(rec)
    return records, floats.array(), ints.array()
