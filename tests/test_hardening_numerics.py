"""Narrow angular bands: their solid angles (cos a - cos b) computed without cancelling, and bands
narrower than float64 resolves refused in one line, sky maps near the largest float (issue 13)."""
import math

import numpy as np

import pytest

import oceanmc
from oceanmc.config.base import ConfigError
from oceanmc.scene.grid import make_grid

BASE = {"water": {"layers": [{"thickness_m": 1.0, "a": 0.1, "b": 0.4,
                              "phase": {"model": "henyey_greenstein", "g": 0.9}}]},
        "bottom": {"model": "black"}}


def one_minus_cos_series(x):
    """1 - cos x by its Taylor series (exact to float64 for x < 1e-2)."""
    return x * x / 2.0 - x ** 4 / 24.0 + x ** 6 / 720.0


def test_narrow_polar_band_solid_angle_is_exact():
    edges = [0.0, 0.01, 90.0, 179.99, 180.0]
    config = oceanmc.load_config({**BASE, "tallies": {"theta_edges_deg": edges}})
    omega = make_grid(config.tallies).solid_angle
    cap = 2.0 * math.pi * one_minus_cos_series(math.radians(0.01))
    assert omega[0, 0] == pytest.approx(cap, rel=1e-12)
    assert omega[-1, 0] == pytest.approx(cap, rel=1e-12)
    assert omega[1:-1].sum() + omega[0, 0] + omega[-1, 0] == pytest.approx(4.0 * math.pi)


def test_band_too_narrow_for_float64_is_refused():
    with pytest.raises(ConfigError, match=r"theta_edges_deg.*at least 0\.001 deg"):
        oceanmc.load_config({**BASE, "tallies": {"theta_edges_deg": [0.0, 90.0, 180 - 1e-6,
                                                                     180.0]}})


def test_sky_map_near_the_largest_float_reads_as_its_shape(tmp_path):
    """A sky map of values near 1.7e308 packs into the same sky record and tables as the same map
    near 1: only the map's shape matters, and sums over the map must not overflow."""
    import warnings

    from oceanmc.scene import sky

    shape = 1.0 + np.arange(90 * 36, dtype=float).reshape(90, 36) / (90 * 36)
    packed = []
    for scale in (1.0, 1.7e308 / shape.max()):
        np.save(tmp_path / f"sky{len(packed)}.npy", shape * scale)
        config = oceanmc.load_config({**BASE, "illumination": {
            "diffuse_fraction": 1.0, "sky": {"map": str(tmp_path / f"sky{len(packed)}.npy")}}})
        with warnings.catch_warnings():
            warnings.simplefilter("error")   # an overflow warning fails the test
            packed.append(sky.pack(config.illumination))
    (rec0, pool0), (rec1, pool1) = packed
    assert rec0.tolist() == rec1.tolist()
    np.testing.assert_allclose(pool1, pool0, rtol=1e-12)
