"""Bottom BRDF samplers (local frame, normal +z, wi towards the light): sampled directions against
the pdf (chi-square over theta x phi cells), the weight == f cos / pdf identity at sampled
directions, the weighted histogram against the integral of f cos over each cell (the quantity a
photon tracer estimates), Minnaert's rho_dh = 2 rho cos^k(t_i)/(k+2), reciprocity and energy
conservation, and the global <-> local frame change of dispatch.reflect."""
import math

import numpy as np
import pytest
from numba import njit
from scipy import integrate

from oceanmc.kernel import models
from oceanmc.kernel.brdf import dispatch, lambertian, minnaert, specular

from stats_helpers import assert_chi2, assert_z

N_SAMPLES = 400_000
THETA_EDGES = np.radians(np.arange(0.0, 90.1, 7.5))   # 12 bands
PHI_EDGES = np.linspace(0.0, 2.0 * math.pi, 13)        # 12 bands


@njit(cache=False)
def _sample_many(model, params, wix, wiy, wiz, u1, u2):
    n = u1.shape[0]
    out = np.empty((n, 4))
    for i in range(n):
        wox, woy, woz, w = dispatch.sample_local(model, params, wix, wiy, wiz, u1[i], u2[i])
        out[i, 0] = wox
        out[i, 1] = woy
        out[i, 2] = woz
        out[i, 3] = w
    return out


@njit(cache=False)
def _f_and_pdf(model, params, wix, wiy, wiz, wo):
    n = wo.shape[0]
    out = np.empty((n, 2))
    for i in range(n):
        out[i, 0] = dispatch.evaluate_local(model, params, wix, wiy, wiz, wo[i, 0], wo[i, 1],
                                            wo[i, 2])
        out[i, 1] = dispatch.pdf_local(model, params, wix, wiy, wiz, wo[i, 0], wo[i, 1],
                                       wo[i, 2])
    return out


def incident(theta_i_deg, phi_i_deg=30.0):
    t, p = math.radians(theta_i_deg), math.radians(phi_i_deg)
    return math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)


def draw(model, params, wi, n=N_SAMPLES, seed=1):
    rng = np.random.default_rng(seed)
    out = _sample_many(model, np.array(params + [0.0] * (4 - len(params))), *wi,
                       rng.random(n), rng.random(n))
    assert np.all(np.isfinite(out))
    norm = np.linalg.norm(out[:, :3], axis=1)
    np.testing.assert_allclose(norm, 1.0, atol=1e-12)
    assert np.all(out[:, 2] >= 0.0), "reflected direction below the surface"
    return out


def cell_counts(wo, weights=None):
    theta = np.arccos(np.clip(wo[:, 2], -1.0, 1.0))
    phi = np.mod(np.arctan2(wo[:, 1], wo[:, 0]), 2.0 * math.pi)
    h, _, _ = np.histogram2d(theta, phi, bins=[THETA_EDGES, PHI_EDGES], weights=weights)
    return h


def assert_directions(counts, probs, what):
    """Chi-square over the theta x phi cells, then over each marginal with the power check."""
    assert_chi2(counts, probs, rel_cap=None, what=what)
    assert_chi2(counts.sum(axis=1), probs.sum(axis=1), what=what + " (theta marginal)")
    assert_chi2(counts.sum(axis=0), probs.sum(axis=0), what=what + " (phi marginal)")


def cosine_power_cell_probs(power):
    """Cell probabilities of pdf ~ cos^power(theta) (phi uniform): the band probability is
    mu^(power + 1) between its edges, normalised."""
    mu = np.cos(THETA_EDGES)
    band = mu[:-1] ** (power + 1) - mu[1:] ** (power + 1)
    return np.outer(band, np.diff(PHI_EDGES) / (2.0 * math.pi))


def f_cos_cell_integral(f_of_mu_o):
    """Integral of f(mu_o) cos(theta_o) over each (theta, phi) cell, for an f without phi_o
    dependence (true of Lambertian and Minnaert)."""
    band = np.array([integrate.quad(lambda t: f_of_mu_o(math.cos(t)) * math.cos(t) * math.sin(t),
                                    a, b, epsabs=1e-14)[0]
                     for a, b in zip(THETA_EDGES[:-1], THETA_EDGES[1:])])
    return np.outer(band, np.diff(PHI_EDGES))


# --- Lambertian -------------------------------------------------------------------------------

@pytest.mark.parametrize("theta_i", [0.0, 45.0, 80.0])
def test_lambertian(theta_i):
    rho = 0.37
    wi = incident(theta_i)
    out = draw(models.BOTTOM_LAMBERTIAN, [rho], wi, seed=int(theta_i) + 1)
    wo, weight = out[:, :3], out[:, 3]
    # cosine-weighted directions: pdf = cos/pi, whatever the incidence
    assert_directions(cell_counts(wo), cosine_power_cell_probs(1.0), f"Lambertian {theta_i}")
    # weight = f cos / pdf = rho, the directional-hemispherical reflectance
    fp = _f_and_pdf(models.BOTTOM_LAMBERTIAN, np.array([rho, 0, 0, 0.0]), *wi, wo[:2000])
    np.testing.assert_allclose(fp[:, 0], rho / math.pi, rtol=1e-14)
    np.testing.assert_allclose(fp[:, 1], wo[:2000, 2] / math.pi, rtol=1e-12)
    np.testing.assert_allclose(weight[:2000], fp[:, 0] * wo[:2000, 2] / fp[:, 1], rtol=1e-12)
    np.testing.assert_allclose(weight, rho, rtol=0, atol=0)


# --- Minnaert ---------------------------------------------------------------------------------

MINNAERT_CASES = [(k, t) for k in (0.0, 0.5, 1.0, 2.0, 5.0) for t in (0.0, 30.0, 60.0, 85.0)]


def minnaert_f(rho, k, mu_i, mu_o):
    return rho / math.pi * (mu_i * mu_o) ** k


@pytest.mark.parametrize("k, theta_i", MINNAERT_CASES)
def test_minnaert(k, theta_i):
    rho = 0.6
    wi = incident(theta_i)
    mu_i = wi[2]
    params = np.array([rho, k, 0.0, 0.0])
    out = draw(models.BOTTOM_MINNAERT, [rho, k], wi, n=200_000,
               seed=int(10 * k) * 100 + int(theta_i))
    wo, weight = out[:, :3], out[:, 3]
    # the sampling pdf (k + 2) cos^(k+1)/(2 pi)
    assert_directions(cell_counts(wo), cosine_power_cell_probs(k + 1.0), f"Minnaert k={k}")
    # weight == f cos / pdf at the sampled directions, and == rho_dh
    fp = _f_and_pdf(models.BOTTOM_MINNAERT, params, *wi, wo[:5000])
    f_ref = np.array([minnaert_f(rho, k, mu_i, m) for m in wo[:5000, 2]])
    np.testing.assert_allclose(fp[:, 0], f_ref, rtol=1e-12)
    np.testing.assert_allclose(weight[:5000], fp[:, 0] * wo[:5000, 2] / fp[:, 1], rtol=1e-9)
    rho_dh = 2.0 * rho * mu_i ** k / (k + 2.0)
    np.testing.assert_allclose(weight, rho_dh, rtol=1e-12)
    # rho_dh is the integral of f cos over the outgoing hemisphere
    hemi = integrate.quad(lambda m: 2.0 * math.pi * minnaert_f(rho, k, mu_i, m) * m, 0, 1)[0]
    assert rho_dh == pytest.approx(hemi, rel=1e-9)
    assert minnaert.reflectance(params, mu_i) == pytest.approx(rho_dh, rel=1e-12)
    # what the photon tracer estimates: the weighted histogram = integral of f cos per cell
    n = weight.size
    estimate = cell_counts(wo, weight) / n
    p_cell = cell_counts(wo) / n   # the weight is constant: binomial cell counts
    se = np.sqrt(p_cell * (1.0 - p_cell) / n) * rho_dh
    reference = f_cos_cell_integral(lambda m: minnaert_f(rho, k, mu_i, m))
    big = reference > 1e-3 * reference.max()
    assert_z(estimate[big], reference[big], np.maximum(se[big], 1e-300),
             what=f"Minnaert k={k} t_i={theta_i} weighted cells")
    # the same per theta band (summed over phi), with a cap on the error of the major bands
    band_est = estimate.sum(axis=1)
    band_p = p_cell.sum(axis=1)
    band_se = np.sqrt(band_p * (1.0 - band_p) / n) * rho_dh
    band_ref = reference.sum(axis=1)
    major = band_ref >= 0.05 * band_ref.sum()
    assert_z(band_est[major], band_ref[major], band_se[major], rel_max=0.05,
             what=f"Minnaert k={k} t_i={theta_i} weighted theta bands")
    assert band_est.sum() == pytest.approx(rho_dh, rel=1e-9)


def test_minnaert_pdf_normalised():
    for k in (0.0, 0.5, 2.0, 5.0):
        params = np.array([0.5, k, 0.0, 0.0])
        total = integrate.quad(
            lambda t: 2.0 * math.pi * math.sin(t) * minnaert.pdf(params, 0.0, 0.0, 1.0, math.sin(t),
                                                                  0.0, math.cos(t)),
            0.0, math.pi / 2.0)[0]
        assert total == pytest.approx(1.0, abs=1e-9)
    assert minnaert.pdf(np.array([0.5, 1.0, 0, 0]), 0, 0, 1.0, 0.0, 0.6, -0.8) == 0.0


def test_lambertian_pdf_normalised():
    params = np.array([0.5, 0.0, 0.0, 0.0])
    total = integrate.quad(lambda t: 2.0 * math.pi * math.sin(t)
                           * lambertian.pdf(params, 0.0, 0.0, 1.0, math.sin(t), 0.0, math.cos(t)),
                           0.0, math.pi / 2.0)[0]
    assert total == pytest.approx(1.0, abs=1e-12)


def test_minnaert_k0_is_lambertian():
    params = np.array([0.4, 0.0, 0.0, 0.0])
    for mu_i in (1.0, 0.5, 0.05):
        assert minnaert.reflectance(params, mu_i) == pytest.approx(0.4, rel=1e-14)
        assert minnaert.evaluate(params, math.sqrt(1 - mu_i ** 2), 0.0, mu_i, 0.0, 0.6, 0.8) \
            == pytest.approx(0.4 / math.pi, rel=1e-14)


@pytest.mark.parametrize("model, params", [(models.BOTTOM_LAMBERTIAN, [0.8, 0.0]),
                                           (models.BOTTOM_MINNAERT, [1.0, 0.0]),
                                           (models.BOTTOM_MINNAERT, [1.0, 0.7]),
                                           (models.BOTTOM_MINNAERT, [0.9, 3.0])])
def test_reciprocity_and_energy(model, params):
    """f(i, o) = f(o, i) >= 0, and the integral of f cos over the outgoing hemisphere <= 1 for
    every incidence (reflectance <= 1)."""
    p = np.array(params + [0.0, 0.0])
    rng = np.random.default_rng(2)
    for _ in range(200):
        a = rng.normal(size=3)
        b = rng.normal(size=3)
        a[2], b[2] = abs(a[2]), abs(b[2])
        a /= np.linalg.norm(a)
        b /= np.linalg.norm(b)
        fab = dispatch.evaluate_local(model, p, *a, *b)
        fba = dispatch.evaluate_local(model, p, *b, *a)
        assert fab >= 0.0
        assert fab == pytest.approx(fba, rel=1e-12)
    for theta_i in np.linspace(0.0, 89.9, 30):
        wi = incident(theta_i)
        total = integrate.dblquad(
            lambda t, ph: dispatch.evaluate_local(model, p, *wi, math.sin(t) * math.cos(ph),
                                                  math.sin(t) * math.sin(ph), math.cos(t))
            * math.cos(t) * math.sin(t), 0.0, 2.0 * math.pi, 0.0, math.pi / 2.0,
            epsabs=1e-10)[0]
        assert total <= 1.0 + 1e-9
        # and it is what sample() returns as the weight
        w = dispatch.sample_local(model, p, *wi, 0.3, 0.7)[3]
        assert w == pytest.approx(total, rel=1e-7, abs=1e-12)


def test_minnaert_albedo():
    """Bihemispherical albedo (cosine-weighted average of rho_dh) = 4 rho/(k + 2)^2."""
    for k in (0.0, 0.5, 1.0, 3.0):
        rho = 0.7
        params = np.array([rho, k, 0.0, 0.0])
        albedo = integrate.quad(lambda m: 2.0 * m * minnaert.reflectance(params, m), 0, 1)[0]
        assert albedo == pytest.approx(4.0 * rho / (k + 2.0) ** 2, rel=1e-9)


# --- specular and the frame change ------------------------------------------------------------

def test_specular():
    params = np.array([0.9, 0.0, 0.0, 0.0])
    for wi in (incident(0.0), incident(40.0, 10.0), incident(89.0, 250.0)):
        wox, woy, woz, w = specular.sample(params, *wi, 0.1, 0.9)
        assert (wox, woy, woz) == pytest.approx((-wi[0], -wi[1], wi[2]), abs=1e-15)
        assert w == 0.9


@pytest.mark.parametrize("model, params", [(models.BOTTOM_LAMBERTIAN, [0.5, 0.0]),
                                           (models.BOTTOM_MINNAERT, [0.5, 1.5]),
                                           (models.BOTTOM_SPECULAR, [0.7, 0.0])])
def test_reflect_frame(model, params):
    """dispatch.reflect takes the global travel direction (z down, uz > 0 towards the bottom)
    and returns an upward travel direction with the weight for the incidence cosine uz."""
    p = np.array(params + [0.0, 0.0])
    rng = np.random.default_rng(4)
    mu_out = []
    for _ in range(20_000):
        mu = rng.uniform(0.01, 1.0)
        phi = rng.uniform(0, 2 * math.pi)
        ux, uy, uz = math.sqrt(1 - mu * mu) * math.cos(phi), math.sqrt(1 - mu * mu) * math.sin(phi), mu
        ox, oy, oz, w = dispatch.reflect(model, p, ux, uy, uz, rng.random(), rng.random())
        assert oz < 0.0
        assert ox * ox + oy * oy + oz * oz == pytest.approx(1.0, abs=1e-12)
        if model == models.BOTTOM_SPECULAR:
            assert (ox, oy, oz) == pytest.approx((ux, uy, -uz), abs=1e-14)
            assert w == params[0]
        elif model == models.BOTTOM_MINNAERT:
            assert w == pytest.approx(2 * params[0] * mu ** params[1] / (params[1] + 2), rel=1e-12)
        else:
            assert w == params[0]
        mu_out.append(-oz)
    if model != models.BOTTOM_SPECULAR:
        # the reflected polar distribution in the global frame: pdf ~ mu^(k+1)
        k = params[1] if model == models.BOTTOM_MINNAERT else 0.0
        mean, se = np.mean(mu_out), np.std(mu_out, ddof=1) / math.sqrt(len(mu_out))
        assert_z(mean, (k + 2.0) / (k + 3.0), se, rel_max=0.01, what="reflected <mu>")
