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
    "plane_z", "plane_tally", "segment_layer", "layer_a", "layer_b",
    # phase functions: a layer's components layer_comp_start .. + layer_comp_count
    "layer_comp_start", "layer_comp_count", "comp_cumweight", "comp_model", "comp_params",
    "comp_tab_start", "comp_tab_len", "tab_psi", "tab_q", "tab_cdf",
    # bottom
    "bottom_model", "bottom_params",
    # tallies
    "theta_mu_edges", "theta_is_cap", "n_phi", "tally_radiance", "surface_tally", "air_level",
    "mu_cut", "level_z", "level_tau", "plane_tau",
    # local estimates: upward in-water directions (n, 3), t/n^2 for each at 0+
    "local_estimates", "le_dirs", "le_water", "le_air_factor",
    # estimator
    "analog", "roulette_weight", "roulette_survival", "max_events",
])
