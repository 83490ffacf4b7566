"""Tests of the independent water-Raman reference (oceanmc/validation/raman_reference.py).

The module is loaded from its file, not through the oceanmc package, so that these tests share
no code with the kernel and keep running while the kernel changes (importing
oceanmc.validation would import the cases and the numba kernel).

Scene of the Monte Carlo comparisons: one layer 0 <= z <= 2 m, a(l) = 0.02 + 1e-4 (l - 450) 1/m,
no elastic scattering, E0 = 1 W m^-2 nm^-1, emission bands 450..600 nm every 25 nm, 2 nm bins,
excitation 300..520 nm (covers the first Raman order of every band, 375..520 nm, and the
second order of all of them). Bounds: |z| < 4 per band and quantity (with 7 bands x 3
quantities, a correct code exceeds 4 with probability ~1e-3); seeds are fixed.
"""
from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate

_PATH = Path(__file__).resolve().parents[1] / "oceanmc" / "validation" / "raman_reference.py"
_spec = importlib.util.spec_from_file_location("raman_reference_standalone", _PATH)
rr = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(rr)

DEPTH = 2.0
BANDS = np.arange(450.0, 601.0, 25.0)
EXCITATION = (300.0, 520.0)
Z_MAX = 4.0


def absorption(lam):
    """Clear-water-like absorption with a small slope (1/m)."""
    return 0.02 + 1e-4 * (np.asarray(lam) - 450.0)


def _z(mc, ref):
    mean, se = mc
    return (mean - ref) / se


def test_walrafen_redistribution_integrates_to_one():
    # integral over emission wavelength of f(l' -> l) = 1: photons are conserved (to 1e-4)
    lp = np.array([300.0, 350.0, 400.0, 488.0, 550.0, 700.0])
    np.testing.assert_allclose(rr.raman_emission_photons(lp), 1.0, atol=1e-4)
    # g itself over dk, by an independent rule (trapezoid on 1/cm steps)
    dk = np.arange(1500.0, 6000.0, 1.0)
    assert abs(integrate.trapezoid(rr.walrafen_g(dk), x=dk) - 1.0) < 1e-6
    # the phase function integrates to 1 over 4 pi; 0.067 (1 + 0.55 cos^2) per sr
    x = np.linspace(-1, 1, 2001)
    assert abs(2 * math.pi * integrate.simpson(rr.raman_phase(x), x=x) - 1.0) < 1e-10
    assert abs(rr.raman_phase(0.0) - 0.067) < 5e-4


def test_cos_psi_sampling_follows_phase_function():
    beta = 0.55
    u = np.linspace(0.0, 1.0, 101)
    x = rr.sample_raman_cos(u, beta)
    cdf = (x + 1 + beta * (x ** 3 + 1) / 3) / (2 + 2 * beta / 3)
    assert np.abs(cdf - u).max() < 1e-12                       # exact inverse CDF
    x = rr.sample_raman_cos(np.random.default_rng(7).uniform(size=1_000_000), beta)
    m2 = (1 / 3 + beta / 5) / (1 + beta / 3)                     # <cos^2 psi> of 1 + beta cos^2
    assert abs(x.mean()) < 4 * math.sqrt(m2 / x.size)
    assert abs((x ** 2).mean() - m2) < 4 * (x ** 2).std() / math.sqrt(x.size)


def test_single_scattering_quadrature_converged():
    # the default l' step (0.05 nm) and mu nodes against a 5x finer l' step and 3x more nodes
    kw = dict(b488=2.6e-2)
    coarse = rr.single_scattering(BANDS, DEPTH, absorption, **kw)
    fine = rr.single_scattering(BANDS, DEPTH, absorption, step_nm=0.01, mu_nodes=72, **kw)
    for key in coarse:
        np.testing.assert_allclose(coarse[key], fine[key], rtol=1e-8)
    # thin-layer limit: half the once-Raman light goes up, half down
    eu, ed = coarse["Eu_top"], coarse["Ed_bottom"]
    assert np.all(np.abs(eu / ed - 1) < 0.05)


def test_once_raman_walk_matches_single_scattering():
    """b488 = 2.6e-2 (100x the default) makes Raman light abundant (b_R d ~ 0.05..0.16 over
    the excitation band). The walk's once-Raman tallies are exactly what single_scattering()
    computes (no approximation), so all three quantities are compared in every band; the second
    and higher orders are tallied apart ("_multi") and are NOT small here."""
    kw = dict(b488=2.6e-2)
    ref = rr.single_scattering(BANDS, DEPTH, absorption, **kw)
    mc = rr.reference_walk(BANDS, DEPTH, absorption, excitation_range_nm=EXCITATION,
                           photons=10_000_000, seed=11, **kw)
    for key in ("Eu_top", "Ed_bottom", "Eou_top"):
        z = _z(mc[key + "_once"], ref[key])
        assert np.all(np.abs(z) < Z_MAX), (key, np.round(z, 2))
        assert np.all(mc[key + "_once"][1] < 0.15 * ref[key])   # the test has power
        np.testing.assert_allclose(mc[key + "_once"][0] + mc[key + "_multi"][0], mc[key][0],
                                   rtol=1e-12)
    # photon budget closes photon by photon
    b = mc["budget"]
    out = sum(b[k][0] for k in rr.BUDGET_KEYS if k != "incident")
    assert abs(out / b["incident"][0] - 1) < 1e-12


def test_grazing_rule_and_overlapping_bins():
    """Eou with the grazing rule (2/mu_cut below mu_cut = 0.05) against single_scattering() with
    the same mu_cut (that estimator's exact expectation), |z| < 4; the rule changes the value
    measurably. Overlapping bins (the slow path) score like separate runs."""
    kw = dict(b488=2.6e-2, excitation_range_nm=EXCITATION, photons=4_000_000, seed=2)
    ref = rr.single_scattering(BANDS, DEPTH, absorption, b488=2.6e-2, mu_cut=0.05)
    plain = rr.single_scattering(BANDS, DEPTH, absorption, b488=2.6e-2)
    assert np.all(np.abs(ref["Eou_top"] / plain["Eou_top"] - 1) > 1e-3)
    np.testing.assert_allclose(ref["Eu_top"], plain["Eu_top"], rtol=1e-12)
    mc = rr.reference_walk(BANDS, DEPTH, absorption, mu_cut=0.05, **kw)
    z = _z(mc["Eou_top_once"], ref["Eou_top"])
    assert np.all(np.abs(z) < Z_MAX), np.round(z, 2)

    both = rr.reference_walk([500.0, 501.0], DEPTH, absorption, **kw)
    for lam, i in ((500.0, 0), (501.0, 1)):
        one = rr.reference_walk([lam], DEPTH, absorption, **kw)
        for key in ("Eu_top", "Ed_bottom", "Eou_top"):
            assert one[key][0][0] == pytest.approx(both[key][0][i], rel=1e-12)


def test_total_raman_walk_matches_single_scattering_at_default_coefficients():
    """At the default b488 = 2.6e-4 the ALL-orders Raman light of the walk is compared with
    single scattering, since there the second order (bounded analytically by
    second_order_bound(), an upper bound on Eu + Ed of the twice-scattered light) is below a
    quarter of the standard error in every band. Eou has no such bound and is left to the
    once-Raman test."""
    ref = rr.single_scattering(BANDS, DEPTH, absorption)
    bound = rr.second_order_bound(BANDS, DEPTH, absorption)
    mc = rr.reference_walk(BANDS, DEPTH, absorption, excitation_range_nm=EXCITATION,
                           photons=30_000_000, seed=5)
    for key in ("Eu_top", "Ed_bottom"):
        se = mc[key][1]
        assert np.all(bound < 0.25 * se), (key, np.round(bound / se, 3))
        z = _z(mc[key], ref[key])
        assert np.all(np.abs(z) < Z_MAX), (key, np.round(z, 2))


def test_second_order_bound_against_walk():
    """The walk's two-or-more-Raman light (Eu + Ed, summed over the bands) against the analytic
    bound on the twice-scattered light, at b488 = 2.6e-3: below the bound (within 4 standard
    errors; third order adds ~ b_R(300 nm) d ~ 8% or less to the walk), and above half of it
    (in this thin, weakly absorbing layer nearly all the emitted light leaves, so the bound is
    nearly attained; measured ratios 0.76-1.08 over seeds). Bands are treated as independent
    for the standard error of the sum."""
    kw = dict(b488=2.6e-3)
    bound = rr.second_order_bound(BANDS, DEPTH, absorption, **kw).sum()
    mc = rr.reference_walk(BANDS, DEPTH, absorption, excitation_range_nm=EXCITATION,
                           photons=20_000_000, seed=3, **kw)
    multi = mc["Eu_top_multi"][0].sum() + mc["Ed_bottom_multi"][0].sum()
    se = math.sqrt((mc["Eu_top_multi"][1] ** 2).sum() + (mc["Ed_bottom_multi"][1] ** 2).sum())
    assert multi < bound + Z_MAX * se, (multi, bound, se)
    assert multi > 0.5 * bound, (multi, bound, se)


def test_photon_conservation_in_thick_nonabsorbing_layer():
    """a = 0, b_el = 0, d = 50 m, b488 = 2.6e-2: several Raman orders, nothing absorbed. Raman
    photons leaving top and bottom plus the unscattered beam equal the incident photons; the
    Raman part (Monte Carlo) is compared with incident minus the analytic unscattered beam
    integral E0 l' exp(-b_R(l') d) dl', and with the photons read off the scored spectra."""
    lo, hi = 400.0, 440.0
    b488, depth = 2.6e-2, 50.0
    grid = np.arange(441.0, 2001.0, 2.0)                 # contiguous 2 nm bins over all emission
    mc = rr.reference_walk(grid, depth, lambda lam: np.zeros_like(lam), b488=b488,
                           excitation_range_nm=(lo, hi), photons=2_000_000, seed=1)
    b = mc["budget"]
    q = 1e-9 / (rr.H_PLANCK * rr.C_LIGHT)                # photons per (W m^-2 nm^-1 nm) per nm
    lp = np.linspace(lo, hi, 4001)
    incident = integrate.simpson(lp * q, x=lp)
    direct = integrate.simpson(lp * q * np.exp(-rr.raman_b(lp, b488) * depth), x=lp)

    assert abs(b["incident"][0] / incident - 1) < 4 * b["incident"][1] / incident
    assert b["absorbed"][0] == 0.0 and b["elastic_top"][0] == 0.0
    total = b["raman_top"][0] + b["raman_bottom"][0] + b["direct_bottom"][0]
    assert abs(total / b["incident"][0] - 1) < 1e-12                     # photon by photon
    raman = b["raman_top"][0] + b["raman_bottom"][0]
    raman_se = math.hypot(b["raman_top"][1], b["raman_bottom"][1])
    assert abs(raman - (incident - direct)) < Z_MAX * raman_se, (raman, incident - direct)
    assert raman_se < 1e-3 * raman
    # the spectra carry the same photons: sum of (Eu + Ed) l over the bins (bin-centre error
    # ~ (bin / l)^2, negligible)
    spectral = np.sum((mc["Eu_top"][0] + mc["Ed_bottom"][0]) * grid * 2.0) * q
    assert abs(spectral / raman - 1) < 1e-3
    # energy is not conserved: the Raman light is redder than the light it came from (each
    # shift keeps l'/l < 0.87 of the energy)
    removed = integrate.simpson(1 - np.exp(-rr.raman_b(lp, b488) * depth), x=lp)
    energy_raman = np.sum(mc["Eu_top"][0] + mc["Ed_bottom"][0]) * 2.0
    assert energy_raman < 0.9 * removed


def test_budget_closes_with_elastic_scattering():
    """With absorption and isotropic elastic scattering every fate occurs, and the photon budget
    still closes photon by photon (the elastic branch of the walk runs)."""
    mc = rr.reference_walk(BANDS, 5.0, lambda lam: np.full_like(lam, 0.1),
                           elastic=lambda lam: np.full_like(lam, 0.5), b488=2.6e-2,
                           excitation_range_nm=EXCITATION, photons=400_000, seed=4)
    b = mc["budget"]
    assert all(b[k][0] > 0 for k in rr.BUDGET_KEYS)
    out = sum(b[k][0] for k in rr.BUDGET_KEYS if k != "incident")
    assert abs(out / b["incident"][0] - 1) < 1e-12
    assert np.all(mc["Eu_top"][0] > 0) and np.all(mc["Eu_top_multi"][0] >= 0)
