"""SceneArrays: the whole scene as the kernel sees it, numpy arrays and scalars only.

Planes are the z levels where something happens (the surface at index 0, layer boundaries, tally
depths, the bottom last; z = inf when the water is infinitely deep). Segment i lies between
plane i and plane i + 1 and belongs to water layer segment_layer[i].
"""
from collections import namedtuple

SceneArrays = namedtuple("SceneArrays", [
    # illumination
    "sun_mu", "sun_sin", "diffuse_fraction", "sky_model",
    # surface
    "surface_flat", "n_water", "fresnel_schlick",
    # geometry and water
    "plane_z", "plane_tally", "segment_layer",
    # per layer: extinction c = a + b, 1/c (0 when c = 0) and the single-scattering albedo b/c
    "layer_c", "layer_inv_c", "layer_albedo",
    # phase functions: a layer's components layer_comp_start .. + layer_comp_count
    "layer_comp_start", "layer_comp_count", "comp_cumweight", "comp_model", "comp_params",
    "comp_tab_start", "comp_tab_len", "tab_psi", "tab_q", "tab_cdf",
    # bottom
    "bottom_model", "bottom_params",
    # tallies
    "theta_mu_edges", "theta_lookup", "theta_is_cap", "n_phi", "phi_edge_cos", "phi_edge_sin", "tally_radiance", "surface_tally", "air_level",
    "mu_cut", "level_z", "level_tau", "plane_tau",
    # local estimates: upward in-water directions (n, 3), t/n^2 for each at 0+
    "local_estimates", "le_dirs", "le_water", "le_air_factor",
    # local estimates of the nadir polar-cap radiance (cap_tables.py): M0, M1 tables per
    # distinct layer phase function on a two-piece uniform alpha grid
    "cap_estimates", "cap_table_of_layer", "cap_m0w", "cap_m1w", "cap_m0a", "cap_m1a",
    "cap_fine_end", "cap_fine_step", "cap_coarse_step", "cap_fine_nodes",
    "cap_mu_w", "cap_omega_w", "cap_level_decay", "cap_cos_water", "cap_mu_a", "cap_omega_a",
    "cap_cos_air",
    "cap_h", "cap_dh",
    # estimator
    "analog", "roulette_weight", "roulette_survival", "max_events", "split_weight",
    # scattering biased toward straight up (kernel/upward.py): per layer the fraction f of
    # events that draw from the cone, f / (the cone's solid angle) and 1 - f; cos(half-angle)
    "layer_up_fraction", "layer_up_density", "layer_up_keep", "up_cos",
    # tabulated skies (sky_maps.py): cell edges in sin^2(theta_view) and phi_view (rad), the
    # marginal CDF over rows, conditional CDFs within rows, cell radiances, sky parameters
    "sky_s_edges", "sky_phi_edges", "sky_row_cdf", "sky_cell_cdf", "sky_cell_L", "sky_params",
])
