"""The fast angular binning of the tallies (lookup table for theta, polynomial guess plus exact
edge tests for phi) agrees with the plain binary search and atan2 everywhere but on the edges
themselves."""
import math

import numpy as np
import pytest

import oceanmc
from oceanmc import scene
from oceanmc.kernel.tally import phi_band, phi_band_fast, theta_band, theta_band_fast


def _scene(**tallies):
    config = oceanmc.load_config({"water": {"layers": [{"thickness_m": 1, "a": 0.1, "b": 0.1}]},
                                  "bottom": {"model": "black"}, "tallies": tallies})
    return scene.build(config)


@pytest.mark.parametrize("edges", ["hydrolight", [0, 1e-3, 2e-3, 90, 179.999, 180],
                                   [0, 48.27, 90, 180], list(np.linspace(0, 180, 181))])
def test_theta_lookup_matches_binary_search(edges):
    sc = _scene(theta_edges_deg=edges)
    grid = sc.grid[0]
    rng = np.random.default_rng(1)
    mu = sc.floats[grid["theta_mu_edges"]:grid["theta_mu_edges"] + grid["n_theta"] + 1]
    uz = np.clip(np.concatenate([rng.uniform(-1, 1, 50_000), mu, np.nextafter(mu, 2),
                                 np.nextafter(mu, -2)]), -1.0, 1.0)
    for u in uz:
        assert theta_band_fast(grid, sc.floats, sc.ints, u) == theta_band(u, mu), u


@pytest.mark.parametrize("n", [1, 2, 3, 24, 360])
def test_phi_bins_match_atan2_off_the_edges(n):
    sc = _scene(phi_bands=n)
    rng = np.random.default_rng(n)
    edges = np.radians(sc.angles.phi_edges)
    angles = np.concatenate([rng.uniform(-math.pi, math.pi, 30_000), edges + 1e-9,
                             edges - 1e-9, [0.0, math.pi / 2, math.pi, -math.pi / 2]])
    for a, r in zip(angles, rng.uniform(1e-3, 1.0, angles.size)):
        ux, uy = r * math.cos(a), r * math.sin(a)
        assert phi_band_fast(sc.grid[0], sc.floats, ux, uy) == phi_band(ux, uy, n), a
