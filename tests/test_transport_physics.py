"""Whole-engine physics: scenes with analytic answers, run through oceanmc.simulate.

Each statistical check is a z-score against the batch standard error with a fixed seed (|z| below
a Bonferroni bound for the number of compared values, stats_helpers.z_bound) plus a cap on the
relative error; estimates without noise (exact weights in non-scattering layers) are compared
with a tolerance at the level of rounding. Every scene's energy budget must add up to 1 within
its standard error (check_result). References are computed here from the formulas of DESIGN.md
section 4 with an independent Fresnel formula (stats_helpers.fresnel_reference) and scipy
quadrature, never from oceanmc's output.
"""
import math

import numpy as np
import pytest
from scipy import integrate

import oceanmc

from stats_helpers import (assert_same, assert_z, batch_mean_se, chandrasekhar_h, dof_of,
                           fresnel_reference)

N = 1.34
MU_C = math.sqrt(1.0 - 1.0 / N ** 2)   # cosine of the critical angle in water (48.27 deg)
THREADS = 2


# --- helpers ----------------------------------------------------------------------------------

def zr(r, estimate, reference, stderr, **kwargs):
    """assert_z with the degrees of freedom of r's batch standard errors."""
    return assert_z(estimate, reference, stderr, dof=dof_of(r), **kwargs)


def check_result(r, *, exact_budget: bool = False):
    """No NaN or inf in any batch of any quantity; the energy budget adds up to 1 within its
    standard error (and to 1e-3 at most); nothing truncated by the event limit."""
    for name, q in r.quantities.items():
        assert np.all(np.isfinite(q.batches)), f"{name} has NaN or inf"
    total, se = r["budget/total"], r.stderr("budget/total")
    if exact_budget:
        assert total == pytest.approx(1.0, abs=1e-9)
    else:
        zr(r, total, 1.0, se, abs_max=1e-3, what="budget/total")
    assert r["budget/truncated"] == 0.0
    for name in r.quantities:
        if name.startswith("budget/") and name != "budget/total":
            assert np.all(r.quantities[name].batches >= 0.0), f"{name} negative"


def simulate(config, threads=THREADS, exact_budget=False):
    r = oceanmc.simulate(config, threads=threads)
    check_result(r, exact_budget=exact_budget)
    return r


def T_air(theta_deg, n=N):
    """Fresnel transmittance from air at theta (deg)."""
    return 1.0 - fresnel_reference(1.0, n, math.radians(theta_deg))


def refracted_mu(mu_air, n=N):
    return math.sqrt(1.0 - (1.0 - mu_air ** 2) / n ** 2)


def band_mu(r):
    """(mu_hi, mu_lo) of each theta band, as cosines from nadir of the travel direction."""
    mu = np.cos(np.radians(r.coords["theta_edges"]))
    return mu[:-1], mu[1:]


def unique_quads(r, values):
    """Flattens (theta, phi) arrays to the distinct quads: a polar cap counts once."""
    values = np.asarray(values)
    mask = np.ones(values.shape[-2:], dtype=bool)
    mask[0, 1:] = False
    mask[-1, 1:] = False
    return values[..., mask], mask


def band_rows(r, upward: bool):
    theta = r.coords["theta"]
    return np.where(theta > 90.0)[0] if upward else np.where(theta < 90.0)[0]


def quad_average(f, mu_a, mu_b):
    """Solid-angle average over a band of an azimuth-independent radiance f(mu), mu_a < mu_b."""
    lo, hi = min(mu_a, mu_b), max(mu_a, mu_b)
    return integrate.quad(f, lo, hi, epsabs=1e-13, epsrel=1e-11, limit=200)[0] / (hi - lo)


def radiance_band_reference(r, f, upward: bool):
    """A (theta, phi) array of quad averages of f(|mu|) on the upward or downward bands (NaN on
    the others)."""
    hi, lo = band_mu(r)
    ref = np.full((len(hi), len(r.coords["phi"])), np.nan)
    for i in band_rows(r, upward):
        ref[i, :] = quad_average(f, abs(hi[i]), abs(lo[i]))
    return ref


def edge_rows(r):
    """Theta bands whose estimates are intrinsically noisier: the polar caps (small solid angle)
    and the bands touching the horizon (the 1/|mu| weights of grazing crossings)."""
    edges = r.coords["theta_edges"]
    rows = [0, len(edges) - 2]
    rows += [i for i in range(len(edges) - 1) if edges[i] == 90.0 or edges[i + 1] == 90.0]
    return np.array(sorted(set(rows)))


def compare_radiance(r, name, depth_index, reference, upward, *, quad_rel_max, band_rel_max,
                     edge_rel_max, edge_band_rel_max=None, faint=0.0, exclude=None, what):
    """Every quad of the chosen hemisphere against its reference (z with Bonferroni over the
    quads), then the azimuthal average of each band with its batch standard error. Relative
    caps: quad_rel_max on single quads, band_rel_max on band averages; in the polar caps and the
    bands next to the horizon (edge_rows) edge_rel_max on single quads and edge_band_rel_max
    (default edge_rel_max / 4) on band averages. Quads fainter than
    faint x the brightest reference (too few photons for a z-score) must only lie within
    faint x brightest of the reference. exclude: a (theta, phi) mask of quads left out (band
    averages then run over the others). Returns the largest |z|."""
    q = r.quantities[name]
    batches = q.batches if depth_index is None else q.batches[:, depth_index]
    rows = band_rows(r, upward)
    est, se = batch_mean_se(batches)
    nt, nphi = est.shape
    sel = np.zeros(est.shape, dtype=bool)
    sel[rows, :] = True
    sel[0, 1:] = False
    sel[-1, 1:] = False
    if exclude is not None:
        sel &= ~exclude
    brightest = np.nanmax(reference[sel])
    dim = sel & (reference < faint * brightest)
    if dim.any():
        assert np.all(np.abs(est[dim] - reference[dim]) <= faint * brightest), what
    use = sel & ~dim
    cap = np.full(est.shape, quad_rel_max)
    cap[edge_rows(r), :] = edge_rel_max
    z = zr(r, est[use], reference[use], se[use], rel_max=None, what=f"{what}: quads")
    err = np.abs(est[use] - reference[use]) / reference[use]
    worst = int(np.argmax(err / cap[use]))
    assert np.all(err <= cap[use]), (f"{what}: quad off by {err[worst]:.2%} (cap "
                                     f"{cap[use][worst]:.0%}): {est[use][worst]:.5g} +- "
                                     f"{se[use][worst]:.2g} vs {reference[use][worst]:.5g}")
    bright_rows = np.array([i for i in rows if reference[i, 0] >= faint * brightest])
    keep = np.ones(est.shape) if exclude is None else (~exclude).astype(float)
    keep = keep[bright_rows, :]
    band_mean, band_se = batch_mean_se((batches[:, bright_rows, :] * keep).sum(axis=2)
                                       / keep.sum(axis=1))
    band_ref = (reference[bright_rows, :] * keep).sum(axis=1) / keep.sum(axis=1)
    zb = zr(r, band_mean, band_ref, band_se, what=f"{what}: azimuthal band averages")
    if edge_band_rel_max is None:
        edge_band_rel_max = edge_rel_max / 4.0
    band_cap = np.where(np.isin(bright_rows, edge_rows(r)), edge_band_rel_max, band_rel_max)
    err_b = np.abs(band_mean - band_ref) / band_ref
    assert np.all(err_b <= band_cap), (f"{what}: band averages off by {err_b} (caps "
                                       f"{band_cap})")
    return max(np.max(np.abs(z)), np.max(np.abs(zb)))


def report_se(r, name, depth_index, upward):
    """(largest relative standard error of the interior quads, of the edge quads)."""
    q = r.quantities[name]
    batches = q.batches if depth_index is None else q.batches[:, depth_index]
    est, se = batch_mean_se(batches)
    rows = band_rows(r, upward)
    inner = [i for i in rows if i not in edge_rows(r)]
    outer = [i for i in rows if i in edge_rows(r)]
    return (np.max(se[inner] / np.abs(est[inner])), np.max(se[outer] / np.abs(est[outer])))


# --- 4. pure absorber under a flat surface ----------------------------------------------------

ABSORBER_LAYERS = [{"thickness_m": 3.0, "a": 0.1, "b": 0.0},
                   {"thickness_m": 7.0, "a": 0.3, "b": 0.0}]
ABSORBER_DEPTHS = [0.0, 1.0, 3.0, 5.0, 10.0]


def optical_path(z):
    """Integral of a over depth from 0 to z for ABSORBER_LAYERS."""
    return 0.1 * min(z, 3.0) + 0.3 * max(0.0, z - 3.0)


def absorber_config(**over):
    config = {"photons": 40_000, "batches": 8, "seed": 1,
              "illumination": {"Ed0": 1.0, "sun_zenith_deg": 40.0, "diffuse_fraction": 0.0},
              "surface": {"model": "flat", "n_water": N},
              "water": {"layers": ABSORBER_LAYERS}, "bottom": {"model": "black"},
              "tallies": {"depths_m": ABSORBER_DEPTHS}}
    config.update(over)
    return config


def sun_absorber_reference(theta_s=40.0, ed0=1.0):
    mu_w = refracted_mu(math.cos(math.radians(theta_s)))
    t = T_air(theta_s)
    ed = np.array([ed0 * t * math.exp(-optical_path(z) / mu_w) for z in ABSORBER_DEPTHS])
    return ed, mu_w, t


def test_pure_absorber_sun_exact():
    """b = 0, sun only, implicit weights: Ed(z) = Ed0 (1 - R) exp(-int a dz / cos t_w) with no
    noise at all, Eod = Ed / cos t_w, no upward light; budget terms exact."""
    ed0 = 2.5
    r = simulate(absorber_config(illumination={"Ed0": ed0, "sun_zenith_deg": 40.0}),
                 exact_budget=True)
    ed, mu_w, t = sun_absorber_reference(40.0, ed0)
    np.testing.assert_allclose(r["Ed"], ed, rtol=1e-10)
    np.testing.assert_allclose(r["Eod"], ed / mu_w, rtol=1e-10)
    assert np.all(r["Eu"] == 0.0) and np.all(r["Eou"] == 0.0)
    assert r["air/Ed"] == pytest.approx(ed0, rel=1e-12)
    assert r["air/Eu"] == pytest.approx(ed0 * (1.0 - t), rel=1e-10)
    assert r["budget/surface_reflection"] == pytest.approx(1.0 - t, rel=1e-10)
    assert r["budget/absorbed_layer_1"] == pytest.approx(
        t * (1.0 - math.exp(-0.3 / mu_w)), rel=1e-10)
    assert r["budget/absorbed_layer_2"] == pytest.approx(
        t * math.exp(-0.3 / mu_w) * (1.0 - math.exp(-2.1 / mu_w)), rel=1e-10)
    assert r["budget/absorbed_bottom"] == pytest.approx(t * math.exp(-2.4 / mu_w), rel=1e-10)
    # the refracted beam lies in one quad, whose radiance x solid angle is Eod
    omega = np.cos(np.radians(r.coords["theta_edges"]))
    band = np.searchsorted(-omega, -mu_w) - 1
    dmu = omega[band] - omega[band + 1]
    dphi = math.radians(360.0 / len(r.coords["phi"]))
    np.testing.assert_allclose(r["radiance"][:, band, 0] * dmu * dphi, ed / mu_w, rtol=1e-10)
    others = r["radiance"].copy()
    others[:, band, 0] = 0.0
    assert np.all(others == 0.0)


def test_pure_absorber_sun_analog():
    """The same scene in analog mode (absorption and Fresnel decided by random draws): noisy,
    and equal to the formula within the standard errors."""
    r = simulate(absorber_config(photons=400_000, batches=16, seed=2,
                                 estimator={"mode": "analog"}))
    ed, mu_w, t = sun_absorber_reference()
    z = zr(r, r["Ed"], ed, r.stderr("Ed"), rel_max=0.01, what="analog Ed(z)")
    assert np.all(r.stderr("Ed") > 0.0)
    zr(r, r["budget/surface_reflection"], 1.0 - t, r.stderr("budget/surface_reflection"),
             rel_max=0.02, what="analog surface reflection")
    zr(r, r["budget/absorbed_bottom"], t * math.exp(-2.4 / mu_w),
             r.stderr("budget/absorbed_bottom"), rel_max=0.02, what="analog bottom")
    print(f"analog pure absorber: max |z| Ed = {np.max(np.abs(z)):.2f}")


def test_pure_absorber_sun_and_sky():
    """Sun plus a uniform sky (diffuse_fraction 0.6): the sky part is
    Ed_sky(z) = f Ed0 int_0^1 2 mu (1 - R(mu)) exp(-int a dz / mu_w(mu)) dmu."""
    f = 0.6
    r = simulate(absorber_config(photons=400_000, batches=16, seed=3,
                                 illumination={"sun_zenith_deg": 40.0, "diffuse_fraction": f}))
    ed_sun, _, _ = sun_absorber_reference()

    def sky(z, scalar=False):
        g = lambda m: 2.0 * m * (1.0 - fresnel_reference(1.0, N, math.acos(m))) * math.exp(
            -optical_path(z) / refracted_mu(m)) / (refracted_mu(m) if scalar else 1.0)
        return integrate.quad(g, 0.0, 1.0, epsabs=1e-13, limit=200)[0]
    ed = (1.0 - f) * ed_sun + f * np.array([sky(z) for z in ABSORBER_DEPTHS])
    z1 = zr(r, r["Ed"], ed, r.stderr("Ed"), rel_max=0.005, what="sun+sky Ed(z)")
    eod_sun = ed_sun / refracted_mu(math.cos(math.radians(40.0)))
    eod = (1.0 - f) * eod_sun + f * np.array([sky(z, True) for z in ABSORBER_DEPTHS])
    z2 = zr(r, r["Eod"], eod, r.stderr("Eod"), rel_max=0.005, what="sun+sky Eod(z)")
    assert np.all(r["Eu"] == 0.0)
    print(f"sun+sky pure absorber: max |z| Ed {np.max(np.abs(z1)):.2f}, "
          f"Eod {np.max(np.abs(z2)):.2f}")


# --- 5. Lambertian and Minnaert bottoms with no water in the way ------------------------------

def bare_bottom_config(bottom, *, sun=30.0, f=0.0, photons=2_000_000, seed=4):
    return {"photons": photons, "batches": 40, "seed": seed,
            "illumination": {"Ed0": 1.0, "sun_zenith_deg": sun, "diffuse_fraction": f},
            "surface": {"model": "none"},
            "water": {"layers": [{"thickness_m": 1e-6, "a": 0.0, "b": 0.0}]},
            "bottom": bottom, "tallies": {"depths_m": [0.0]}}


def test_lambertian_bottom():
    """Reflected flux rho Ed (exact weights), reflected radiance rho Ed / pi in every upward
    quad, scalar irradiance Eou = 2 rho Ed (which also checks the grazing 1/mu rule: exact for
    constant radiance); at 0+ the same (n = 1), all of it water-leaving."""
    rho = 0.3
    r = simulate(bare_bottom_config({"model": "lambertian", "reflectance": rho}),
                 exact_budget=True)
    assert r["Ed"][0] == pytest.approx(1.0, rel=1e-12)
    assert r["Eu"][0] == pytest.approx(rho, rel=1e-10)
    assert r["budget/water_leaving"] == pytest.approx(rho, rel=1e-10)
    assert r["budget/absorbed_bottom"] == pytest.approx(1.0 - rho, rel=1e-10)
    zr(r, r["Eou"][0], 2.0 * rho, r.stderr("Eou")[0], rel_max=0.01, what="Lambertian Eou")
    ref = radiance_band_reference(r, lambda m: rho / math.pi, upward=True)
    zmax = compare_radiance(r, "radiance", 0, ref, True, quad_rel_max=0.15, band_rel_max=0.02,
                            edge_rel_max=0.5, what="Lambertian L(0)")
    zmax_air = compare_radiance(r, "air/radiance", None, ref, True, quad_rel_max=0.15,
                                band_rel_max=0.02, edge_rel_max=0.5, what="Lambertian L(0+)")
    np.testing.assert_allclose(r["air/Lw"][10:], r["air/radiance"][10:], rtol=1e-12)
    assert r["air/Lw_nadir"] == pytest.approx(r["Lu"][0], rel=1e-12)
    print(f"Lambertian bottom: max |z| {zmax:.2f} (0-), {zmax_air:.2f} (0+)")


def minnaert_radiance(rho, k, mu_r, ed_factor):
    """L(mu_r) for Minnaert (rho/pi)(mu_i mu_r)^k lit by ed_factor = integral of mu_i^k dEd."""
    return rho / math.pi * mu_r ** k * ed_factor


@pytest.mark.parametrize("k, sun, f", [(3.0, 40.0, 0.0), (1.0, 20.0, 0.5), (0.5, 70.0, 0.0)])
def test_minnaert_bottom(k, sun, f):
    """Minnaert bottom under sun (and sky): Eu = Ed0 [(1 - f) rho_dh(mu_s) + f 4 rho/(k + 2)^2]
    (the sky's part is the bihemispherical albedo), radiance quad averages of
    (rho/pi) mu_r^k [(1 - f) mu_s^k + f 2/(k + 2)] Ed0, and Eou = 2 pi int L dmu."""
    rho = 0.8
    r = simulate(bare_bottom_config({"model": "minnaert", "reflectance": rho, "k": k}, sun=sun,
                                    f=f, seed=5 + int(k)), exact_budget=(f == 0.0))
    mu_s = math.cos(math.radians(sun))
    eu = (1.0 - f) * 2.0 * rho * mu_s ** k / (k + 2.0) + f * 4.0 * rho / (k + 2.0) ** 2
    ed_factor = (1.0 - f) * mu_s ** k + f * 2.0 / (k + 2.0)
    if f == 0.0:
        assert r["Eu"][0] == pytest.approx(eu, rel=1e-10)
    else:
        zr(r, r["Eu"][0], eu, r.stderr("Eu")[0], rel_max=0.005, what="Minnaert Eu (sky)")
    zr(r, r["Eou"][0], 2.0 * rho * ed_factor / (k + 1.0), r.stderr("Eou")[0],
             rel_max=0.01, what="Minnaert Eou")
    ref = radiance_band_reference(r, lambda m: minnaert_radiance(rho, k, m, ed_factor),
                                  upward=True)
    # near the horizon the radiance ~ mu^k is faint for large k: quads below 5% of the
    # brightest are only checked to lie within 5% of it
    zmax = compare_radiance(r, "radiance", 0, ref, True, quad_rel_max=0.2, band_rel_max=0.03,
                            edge_rel_max=0.6, faint=0.05, what=f"Minnaert k={k} L(0)")
    print(f"Minnaert k={k} sun={sun} f={f}: max |z| {zmax:.2f}")


# --- 6./7. Snell's window, sky reflectance ------------------------------------------------------

def snell_config(sky="uniform", photons=1_000_000, seed=6):
    return {"photons": photons, "batches": 40, "seed": seed,
            "illumination": {"Ed0": 1.0, "sun_zenith_deg": 30.0, "diffuse_fraction": 1.0,
                             "sky": sky},
            "surface": {"model": "flat", "n_water": N},
            "water": {"layers": [{"thickness_m": 1.0, "a": 0.0, "b": 0.0}]},
            "bottom": {"model": "black"}, "tallies": {"depths_m": [0.0]}}


def sky_reflectance(weight):
    num = integrate.quad(lambda m: weight(m) * m * fresnel_reference(1.0, N, math.acos(m)),
                         0.0, 1.0, epsabs=1e-14, limit=200)[0]
    return num / integrate.quad(lambda m: weight(m) * m, 0.0, 1.0)[0]


def test_snells_window():
    """Uniform sky L = Ed0/pi over black, clear water: just below the surface the downward
    radiance is t(theta_air) n^2 L inside the critical cone (48.27 deg) and 0 outside; the quad
    straddling the cone edge gets the exact quad average. No upward light. Above the surface the
    sky quads read Ed0/pi and the reflected ones R(theta) Ed0/pi."""
    r = simulate(snell_config())
    L = 1.0 / math.pi

    def water(mu_w):
        if mu_w <= MU_C:
            return 0.0
        mu_a = math.sqrt(max(0.0, 1.0 - N ** 2 * (1.0 - mu_w ** 2)))
        return (1.0 - fresnel_reference(1.0, N, math.acos(mu_a))) * N ** 2 * L
    ref = radiance_band_reference(r, water, upward=False)
    hi, lo = band_mu(r)
    outside = np.array([h <= MU_C for h in hi]) & (r.coords["theta"] < 90.0)
    straddle = np.array([(h > MU_C > l) for h, l in zip(hi, lo)])
    assert r.coords["theta_edges"][np.where(straddle)[0][0]] == 45.0
    # outside the window: exactly nothing
    assert np.all(r["radiance"][0][outside] == 0.0)
    assert np.all(r["radiance"][0][r.coords["theta"] > 90.0] == 0.0)
    # inside: every quad and band (the empty bands are 'faint' there and checked above)
    zmax = compare_radiance(r, "radiance", 0, ref, False, quad_rel_max=0.15, band_rel_max=0.015,
                            edge_rel_max=0.5, edge_band_rel_max=0.04, faint=1e-12,
                            what="Snell window L(0-)")
    i = int(np.where(straddle)[0][0])
    straddling, straddling_se = batch_mean_se(
        r.quantities["radiance"].batches[:, 0, i, :].mean(axis=1))
    zr(r, straddling, ref[i, 0], straddling_se, rel_max=0.02, what="straddling band")
    print(f"Snell window: max |z| {zmax:.2f}; straddling band {straddling:.5f} +- "
          f"{straddling_se:.5f} vs {ref[i, 0]:.5f}; cap {r['radiance'][0, 0, 0]:.5f} +- "
          f"{r.stderr('radiance')[0, 0, 0]:.5f} vs {ref[0, 0]:.5f}")
    # fluxes: Ed(0-) = (1 - r_aw) Ed0 = Eod-weighted check, reflected fraction 0.0675
    r_aw = sky_reflectance(lambda m: 1.0)
    assert abs(r_aw - 0.0675) < 6e-5
    zr(r, r["budget/surface_reflection"], r_aw, r.stderr("budget/surface_reflection"),
             rel_max=0.01, what="uniform-sky surface reflectance")
    zr(r, r["Ed"][0], 1.0 - r_aw, r.stderr("Ed")[0], rel_max=0.002, what="Ed(0-)")
    zr(r, r["air/Eu"], r_aw, r.stderr("air/Eu"), rel_max=0.01, what="air/Eu")
    assert r["air/Ed"] == pytest.approx(1.0, rel=1e-12)
    assert r["air/Eu_water_leaving"] == 0.0
    assert np.all(r["air/Lw"] == 0.0)   # all the upward light at 0+ is sky reflection
    # above the surface: the sky itself and its reflection
    sky_ref = radiance_band_reference(r, lambda m: L, upward=False)
    compare_radiance(r, "air/radiance", None, sky_ref, False, quad_rel_max=0.15,
                     band_rel_max=0.015, edge_rel_max=0.5, what="uniform sky L(0+)")
    refl_ref = radiance_band_reference(
        r, lambda m: L * fresnel_reference(1.0, N, math.acos(m)), upward=True)
    compare_radiance(r, "air/radiance", None, refl_ref, True, quad_rel_max=0.2,
                     band_rel_max=0.03, edge_rel_max=0.6, what="reflected sky L(0+)")
    print(f"uniform sky: r_aw = {r['budget/surface_reflection']:.5f} +- "
          f"{r.stderr('budget/surface_reflection'):.5f} (ref {r_aw:.5f})")


def test_cardioidal_sky():
    """Cardioidal sky L ~ 1 + 2 cos(zenith): reflected fraction 0.0522 and the sky radiance
    3 Ed0 (1 + 2 mu) / (7 pi) above the surface (this also tests the sky sampler)."""
    r = simulate(snell_config(sky="cardioidal", photons=1_000_000, seed=7))
    r_card = sky_reflectance(lambda m: 1.0 + 2.0 * m)
    assert abs(r_card - 0.0522) < 6e-5
    z = zr(r, r["budget/surface_reflection"], r_card, r.stderr("budget/surface_reflection"),
                 rel_max=0.01, what="cardioidal-sky surface reflectance")
    sky_ref = radiance_band_reference(r, lambda m: 3.0 * (1.0 + 2.0 * m) / (7.0 * math.pi),
                                      upward=False)
    compare_radiance(r, "air/radiance", None, sky_ref, False, quad_rel_max=0.2,
                     band_rel_max=0.02, edge_rel_max=0.6, what="cardioidal sky L(0+)")
    print(f"cardioidal sky: r = {r['budget/surface_reflection']:.5f} +- "
          f"{r.stderr('budget/surface_reflection'):.5f} (ref {r_card:.5f}, z {float(z[0]):.2f})")


def test_water_to_air_reflectance():
    """A white Lambertian bottom (rho = 1) under a thin clear layer sends uniform radiance up to
    the surface, which reflects r_wa = 0.4807 of it back (TIR included). With T the sun's
    transmittance, Ed(0-) = T + r_wa Eu(0-): r_wa = (Ed(0-) - T)/Eu(0-) per batch. Also the
    radiance just below the surface: uniform upward, L_up = T / (pi (1 - r_wa)); downward
    outside Snell's window equal to it (total internal reflection), inside R(theta) L_up."""
    sun = 30.0
    r = simulate({"photons": 4_000_000, "batches": 32, "seed": 8,
                  "illumination": {"Ed0": 1.0, "sun_zenith_deg": sun},
                  "surface": {"model": "flat", "n_water": N},
                  "water": {"layers": [{"thickness_m": 1e-3, "a": 0.0, "b": 0.0}]},
                  "bottom": {"model": "lambertian", "reflectance": 1.0},
                  "tallies": {"depths_m": [0.0]}})
    r_wa_ref = (integrate.quad(lambda m: 2.0 * m * fresnel_reference(N, 1.0, math.acos(m)),
                               MU_C, 1.0, epsabs=1e-14, limit=200)[0] + MU_C ** 2)
    assert abs(r_wa_ref - 0.4807) < 6e-5
    t = T_air(sun)
    ratio = (r.quantities["Ed"].batches[:, 0] - t) / r.quantities["Eu"].batches[:, 0]
    est, se = batch_mean_se(ratio)
    z = zr(r, est, r_wa_ref, se, rel_max=0.005, what="r_wa")
    # no absorption anywhere: all that entered leaves
    zr(r, r["budget/water_leaving"], t, r.stderr("budget/water_leaving"), abs_max=1e-3,
             what="water leaving")
    assert r["budget/surface_reflection"] == pytest.approx(1.0 - t, rel=1e-10)
    l_up = t / (math.pi * (1.0 - r_wa_ref))
    up = radiance_band_reference(r, lambda m: l_up, upward=True)
    compare_radiance(r, "radiance", 0, up, True, quad_rel_max=0.15, band_rel_max=0.02,
                     edge_rel_max=0.5, what="uniform upwelling L(0-)")

    def down(mu_w):
        return l_up * fresnel_reference(N, 1.0, math.acos(mu_w))
    ref = radiance_band_reference(r, down, upward=False)
    # the sun's refracted beam adds to one quad (band 15-25 deg, phi = 0): leave it out
    mu_sun = refracted_mu(math.cos(math.radians(sun)))
    hi, lo = band_mu(r)
    sun_band = int(np.where((hi >= mu_sun) & (lo < mu_sun))[0][0])
    sun_quad = np.zeros(ref.shape, dtype=bool)
    sun_quad[sun_band, 0] = True
    zd = compare_radiance(r, "radiance", 0, ref, False, quad_rel_max=0.2, band_rel_max=0.02,
                          edge_rel_max=0.5, exclude=sun_quad, what="reflected-down L(0-)")
    # above the surface the water-leaving radiance obeys the n^2 law the other way:
    # Lw(theta_air) = (1 - R(theta_air)) L_up / n^2, uniform L_up below
    lw = radiance_band_reference(
        r, lambda m: (1.0 - fresnel_reference(1.0, N, math.acos(m))) * l_up / N ** 2, upward=True)
    zw = compare_radiance(r, "air/Lw", None, lw, True, quad_rel_max=0.2, band_rel_max=0.02,
                          edge_rel_max=0.5, what="water-leaving Lw(0+)")
    zr(r, r["air/Lw_nadir"], lw[-1, 0], r.stderr("air/Lw_nadir"), rel_max=0.05, what="Lw nadir")
    assert r["air/Rrs_nadir"] == pytest.approx(r["air/Lw_nadir"], rel=1e-12)
    assert r["air/Eu_water_leaving"] == pytest.approx(r["budget/water_leaving"], rel=1e-12)
    tir = np.where(hi[:10] <= MU_C)[0]
    band_mean, band_se = batch_mean_se(r.quantities["radiance"].batches[:, 0, tir, :]
                                       .mean(axis=2))
    zr(r, band_mean, l_up, band_se, rel_max=0.01, what="TIR bands = L_up")
    print(f"r_wa = {est:.5f} +- {se:.5f} (ref {r_wa_ref:.5f}, z {float(z[0]):.2f}); "
          f"max |z| down quads {zd:.2f}, Lw quads {zw:.2f}; Lw nadir {r['air/Lw_nadir']:.5f} +- "
          f"{r.stderr('air/Lw_nadir'):.5f} (ref {lw[-1, 0]:.5f})")


# --- 8. Chandrasekhar: semi-infinite isotropic scattering --------------------------------------

@pytest.mark.parametrize("upward_fraction", [None, 0.1])
def test_chandrasekhar_semi_infinite(upward_fraction):
    """w0 = 0.8, mu0 = 0.5, no interface: plane albedo A = 1 - H(mu0) sqrt(1 - w0) = 0.36797 and
    reflected radiance L(mu)/Ed = w0 H(mu) H(mu0) / (4 pi (mu + mu0)) (0.09586 at nadir), here
    compared as quad averages over every upward band, the 175-180 deg cap included; with the
    plain walk and with scattering biased toward straight up (estimator.upward_fraction)."""
    w0, mu0 = 0.8, 0.5
    H = chandrasekhar_h(w0)
    A = 1.0 - H(mu0)[0] * math.sqrt(1.0 - w0)
    L = lambda m: w0 * H(m)[0] * H(mu0)[0] / (4.0 * math.pi * (m + mu0))
    assert abs(A - 0.36797) < 6e-6
    assert abs(L(1.0) - 0.09586) < 6e-6
    r = simulate({"photons": 2_000_000, "batches": 40, "seed": 9,
                  "illumination": {"Ed0": 1.0, "sun_zenith_deg": 60.0},
                  "surface": {"model": "none"},
                  "water": {"layers": [{"thickness_m": float("inf"), "a": 0.2, "b": 0.8,
                                        "phase": {"model": "isotropic"}}]},
                  "bottom": {"model": "none"}, "tallies": {"depths_m": [0.0]},
                  "estimator": {"upward_fraction": upward_fraction}})
    za = zr(r, r["air/Eu"], A, r.stderr("air/Eu"), rel_max=0.003, what="plane albedo")
    assert r["Ed"][0] == pytest.approx(1.0, rel=1e-12)
    assert r["Eu"][0] == pytest.approx(r["air/Eu"], rel=1e-12)
    ref = radiance_band_reference(r, L, upward=True)
    cap = ref[-1, 0]
    zl = zr(r, r["air/Lu"], cap, r.stderr("air/Lu"), rel_max=0.04, what="nadir cap")
    assert r["air/Lw_nadir_crossing"] == pytest.approx(r["air/Lu"], rel=1e-12)
    assert r["air/Rrs_nadir"] == pytest.approx(r["air/Lw_nadir"], rel=1e-12)
    # the local (next-event) estimate of the same cap average: same expectation, far smaller
    # standard error (with the upward bias the ratio of the two over 40 batches was 7.6-14.7 at
    # seeds 9, 12-14, on this kernel and on the one of 29d7ba3 alike, so a factor 5 is asked)
    zr(r, r["air/Lw_nadir"], cap, r.stderr("air/Lw_nadir"), rel_max=0.003, what="local cap")
    zr(r, r["Lu"][0], cap, r.stderr("Lu")[0], rel_max=0.003, what="local cap 0-")
    assert r.stderr("air/Lw_nadir") < r.stderr("air/Lu") / 5.0
    zmax = compare_radiance(r, "air/radiance", None, ref, True, quad_rel_max=0.15,
                            band_rel_max=0.02, edge_rel_max=0.5, what="Chandrasekhar L(mu)")
    # absorbed + reflected = 1 (nothing is lost below a semi-infinite absorbing medium)
    zr(r, r["budget/absorbed_layer_1"] + r["budget/water_leaving"], 1.0,
             r.stderr("budget/total"), abs_max=1e-3, what="Chandrasekhar budget")
    print(f"Chandrasekhar: A = {r['air/Eu']:.5f} +- {r.stderr('air/Eu'):.5f} (ref {A:.5f}, "
          f"z {float(za[0]):.2f}); nadir cap {r['air/Lu']:.5f} +- {r.stderr('air/Lu'):.5f} "
          f"(ref quad average {cap:.5f}, z {float(zl[0]):.2f}); max |z| quads {zmax:.2f}")


# --- 10. determinism ---------------------------------------------------------------------------

FULL_SCENE = {"photons": 30_000, "batches": 6, "seed": 12,
              "illumination": {"Ed0": 1.0, "sun_zenith_deg": 35.0, "diffuse_fraction": 0.3},
              "surface": {"model": "flat", "n_water": N},
              "water": {"layers": [
                  {"thickness_m": 2.0, "a": 0.1, "b": 0.5, "phase": {"model": "petzold"}},
                  {"thickness_m": 3.0, "a": 0.05, "b": 0.0},
                  {"thickness_m": 4.0, "a": 0.2, "b": 1.0,
                   "phase": {"model": "mixture", "components": [
                       {"b": 0.9, "phase": {"model": "henyey_greenstein", "g": 0.85}},
                       {"b": 0.1, "phase": {"model": "pure_water"}}]}}]},
              "bottom": {"model": "minnaert", "reflectance": 0.5, "k": 0.8},
              "tallies": {"depths_m": [0.0, 1.0, 5.0, 9.0]}}


def test_determinism_across_threads():
    """Same seed, 1 thread vs 2 threads: every batch of every quantity bit-identical; another
    seed differs."""
    a = simulate(FULL_SCENE, threads=1)
    b = simulate(FULL_SCENE, threads=2)
    assert a.quantities.keys() == b.quantities.keys()
    for name in a.quantities:
        assert np.array_equal(a.quantities[name].batches, b.quantities[name].batches), name
    c = simulate(dict(FULL_SCENE, seed=13), threads=2)
    assert not np.array_equal(a.quantities["Ed"].batches, c.quantities["Ed"].batches)


def test_batches_do_not_depend_on_the_batch_count():
    """Batch b's stream is a function of (seed, b) only: with the same photons per batch, the
    first batches of a 3-batch and a 6-batch run are identical."""
    a = simulate(dict(FULL_SCENE, photons=15_000, batches=3), threads=2)
    b = simulate(dict(FULL_SCENE, photons=30_000, batches=6), threads=2)
    for name in a.quantities:
        assert np.array_equal(a.quantities[name].batches, b.quantities[name].batches[:3]), name


# --- 11. analog and implicit estimators agree --------------------------------------------------

def test_analog_vs_implicit():
    """A scattering scene with a flat surface, a Lambertian bottom, sun and sky: the analog and
    the implicit (weights, splitting, roulette) estimators agree within their standard errors on
    irradiances at every depth, the radiance bands, the reflectances and the budget."""
    scene = {"photons": 400_000, "batches": 32,
             "illumination": {"Ed0": 1.0, "sun_zenith_deg": 30.0, "diffuse_fraction": 0.3},
             "surface": {"model": "flat", "n_water": N},
             "water": {"layers": [{"thickness_m": 4.0, "a": 0.15, "b": 0.6,
                                   "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
             "bottom": {"model": "lambertian", "reflectance": 0.5},
             "tallies": {"depths_m": [0.0, 2.0, 4.0],
                         "theta_edges_deg": [0, 30, 60, 90, 120, 150, 180], "phi_bands": 4}}
    imp = simulate(dict(scene, seed=21, estimator={"mode": "implicit"}))
    ana = simulate(dict(scene, seed=22, estimator={"mode": "analog"}))
    zs = []
    for name in ("Ed", "Eu", "Eod", "Eou"):
        zs.append(assert_same(ana[name], ana.stderr(name), imp[name], imp.stderr(name),
                              rel_max=0.03, n_compared=40, dof=dof_of(imp),
                              what=f"analog vs implicit {name}"))
    for name in ("air/Eu", "air/Eu_water_leaving", "budget/surface_reflection",
                 "budget/water_leaving", "budget/absorbed_layer_1", "budget/absorbed_bottom"):
        zs.append(assert_same(ana[name], ana.stderr(name), imp[name], imp.stderr(name),
                              rel_max=0.03, n_compared=40, dof=dof_of(imp),
                              what=f"analog vs implicit {name}"))
    # radiance: every quad at every depth (unique quads), Bonferroni over all of them
    ua, _ = unique_quads(ana, ana["radiance"])
    sa, _ = unique_quads(ana, ana.stderr("radiance"))
    ui, _ = unique_quads(imp, imp["radiance"])
    si, _ = unique_quads(imp, imp.stderr("radiance"))
    zs.append(assert_same(ua, sa, ui, si, rel_max=0.15, dof=dof_of(imp),
                          what="analog vs implicit radiance"))
    # the analog estimator is the noisier one
    assert ana.stderr("Eu")[0] > imp.stderr("Eu")[0]
    print(f"analog vs implicit: max |z| {max(np.max(np.abs(z)) for z in zs):.2f}")


# --- 12. stability ---------------------------------------------------------------------------

def small(config, photons=20_000):
    config = dict(config, photons=photons, batches=4, seed=31)
    return simulate(config)


def test_index_matched_flat_surface():
    """A flat surface with n_water = 1.0 exactly is no surface: nothing reflected, statistics as
    with surface none."""
    base = {"photons": 100_000, "batches": 8, "seed": 32,
            "illumination": {"Ed0": 1.0, "sun_zenith_deg": 50.0, "diffuse_fraction": 0.4},
            "water": {"layers": [{"thickness_m": 3.0, "a": 0.2, "b": 0.8,
                                  "phase": {"model": "henyey_greenstein", "g": 0.7}}]},
            "bottom": {"model": "lambertian", "reflectance": 0.4},
            "tallies": {"depths_m": [0.0, 3.0]}}
    flat = simulate(dict(base, surface={"model": "flat", "n_water": 1.0}))
    none = simulate(dict(base, seed=33, surface={"model": "none"}))
    assert flat["budget/surface_reflection"] == 0.0
    for name in ("Ed", "Eu", "air/Eu", "budget/water_leaving"):
        assert_same(flat[name], flat.stderr(name), none[name], none.stderr(name),
                    rel_max=0.03, n_compared=8, dof=dof_of(flat), what=f"n=1 flat vs none {name}")


def test_grazing_sun():
    """Sun at 89.9 deg: R = 0.99-ish of the exact Fresnel value, the rest refracts at almost the
    critical angle; no NaN, budget 1."""
    r = small({"illumination": {"Ed0": 1.0, "sun_zenith_deg": 89.9},
               "surface": {"model": "flat", "n_water": N},
               "water": {"layers": [{"thickness_m": 5.0, "a": 0.1, "b": 0.5,
                                     "phase": {"model": "petzold"}}]},
               "bottom": {"model": "lambertian", "reflectance": 0.2},
               "tallies": {"depths_m": [0.0, 5.0]}})
    R = fresnel_reference(1.0, N, math.radians(89.9))
    # the sun's own reflection is exact; light scattered back out adds to air/Eu only
    assert r["budget/surface_reflection"] == pytest.approx(R, rel=1e-9)
    assert r["air/Ed"] == pytest.approx(1.0, rel=1e-12)


def test_extreme_forward_scattering():
    """HG with g = 0.9999 (strong scattering, b = 5/m over 10 m: ~50 events per photon that
    barely deflect it): runs, and Ed(z) stays within a few percent below the unscattered beam's
    T exp(-a z / mu_w) (the small angular spread lengthens the path a little)."""
    r = small({"illumination": {"Ed0": 1.0, "sun_zenith_deg": 20.0},
               "surface": {"model": "flat", "n_water": N},
               "water": {"layers": [{"thickness_m": 10.0, "a": 0.05, "b": 5.0,
                                     "phase": {"model": "henyey_greenstein", "g": 0.9999}}]},
               "bottom": {"model": "black"}, "tallies": {"depths_m": [0.0, 5.0, 10.0]}})
    mu_w = refracted_mu(math.cos(math.radians(20.0)))
    beam = T_air(20.0) * np.exp(-0.05 * np.array([0.0, 5.0, 10.0]) / mu_w)
    ratio = r["Ed"] / beam
    assert np.all(ratio > 0.95), ratio
    assert np.all(ratio < 1.0 + 4.0 * r.stderr("Ed") / beam + 1e-9), ratio


def test_nanometre_layers():
    """Layers of 1e-9 m (scattering and not) between ordinary ones, with tallies on their
    boundaries: no NaN, budget 1, and the thin layers change nothing (compared with the same
    column without them)."""
    thin = [{"thickness_m": 1e-9, "a": 0.3, "b": 2.0, "phase": {"model": "isotropic"}},
            {"thickness_m": 1e-9, "a": 0.0, "b": 0.0}]
    common = {"illumination": {"Ed0": 1.0, "sun_zenith_deg": 30.0, "diffuse_fraction": 0.3},
              "surface": {"model": "flat", "n_water": N},
              "bottom": {"model": "lambertian", "reflectance": 0.3},
              "photons": 200_000, "batches": 8}
    body = {"thickness_m": 2.0, "a": 0.1, "b": 0.4, "phase": {"model": "henyey_greenstein",
                                                              "g": 0.8}}
    with_thin = simulate(dict(common, seed=34,
                              water={"layers": thin + [body] + thin + [body] + thin},
                              tallies={"depths_m": [0.0, 1e-9, 2e-9, 4.0]}))
    without = simulate(dict(common, seed=35, water={"layers": [body, body]},
                            tallies={"depths_m": [0.0, 4.0]}))
    for name in ("Ed", "Eu"):
        assert_same(with_thin[name][[0, 3]], with_thin.stderr(name)[[0, 3]], without[name],
                    without.stderr(name), rel_max=0.03, n_compared=4, dof=dof_of(without),
                    what=f"thin layers {name}")
    assert_same(with_thin["air/Eu"], with_thin.stderr("air/Eu"), without["air/Eu"],
                without.stderr("air/Eu"), rel_max=0.03, dof=dof_of(without),
                what="thin layers air/Eu")


@pytest.mark.parametrize("mode", ["implicit", "analog"])
@pytest.mark.parametrize("b", [0.0, 0.5])
def test_white_mirror_bottom_terminates(mode, b):
    """A specular bottom of reflectance 1 under non-absorbing water, flat surface, sun and sky:
    light bounces between mirror and surface (and is trapped by total internal reflection when
    scattered) but every photon ends, and all of it leaves: reflected + water-leaving = 1."""
    r = small({"illumination": {"Ed0": 1.0, "sun_zenith_deg": 30.0, "diffuse_fraction": 0.5},
               "surface": {"model": "flat", "n_water": N},
               "water": {"layers": [{"thickness_m": 2.0, "a": 0.0, "b": b,
                                     "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
               "bottom": {"model": "specular", "reflectance": 1.0},
               "estimator": {"mode": mode}, "tallies": {"depths_m": [0.0, 2.0]}},
              photons=200_000)
    out = r["budget/surface_reflection"] + r["budget/water_leaving"]
    zr(r, out, 1.0, r.stderr("budget/total"), abs_max=5e-3, what="mirror: all light leaves")
    assert r["budget/absorbed_bottom"] == 0.0
    assert r["budget/absorbed_layer_1"] == 0.0


def test_grazing_collimated_sun_scalar_irradiance_is_exact():
    """The unscattered solar beam gets the exact 1/|mu| even below grazing_mu_cut: with the sun
    at 89.9 deg and no interface, Eod = Ed0 / cos(89.9 deg) = 572.96 at 0+ and at 0-."""
    r = oceanmc.simulate({"photons": 2000, "batches": 4,
                          "illumination": {"sun_zenith_deg": 89.9}, "surface": {"model": "none"},
                          "water": {"layers": [{"thickness_m": 1, "a": 0.0, "b": 0.0}]},
                          "bottom": {"model": "black"}, "tallies": {"depths_m": [0]}})
    expected = 1.0 / math.cos(math.radians(89.9))
    assert r["air/Eod"] == pytest.approx(expected, rel=1e-9)
    assert r["Eod"][0] == pytest.approx(expected, rel=1e-9)


def test_sea_surface_rho_with_the_sun_in_the_polar_cap_is_one_value_across_the_cap(tmp_path):
    """air/rho under a sky map with the sun at the zenith, its beam in the downward polar cap,
    the mirror of the nadir-viewing cap: a cap is one quad, so rho is the same in each of its
    phi columns (the sun's beam, then taken out of the run's own estimate of the cap's sky
    radiance, was subtracted twice from column 0 until 2026-11-29, which left rho 0 there; the
    denominator is now the map's own radiance over the cap)."""
    np.save(tmp_path / "sky.npy", np.ones((9, 36)))   # a uniform sky as a map
    r = simulate(absorber_config(illumination={"Ed0": 1.0, "sun_zenith_deg": 0.0,
                                               "diffuse_fraction": 0.5,
                                               "sky": {"map": str(tmp_path / "sky.npy")}}))
    rho = r["air/rho"]
    cap = rho[-1]   # theta 175-180 deg: looking straight down at the sea
    assert np.all(cap > 0.0) and np.all(cap == cap[0]), cap


@pytest.mark.parametrize("sky", ["uniform", "cardioidal", "harrison_coombes"])
def test_sea_surface_rho_of_a_flat_sea_is_fresnel_at_few_photons(sky):
    """air/rho of a flat sea in the nadir-viewing cap is the Fresnel reflectance at normal
    incidence, ((n - 1) / (n + 1))^2 = 0.0211 for n = 1.34 (varying by 1e-5 over the cap's
    5 deg), whatever the sky, already at 10^4 photons: its denominator is the sky's own
    radiance over the mirror cap. (Each batch's ratio of two estimates, 0 where a batch put
    no sky photon in the mirror cap, read 0.0073 +- 0.0018 here; a user's review.)
    |z| < 4 against the batch standard error."""
    r = oceanmc.simulate({
        "photons": 10_000, "seed": 5,
        "illumination": {"sun_zenith_deg": 30, "diffuse_fraction": 0.2, "sky": sky},
        "surface": {"model": "flat", "n_water": 1.34},
        "water": {"layers": [{"thickness_m": math.inf, "a": 0.05, "b": 0.2,
                              "phase": {"model": "fournier_forand", "bb_ratio": 0.02}}]},
        "bottom": {"model": "none"}, "tallies": {"depths_m": [0]}})
    fresnel = ((1.34 - 1.0) / (1.34 + 1.0)) ** 2
    value, err = r["air/rho"][-1, 0], r.stderr("air/rho")[-1, 0]
    assert err > 0.0 and abs(value - fresnel) < 4.0 * err, (value, err, fresnel)
