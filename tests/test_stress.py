"""Numerical stress: extreme but legal scenes end, stay finite and conserve energy."""
import math

import numpy as np
import pytest

import oceanmc
from oceanmc.kernel.surface.fresnel import fresnel


def run(scene, photons=20_000, batches=8, seed=3):
    r = oceanmc.simulate(dict(scene, photons=photons, batches=batches, seed=seed))
    for name, q in r.quantities.items():
        assert np.all(np.isfinite(q.batches)), name
    assert r["budget/truncated"] == 0.0
    # the budget adds up to 1 within 4 standard errors (roulette noise), and to 1e-6 at least
    assert abs(r["budget/total"] - 1.0) <= max(4.0 * r.stderr("budget/total"), 1e-9) + 1e-6
    return r


@pytest.mark.parametrize("upward_fraction", [None, 0.5])
def test_nearly_conservative_deep_slab(upward_fraction):
    """w0 = 1 - 1e-9 over optical depth 50: thousands of scatterings per photon; everything
    that is not absorbed (a fraction ~1e-9 x events) is reflected or transmitted. With
    upward-biased scattering the fraction is capped at 1 - w0 = 1e-9: no weight grows."""
    r = run({"illumination": {"sun_zenith_deg": 30},
             "water": {"layers": [{"thickness_m": 50.0, "a": 1e-9, "b": 1.0,
                                   "phase": {"model": "isotropic"}}]},
             "bottom": {"model": "black"}, "tallies": {"depths_m": [0, 25, 50]},
             "estimator": {"upward_fraction": upward_fraction}},
            photons=2000, batches=4)
    assert r["budget/absorbed_layer_1"] < 1e-4
    assert r.attrs["scattering_events"] / r.attrs["photons"] > 100


@pytest.mark.parametrize("n", [1.0, 1.0 + 1e-12, 1.0 + 1e-6])
def test_index_at_and_near_one(n):
    r = run({"illumination": {"sun_zenith_deg": 60, "diffuse_fraction": 0.5},
             "surface": {"model": "flat", "n_water": n},
             "water": {"layers": [{"thickness_m": 2, "a": 0.1, "b": 0.5}]},
             "bottom": {"model": "lambertian", "reflectance": 0.5},
             "tallies": {"depths_m": [0, 2]}})
    assert r["budget/surface_reflection"] < 1e-5


def test_exactly_at_the_critical_angle():
    """At exactly the critical angle the transmitted ray is grazing: R = 1 (or 1 - tiny), never
    NaN, both just below and at it."""
    n = 1.34
    cos_c = math.sqrt(1.0 - 1.0 / n ** 2)
    for cos_i in (cos_c, np.nextafter(cos_c, 1.0), np.nextafter(cos_c, 0.0)):
        r, cos_t = fresnel(n, 1.0, cos_i)
        assert math.isfinite(r) and 0.999 <= r <= 1.0
        assert math.isfinite(cos_t) and 0.0 <= cos_t < 1e-6


def test_very_thick_and_very_many_layers():
    thick = run({"water": {"layers": [{"thickness_m": 1e4, "a": 0.01, "b": 0.02}]},
                 "bottom": {"model": "lambertian", "reflectance": 1.0},
                 "tallies": {"depths_m": [0, 1e4]}})
    assert thick["Ed"][1] == 0.0 or thick["Ed"][1] < 1e-30
    many = run({"water": {"layers": [{"thickness_m": 0.005, "a": 0.05 + 0.01 * (i % 3),
                                      "b": 0.3} for i in range(2000)]},
                "bottom": {"model": "lambertian", "reflectance": 0.3},
                "tallies": {"depths_m": [0, 5, 10]}}, photons=4000, batches=4)
    assert many["Ed"][2] > 0.0
    assert len([k for k in many.quantities if k.startswith("budget/absorbed_layer_")]) == 2000


@pytest.mark.parametrize("k", [20.0, 50.0])
def test_minnaert_sharp_exponent(k):
    """k = 50: the reflected light is concentrated near the normal; rho_dh at the refracted sun
    angle is 2 rho cos^k / (k + 2), tiny but finite."""
    r = run({"illumination": {"sun_zenith_deg": 0},
             "surface": {"model": "none"},
             "water": {"layers": [{"thickness_m": 1e-6, "a": 0.0, "b": 0.0}]},
             "bottom": {"model": "minnaert", "reflectance": 1.0, "k": k},
             "tallies": {"depths_m": [0]}})
    assert r["air/Eu"] == pytest.approx(2.0 / (k + 2.0), rel=1e-9)


def test_grazing_sky_photons_and_total_internal_reflection_trap():
    """A sky of grazing photons (uniform sky includes mu -> 0) over a scattering layer with no
    absorption and a white bottom: light trapped by total internal reflection still leaves in
    the end (everything reflected or water-leaving)."""
    r = run({"illumination": {"diffuse_fraction": 1.0},
             "water": {"layers": [{"thickness_m": 1.0, "a": 0.0, "b": 0.2,
                                   "phase": {"model": "henyey_greenstein", "g": 0.9}}]},
             "bottom": {"model": "lambertian", "reflectance": 1.0},
             "tallies": {"depths_m": [0, 1]}})
    assert r["budget/absorbed_layer_1"] == 0.0
    assert r["budget/absorbed_bottom"] == 0.0
