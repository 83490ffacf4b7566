"""Depth profiles: the sublayers' optical depth against the continuous profile (the stated
bound), exact means, and transport through a profile against the exact attenuation."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

import oceanmc
from oceanmc import optics
from oceanmc.optics.column import OPTICAL_DEPTH_TOLERANCE

DCM = {"profile": "gaussian", "background": 0.1, "peak_depth_m": 25.0, "width_m": 6.0,
       "total_mg_m2": 40.0}


def chl(z):
    return 0.1 + 40.0 / (6.0 * math.sqrt(2 * math.pi)) * math.exp(-0.5 * ((z - 25.0) / 6.0) ** 2)


def attenuation(z, wl):
    """c(z) of pure water + chlorophyll from the published formulas (Pope & Fry 1997 a_w at
    440 and 550 nm as printed, Morel 1974 b_w, Bricaud et al. 1998 A_phi, E_phi rows as printed,
    Morel & Maritorena 2001 b_p), independent of oceanmc.optics."""
    a_w = {440.0: 0.00635, 550.0: 0.0565}[wl]
    a_coef, e_coef = {440.0: (0.037824, 0.626633), 550.0: (0.00702755, 0.9311673)}[wl]
    c = chl(z)
    return (a_w + 0.00288 * (wl / 500.0) ** -4.32 + a_coef * c ** e_coef
            + 0.416 * c ** 0.766 * 550.0 / wl)


def test_bricaud_rows_used_above_are_the_shipped_ones():
    from oceanmc.optics.tables import packaged
    table = packaged("chlorophyll_absorption_bricaud_1998.csv")
    row = int(np.searchsorted(table["wavelength_nm"], 550.0))
    assert (table["A_phi"][row], table["E_phi"][row]) == (0.00702755, 0.9311673)


def test_sublayer_optical_depth_within_the_stated_bound():
    config = oceanmc.load_config({"wavelengths_nm": [440, 550], "water": {"layers": [
        {"thickness_m": 60.0, "components": [{"model": "pure_water"},
                                             {"model": "chlorophyll", "chl_mg_m3": DCM}]},
        {"thickness_m": math.inf, "a": 0.1, "b": 0.1}]}, "bottom": {"model": "none"}})
    layers = optics.column_iops(config)[:-1]
    tops = np.array([s.top_m for s in layers] + [60.0])
    assert 10 < len(layers) < 400
    for k, wl in enumerate((440.0, 550.0)):
        tau_layered = np.concatenate([[0.0], np.cumsum([s.c[k] * s.thickness_m
                                                        for s in layers])])
        worst = 0.0
        for i, s in enumerate(layers):
            for z in np.linspace(s.top_m, s.top_m + s.thickness_m, 7):
                exact = quad(attenuation, 0.0, z, args=(wl,), epsabs=1e-12, limit=200)[0]
                layered = tau_layered[i] + s.c[k] * (z - s.top_m)
                worst = max(worst, abs(exact - layered))
        # within a sublayer at most the tolerance; chlorophyll's Chl^E nonlinearity makes the
        # sublayer's mean-amount c differ slightly from the mean c, which may add up over the
        # sublayers: bounded here by 10x the per-sublayer tolerance over 60 m
        assert worst < 10 * OPTICAL_DEPTH_TOLERANCE, (wl, worst)
        assert tau_layered[-1] == pytest.approx(quad(attenuation, 0, 60, args=(wl,),
                                                     limit=200)[0], rel=2e-3)
        assert tops[-1] == 60.0


def test_gaussian_mean_is_exact_and_the_tail_is_its_background():
    from oceanmc.optics import profiles
    from oceanmc.config import GaussianProfile
    g = GaussianProfile(profile="gaussian", background=0.1, peak_depth_m=25.0, width_m=6.0,
                        total_mg_m2=40.0)
    assert profiles.mean(g, 10.0, 30.0, "x") == pytest.approx(
        quad(chl, 10.0, 30.0)[0] / 20.0, rel=1e-12)
    # integral is the whole gaussian's: the part above the surface (z < 0) is not in the water
    in_water = 20.0 * (1.0 + math.erf(25.0 / (6.0 * math.sqrt(2.0))))
    assert profiles.mean(g, 0.0, 1000.0, "x") == pytest.approx(0.1 + in_water / 1000.0,
                                                               rel=1e-12)


def test_transport_through_an_absorbing_profile_matches_exact_attenuation():
    """No scattering (b = 0), no surface, sun at zenith: Ed(z) = exp(-integral of a) exactly;
    the run through the sublayers must give it to rounding."""
    config = oceanmc.load_config({
        "photons": 2000, "batches": 4, "wavelengths_nm": [500],
        "illumination": {"sun_zenith_deg": 0.0}, "surface": {"model": "none"},
        "tallies": {"depths_m": [0.0, 3.0, 7.5, 12.0], "radiance": False},
        "water": {"layers": [{"thickness_m": 12.0, "components": [
            {"model": "constant", "a": 0.2, "b": 0.0, "concentration": {
                "profile": "linear", "depths_m": [0.0, 4.0, 12.0], "values": [0.5, 3.0, 1.0]}}]}]},
        "bottom": {"model": "black"}})
    result = oceanmc.simulate(config)

    def a(z):
        return 0.2 * np.interp(z, [0.0, 4.0, 12.0], [0.5, 3.0, 1.0])

    exact = [math.exp(-quad(a, 0.0, z, points=[4.0])[0]) for z in (0.0, 3.0, 7.5, 12.0)]
    assert result["Ed"] == pytest.approx(exact, rel=1e-9)
    # the absorbed fraction is reported for the configured layer, not per sublayer
    assert result["budget/absorbed_layer_1"] == pytest.approx(1.0 - exact[-1], rel=1e-9)
    assert "budget/absorbed_layer_2" not in result
    assert result.iops["c"].shape == (len(result.iops["layer_top"]), 1)
