"""Analytic references, written here independently of the kernel (numpy/scipy only).

- Fresnel reflectance of a flat interface (unpolarized, exact) and Snell's law;
- cosine-weighted surface reflectances under uniform and cardioidal skies, and the reflectance for
  uniform upwelling radiance from below (total internal reflection included);
- Lambertian and Minnaert BRDFs: directional-hemispherical reflectance and reflected radiance;
- Chandrasekhar's H-function for isotropic scattering, the plane albedo of a semi-infinite medium
  and its reflected radiance;
- quad (solid-angle) averages of azimuthally symmetric radiance fields, including the expectation
  of the crossing estimator's grazing rule (1/|mu| replaced by 2/mu_cut below mu_cut; see
  oceanmc/kernel/tally.py), so that a reference is what the estimator should return on average.
"""
from __future__ import annotations

import functools
import math

import numpy as np
from scipy import integrate

# --- Fresnel / Snell -----------------------------------------------------------------------------


def fresnel(n1: float, n2: float, cos_i):
    """Unpolarized Fresnel reflectance (Rs + Rp)/2 for light going from index n1 into n2 at
    incidence cosine cos_i (0..1); 1 beyond the critical angle. Vectorized."""
    cos_i = np.clip(np.asarray(cos_i, dtype=np.float64), 0.0, 1.0)
    sin_t2 = (n1 / n2) ** 2 * (1.0 - cos_i ** 2)
    tir = sin_t2 >= 1.0
    cos_t = np.sqrt(np.clip(1.0 - sin_t2, 0.0, 1.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t)
        rp = (n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i)
        r = 0.5 * (rs * rs + rp * rp)
    r = np.where(tir | ~np.isfinite(r), 1.0, r)
    return r if r.ndim else float(r)


def fresnel_angle_form(n1: float, n2: float, theta_i):
    """The same reflectance from the angle forms Rs = sin^2(ti - tt)/sin^2(ti + tt),
    Rp = tan^2(ti - tt)/tan^2(ti + tt) (a second, algebraically different implementation used
    to check the first); theta_i in radians, 0 < theta_i < critical angle."""
    ti = np.asarray(theta_i, dtype=np.float64)
    tt = np.arcsin(n1 / n2 * np.sin(ti))
    rs = np.sin(ti - tt) ** 2 / np.sin(ti + tt) ** 2
    rp = np.tan(ti - tt) ** 2 / np.tan(ti + tt) ** 2
    return 0.5 * (rs + rp)


def schlick(n1: float, n2: float, cos_i):
    """Schlick's approximation with the cosine on the less dense side (for figures only)."""
    cos_i = np.asarray(cos_i, dtype=np.float64)
    r0 = ((n1 - n2) / (n1 + n2)) ** 2
    sin_t2 = (n1 / n2) ** 2 * (1.0 - cos_i ** 2)
    cos_t = np.sqrt(np.clip(1.0 - sin_t2, 0.0, 1.0))
    c = cos_i if n1 <= n2 else cos_t
    return np.where(sin_t2 >= 1.0, 1.0, r0 + (1.0 - r0) * (1.0 - c) ** 5)


def refracted_cos(n1: float, n2: float, cos_i):
    """Cosine of the refracted angle (Snell), NaN beyond the critical angle."""
    cos_i = np.asarray(cos_i, dtype=np.float64)
    sin_t2 = (n1 / n2) ** 2 * (1.0 - cos_i ** 2)
    with np.errstate(invalid="ignore"):
        return np.where(sin_t2 <= 1.0, np.sqrt(1.0 - sin_t2), np.nan)


def critical_angle_deg(n: float) -> float:
    return math.degrees(math.asin(1.0 / n))


def _quad(f, a, b, points=None):
    pts = None
    if points:
        pts = [p for p in points if a < p < b] or None
    value, _ = integrate.quad(f, a, b, points=pts, epsabs=1e-13, epsrel=1e-11, limit=400)
    return value


def sky_reflectance(n: float, sky: str = "uniform") -> float:
    """Fraction of the downward plane irradiance from a sky of the given shape that a flat
    surface reflects: integral of R(mu) L(mu) mu dmu / integral of L(mu) mu dmu."""
    shape = (lambda mu: 1.0) if sky == "uniform" else (lambda mu: 1.0 + 2.0 * mu)
    num = _quad(lambda mu: fresnel(1.0, n, mu) * shape(mu) * mu, 0.0, 1.0)
    den = _quad(lambda mu: shape(mu) * mu, 0.0, 1.0)
    return num / den


def uniform_upwelling_reflectance(n: float) -> float:
    """Water-to-air reflectance for uniform upwelling radiance, TIR included:
    2 * integral of R_wa(mu) mu dmu over the water-side hemisphere."""
    mu_c = math.sqrt(1.0 - 1.0 / n ** 2)
    inside = _quad(lambda mu: fresnel(n, 1.0, mu) * 2.0 * mu, mu_c, 1.0)
    return inside + mu_c ** 2   # R = 1 for mu < mu_c: integral of 2 mu = mu_c^2


def sky_radiance_constant(sky: str) -> float:
    """C in L(theta) = C * shape(theta) for unit Ed(0+): uniform 1/pi, cardioidal 3/(7 pi)."""
    return 1.0 / math.pi if sky == "uniform" else 3.0 / (7.0 * math.pi)


def sky_shape(sky: str, mu_air):
    mu_air = np.asarray(mu_air, dtype=np.float64)
    return np.ones_like(mu_air) if sky == "uniform" else 1.0 + 2.0 * mu_air


def radiance_below_surface(n: float, sky: str, mu_w):
    """Downwelling radiance just below a flat surface (unit Ed(0+), sky only), at water-side
    cosine mu_w: t(theta_a) n^2 L_sky(theta_a) inside Snell's window, 0 outside."""
    mu_w = np.asarray(mu_w, dtype=np.float64)
    sin_a2 = n * n * (1.0 - mu_w ** 2)
    inside = sin_a2 < 1.0
    mu_a = np.sqrt(np.clip(1.0 - sin_a2, 0.0, 1.0))
    val = (1.0 - fresnel(1.0, n, mu_a)) * n * n * sky_radiance_constant(sky) * sky_shape(sky, mu_a)
    return np.where(inside, val, 0.0)


# --- quad averages --------------------------------------------------------------------------------


def band_mu(theta_lo_deg: float, theta_hi_deg: float) -> tuple[float, float]:
    """|cos theta| range (lo, hi) of a theta band (deg) on one side of the horizontal."""
    c = [0.0 if t == 90.0 else abs(math.cos(math.radians(t))) for t in (theta_lo_deg, theta_hi_deg)]
    return min(c), max(c)


def band_average(f, mu_lo: float, mu_hi: float, mu_cut: float = 0.0, points=None) -> float:
    """Expected crossing-estimator value of the solid-angle average over |mu| in [mu_lo, mu_hi] of
    an azimuthally symmetric radiance f(|mu|): (1/dmu) [integral of f over mu >= mu_cut + integral
    of f(mu) 2 mu / mu_cut below mu_cut] (the grazing rule; exact when f is constant there)."""
    total = 0.0
    a = max(mu_lo, mu_cut)
    if mu_hi > a:
        total += _quad(f, a, mu_hi, points)
    b = min(mu_hi, mu_cut)
    if b > mu_lo:
        total += _quad(lambda mu: f(mu) * 2.0 * mu / mu_cut, mu_lo, b, points)
    return total / (mu_hi - mu_lo)


def band_averages(f, theta_edges_deg, mu_cut: float, points=None) -> np.ndarray:
    """band_average for every theta band of a grid (f a function of |mu| only)."""
    edges = np.asarray(theta_edges_deg, dtype=np.float64)
    out = np.empty(len(edges) - 1)
    for i in range(len(edges) - 1):
        lo, hi = band_mu(edges[i], edges[i + 1])
        out[i] = band_average(f, lo, hi, mu_cut, points)
    return out


# --- BRDFs ----------------------------------------------------------------------------------------


def minnaert_rho_dh(rho: float, k: float, mu_i) -> np.ndarray:
    """Directional-hemispherical reflectance 2 rho mu_i^k / (k + 2) (k = 0: Lambertian rho)."""
    return 2.0 * rho * np.asarray(mu_i, dtype=np.float64) ** k / (k + 2.0)


def minnaert_radiance(rho: float, k: float, mu_i: float, mu_r):
    """Reflected radiance per unit horizontal irradiance: (rho/pi) (mu_i mu_r)^k."""
    return rho / math.pi * (mu_i * np.asarray(mu_r, dtype=np.float64)) ** k


# --- Chandrasekhar --------------------------------------------------------------------------------


@functools.lru_cache(maxsize=4096)
def _h(mu: float, w0: float) -> float:
    """H(mu) for isotropic scattering with albedo w0 from Chandrasekhar's closed form
    ln H(mu) = -(mu/pi) int_0^{pi/2} ln(1 - w0 t cot t) / (cos^2 t + mu^2 sin^2 t) dt
    (Radiative Transfer, 1950, ch. V, eq. 41)."""
    if mu == 0.0:
        return 1.0

    def integrand(t):
        tcot = 1.0 if t == 0.0 else t / math.tan(t)
        return math.log(1.0 - w0 * tcot) / (math.cos(t) ** 2 + mu * mu * math.sin(t) ** 2)

    value, _ = integrate.quad(integrand, 0.0, math.pi / 2, epsabs=1e-13, epsrel=1e-12, limit=400)
    return math.exp(-mu / math.pi * value)


def chandrasekhar_h(mu, w0: float):
    mu = np.asarray(mu, dtype=np.float64)
    out = np.vectorize(lambda m: _h(float(m), float(w0)))(mu)
    return out if out.ndim else float(out)


def chandrasekhar_h_iterative(mu: float, w0: float, n: int = 200) -> float:
    """The same H from the integral equation H = 1 + (w0/2) mu H int H(mu')/(mu + mu') dmu',
    solved by iteration on Gauss-Legendre nodes (a second implementation for the self-check)."""
    x, w = np.polynomial.legendre.leggauss(n)
    x = 0.5 * (x + 1.0)
    w = 0.5 * w
    h = np.ones(n)
    for _ in range(5000):
        h_new = 1.0 / (1.0 - 0.5 * w0 * x * np.sum(w * h / (x[:, None] + x[None, :]), axis=1))
        if np.max(np.abs(h_new - h)) < 1e-14:
            h = h_new
            break
        h = h_new
    return float(1.0 / (1.0 - 0.5 * w0 * mu * np.sum(w * h / (mu + x))))


def chandrasekhar_albedo(w0: float, mu0: float) -> float:
    """Plane albedo of a semi-infinite isotropic scatterer: 1 - H(mu0) sqrt(1 - w0)."""
    return 1.0 - chandrasekhar_h(mu0, w0) * math.sqrt(1.0 - w0)


def chandrasekhar_radiance(w0: float, mu0: float, mu):
    """Reflected radiance per unit horizontal irradiance: w0 H(mu) H(mu0) / (4 pi (mu + mu0))."""
    mu = np.asarray(mu, dtype=np.float64)
    return w0 * chandrasekhar_h(mu, w0) * chandrasekhar_h(mu0, w0) / (4.0 * math.pi * (mu + mu0))
