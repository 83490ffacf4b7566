"""DISORT references through PythonicDISORT (Ho 2024, a Python port of Stamnes et al.'s DISORT).

Conventions, PythonicDISORT -> oceanmc (each one is checked numerically in the report):

- Optical depth tau is measured from the top down in both; oceanmc depth z maps to
  tau = (a + b) z in a homogeneous slab.
- Polar angle: DISORT's mu > 0 is UPWARD travel, mu < 0 downward. oceanmc's theta is measured
  from nadir of the travel direction, so mu_DISORT = -cos(theta_oceanmc).
- Azimuth: DISORT's intensity depends on cos(m (phi0 - phi)) with phi the azimuth of the travel
  direction and phi0 that of the incident beam's travel direction (the forward-scattering peak of
  downward radiance sits at phi = phi0). With phi0 = 0, DISORT's phi is oceanmc's phi (measured
  from the sun's travel azimuth); the field is symmetric about the principal plane, so the sign of
  phi does not matter.
- Beam: PythonicDISORT's I0 is the beam's flux on a plane normal to the beam; its horizontal flux
  is I0 mu0. oceanmc normalises to Ed(0+) = 1 on the horizontal, so I0 = 1/mu0.
- Fluxes are energetic (not divided by pi). Fm(tau) returns (diffuse, direct) downward flux; the
  direct beam I0 mu0 exp(-tau/mu0) is NOT in the diffuse part, while oceanmc's Ed includes it, so
  Ed_ref = diffuse + direct. Likewise the intensity function u is diffuse only; oceanmc's quad
  average of the quad holding the sun's direction includes the unscattered beam, so the reference
  adds exp(-tau/mu0) / (mu0 Omega_q) there.
- Lambertian bottom of reflectance rho: BDRF_Fourier_modes = [rho] (reflected intensity
  rho/pi times the incident horizontal flux); black bottom: no BDRF. Top: no incoming diffuse
  light (surface: none in oceanmc, no refractive interface).
- Phase function: Henyey-Greenstein, Legendre moments g^l. The solver runs with delta-M scaling
  (f = g^NLeg) and Nakajima-Tanaka corrections evaluated at the interpolation angles
  (interpolate(u, NT_cor="eval")), 128 streams. A second solve with 96 streams gives the
  reference's own error estimate, which enters the z-scores.
- Quad averages: the DISORT radiance is integrated over each oceanmc quad with Gauss-Legendre
  nodes in mu and phi (the polar caps over all azimuths), with the crossing estimator's grazing
  rule (2 mu / mu_cut weight below mu_cut) applied in the band next to the horizontal.
"""
from __future__ import annotations

import contextlib
import ctypes
import glob
import math
import os
import warnings

import numpy as np

N_MU_NODES = 10
N_PHI_NODES = 8


@contextlib.contextmanager
def single_blas_thread():
    """Best effort: run numpy's OpenBLAS on one thread (DISORT's many small solves are several
    times slower with BLAS threads competing with each other and with the photon kernel)."""
    restore = []
    try:
        libdir = os.path.join(os.path.dirname(np.__file__), os.pardir, "numpy.libs")
        for path in glob.glob(os.path.join(libdir, "*openblas*")):
            lib = ctypes.CDLL(path)
            for get, put in (("scipy_openblas_get_num_threads64_",
                              "scipy_openblas_set_num_threads64_"),
                             ("openblas_get_num_threads", "openblas_set_num_threads")):
                if hasattr(lib, get) and hasattr(lib, put):
                    before = int(getattr(lib, get)())
                    getattr(lib, put)(1)
                    restore.append((getattr(lib, put), before))
                    break
    except OSError:
        pass
    try:
        yield
    finally:
        for put, before in restore:
            put(before)


def _solve(tau, w0, g, mu0, rho, nquad):
    """g: Henyey-Greenstein's asymmetry, or the Legendre moments chi_l (chi_0 = 1) of another
    phase function (delta-M truncation f = chi_nquad when positive)."""
    from PythonicDISORT import pydisort, subroutines
    nleg_all = 600
    if np.ndim(g) == 0:
        leg = np.asarray(g, dtype=np.float64) ** np.arange(nleg_all)
    else:
        leg = np.zeros(max(nleg_all, nquad + 1))
        leg[:min(len(g), len(leg))] = np.asarray(g, dtype=np.float64)[:len(leg)]
    nleg = nquad
    f = float(leg[nleg]) if leg[nleg] > 1e-12 else 0.0
    kwargs = dict(NLeg=nleg, NFourier=min(nquad, 64), f_arr=f, NT_cor=f > 0.0)
    if rho > 0.0:
        kwargs["BDRF_Fourier_modes"] = [float(rho)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _, fp, fm, _, u = pydisort(np.array([tau]), np.array([w0]), nquad, leg[None, :], mu0,
                                   1.0 / mu0, 0.0, **kwargs)
        ui = subroutines.interpolate(u, NT_cor="eval" if f > 0.0 else None)
    return fp, fm, ui


def _band_nodes(theta_lo, theta_hi, mu_cut, n):
    """(|mu| nodes, weights) whose weighted sum is the band average with the grazing rule."""
    lo = 0.0 if theta_lo == 90.0 else abs(math.cos(math.radians(theta_lo)))
    hi = 0.0 if theta_hi == 90.0 else abs(math.cos(math.radians(theta_hi)))
    lo, hi = min(lo, hi), max(lo, hi)
    x, w = np.polynomial.legendre.leggauss(n)
    nodes, weights = [], []
    pieces = [(max(lo, mu_cut), hi, False), (lo, min(hi, mu_cut), True)]
    for a, b, grazing in pieces:
        if b <= a:
            continue
        m = a + (b - a) * 0.5 * (x + 1.0)
        ww = (b - a) * 0.5 * w
        if grazing:
            ww = ww * 2.0 * m / mu_cut
        nodes.append(m)
        weights.append(ww)
    return np.concatenate(nodes), np.concatenate(weights) / (hi - lo)


def slab(tau: float, w0: float, g: float, sun_zenith_deg: float, rho: float,
         tau_levels, theta_edges, phi_edges, is_cap, mu_cut: float, nquad: int = 128,
         n_mu: int = N_MU_NODES, n_phi: int = N_PHI_NODES) -> dict:
    """Fluxes and quad-averaged radiances (oceanmc grid) of a homogeneous slab from DISORT.
    Returns Ed, Eu (levels) and radiance (levels, theta, phi), all per unit Ed(0+). g: HG's
    asymmetry or a phase function's Legendre moments (_solve)."""
    mu0 = math.cos(math.radians(sun_zenith_deg))
    fp, fm, ui = _solve(tau, w0, g, mu0, rho, nquad)
    levels = np.asarray(tau_levels, dtype=np.float64)
    diffuse, direct = fm(levels)
    ed = np.asarray(diffuse) + np.asarray(direct)
    eu = np.asarray(fp(levels))

    theta_edges = np.asarray(theta_edges, dtype=np.float64)
    phi_edges = np.asarray(phi_edges, dtype=np.float64)
    n_t, n_p = len(theta_edges) - 1, len(phi_edges) - 1
    # mu nodes for every theta band, in DISORT's sign convention (mu > 0 upward)
    mu_nodes, mu_w, mu_band = [], [], []
    for i in range(n_t):
        m, w = _band_nodes(theta_edges[i], theta_edges[i + 1], mu_cut, n_mu)
        sign = -1.0 if theta_edges[i + 1] <= 90.0 else 1.0   # downward bands: mu_DISORT < 0
        mu_nodes.append(sign * m)
        mu_w.append(w)
        mu_band.append(np.full(len(m), i))
    mu_nodes = np.concatenate(mu_nodes)
    mu_w = np.concatenate(mu_w)
    mu_band = np.concatenate(mu_band)
    x, w = np.polynomial.legendre.leggauss(n_phi)
    phi_nodes, phi_w = [], []
    for j in range(n_p):
        a, b = math.radians(phi_edges[j]), math.radians(phi_edges[j + 1])
        phi_nodes.append(a + (b - a) * 0.5 * (x + 1.0))
        phi_w.append(0.5 * w)            # band average: weights sum to 1 per phi band
    phi_nodes = np.mod(np.concatenate(phi_nodes), 2.0 * math.pi)
    phi_w = np.concatenate(phi_w)
    phi_band = np.repeat(np.arange(n_p), n_phi)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        values = np.asarray(ui(mu_nodes, levels, phi_nodes))    # (mu, tau, phi)
    values = values.reshape(len(mu_nodes), len(levels), len(phi_nodes))
    rad = np.zeros((len(levels), n_t, n_p))
    for i in range(n_t):
        sel = mu_band == i
        over_mu = np.einsum("m,mlp->lp", mu_w[sel], values[sel])   # (levels, phi nodes)
        if is_cap[i]:
            rad[:, i, :] = (over_mu @ phi_w / n_p)[:, None]
        else:
            for j in range(n_p):
                s = phi_band == j
                rad[:, i, j] = over_mu[:, s] @ phi_w[s]

    # the unscattered beam, in the quad holding the sun's travel direction (phi = 0)
    omega = np.abs(np.diff(np.cos(np.radians(theta_edges))))[:, None] \
        * np.radians(np.diff(phi_edges))[None, :]
    omega[is_cap, :] = 2.0 * math.pi * np.abs(np.diff(np.cos(np.radians(theta_edges))))[is_cap,
                                                                                        None]
    i_sun = int(np.searchsorted(theta_edges, sun_zenith_deg, side="right") - 1)
    j_sun = 0 if is_cap[i_sun] else int(np.searchsorted(phi_edges, 0.0, side="right") - 1) % n_p
    beam = np.exp(-levels / mu0) / (mu0 * omega[i_sun, j_sun])
    if is_cap[i_sun]:
        rad[:, i_sun, :] += beam[:, None]
    else:
        rad[:, i_sun, j_sun] += beam
    return {"Ed": ed, "Eu": eu, "radiance": rad, "sun_quad": (i_sun, j_sun)}


def point_radiance(tau, w0, g, sun_zenith_deg, rho, tau_levels, mu_travel, phi_rad,
                   nquad: int = 128) -> np.ndarray:
    """Diffuse radiance (levels, directions) per unit Ed(0+) in exact directions given by the
    oceanmc travel cosine mu_travel = cos(theta) (negative: upward) and phi (radians)."""
    mu0 = math.cos(math.radians(sun_zenith_deg))
    _, _, ui = _solve(tau, w0, g, mu0, rho, nquad)
    mu_d = -np.asarray(mu_travel, dtype=np.float64)        # DISORT: mu > 0 upward
    phi = np.asarray(phi_rad, dtype=np.float64)
    out = np.empty((len(tau_levels), len(mu_d)))
    # Straight up or down the radiance has no azimuth, and every Fourier mode m >= 1 vanishes
    # (it carries P_l^m(mu), zero at |mu| = 1); PythonicDISORT's interpolated modes do not (at
    # tau 2, w0 0.5, g 0.5, sun 40, Lambertian 0.8 the zenith value at phi = 0 came out 0.28% high,
    # 0.09% apart between 96 and 128 streams). There the azimuthal mean over 2 n_fourier azimuths,
    # which keeps the m = 0 mode only, is taken instead.
    polar_azimuths = np.linspace(0.0, 2.0 * math.pi, 2 * min(nquad, 64), endpoint=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k, (m, p) in enumerate(zip(mu_d, phi)):
            polar = abs(abs(m) - 1.0) < 1e-12
            v = np.asarray(ui(np.array([m]), np.asarray(tau_levels, dtype=np.float64),
                              polar_azimuths if polar else np.array([p])))
            out[:, k] = v.reshape(len(tau_levels), -1).mean(axis=1)
    return out


def forward_peak_azimuth_check(g: float = 0.9) -> tuple[float, float]:
    """Downward diffuse radiance at the beam's own polar angle, at phi = phi0 and phi0 + pi, in a
    thin forward-scattering slab: the first is much larger when phi is the travel azimuth."""
    mu0 = 0.5
    _, _, ui = _solve(0.3, 0.9, g, mu0, 0.0, 32)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        v = np.asarray(ui(np.array([-0.55]), np.array([0.3]), np.array([0.0, math.pi])))
    v = v.reshape(-1)
    return float(v[0]), float(v[1])
