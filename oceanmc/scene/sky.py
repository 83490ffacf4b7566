"""The sun and sky packer: the SKY record and its pool (kernel/records.py) from the
illumination config; the sky shapes and maps are read and tabulated by sky_maps.py."""
from __future__ import annotations

import math

import numpy as np

from .. import config as cfg
from .. import registry
from ..kernel import models
from ..kernel.records import SKY, Pool, record
from . import sky_maps


def pack(ill: cfg.Illumination) -> tuple[np.ndarray, np.ndarray]:
    """(SKY record, float pool). Analytic shapes need no tables; Harrison-Coombes and maps are
    sampled from their cell tables (sky_maps.sampling_tables)."""
    sky = ill.sky
    theta_s = math.radians(ill.sun_zenith_deg)
    if isinstance(sky, str) and sky != "harrison_coombes":
        model = registry.SKY[sky]
        tables = {"s_edges": np.zeros(2), "phi_edges": np.zeros(2), "row_cdf": np.ones(1),
                  "cell_cdf": np.ones((1, 1)), "cell_l": np.ones((1, 1))}
        params = np.zeros(8)
    else:
        if isinstance(sky, str):
            theta, phi, L = sky_maps.harrison_coombes_cells(ill.sun_zenith_deg)
            model = registry.SKY[sky]
        else:
            theta, phi, L = sky_maps.read_sky_map(sky.map, sky.dataset, sky.layout)
            # only the map's shape matters (the sky is scaled to Ed0's diffuse part): relative
            # to its brightest cell, so that sums over a map near 1.7e308 cannot overflow
            L = L / L.max()
            model = registry.SKY_MAP[sky.sampling]
        tables = sky_maps.sampling_tables(theta, phi, L)
        if model == models.SKY_MAP_COSINE:
            # the cosine sampler uses only the edges; the cells hold its photon weights
            tables["cell_l"] = sky_maps.cosine_weights(tables["s_edges"], tables["phi_edges"], L)
        params = sky_maps.sky_parameters(ill.sun_zenith_deg)
    pool = Pool(np.float64)
    offsets = {name: pool.add(values) for name, values in tables.items()}
    rec = record(SKY, sun_mu=math.cos(theta_s), sun_sin=math.sin(theta_s),
                 diffuse_fraction=float(ill.diffuse_fraction), model=model,
                 n_rows=tables["cell_l"].shape[0], n_cols=tables["cell_l"].shape[1],
                 params=pool.add(params), **offsets)
    return rec, pool.array()
