"""Compiled loops run once per scene (scene/brdf_tables.py) or by tests, never in the photon loop:
integrals of f cos over outgoing cells for a grid of incident directions (the general sampler's
tables and the energy check), f at pairs of directions both ways (the reciprocity check), and
batches of samples, values and densities."""
import math

import numpy as np

from ..compile import setup
from .dispatch import evaluate_local, pdf_local, sample_local


@setup
def cell_integrals(model, params, theta_i, phi_i, n_t, n_p, gx, gw):
    """out[a, b, c, r] = integral of f(wi_ab, wo) cos(theta_o) over the outgoing cell (dphi band
    c of n_p over [0, 2 pi) relative to phi_i[b], theta_o band r of n_t over [0, pi/2]), with a
    Gauss rule (nodes gx, weights gw on [0, 1]) in s = cos^2(theta_o) and dphi within each cell
    (f cos dOmega = f ds dphi / 2). Also returns the smallest f met and where."""
    n_ti = theta_i.shape[0]
    n_pi = phi_i.shape[0]
    m = gx.shape[0]
    out = np.zeros((n_ti, n_pi, n_p, n_t))
    dt = 0.5 * math.pi / n_t
    dp = 2.0 * math.pi / n_p
    f_min = math.inf
    where = np.zeros(4)
    for a in range(n_ti):
        st = math.sin(theta_i[a])
        wiz = math.cos(theta_i[a])
        for b in range(n_pi):
            wix = st * math.cos(phi_i[b])
            wiy = st * math.sin(phi_i[b])
            for r in range(n_t):
                s_hi = math.cos(r * dt) ** 2
                s_lo = math.cos((r + 1) * dt) ** 2
                ds = s_hi - s_lo
                for c in range(n_p):
                    total = 0.0
                    for k in range(m):
                        s = s_lo + gx[k] * ds
                        mu = math.sqrt(s)
                        so = math.sqrt(max(0.0, 1.0 - s))
                        for j in range(m):
                            phi = phi_i[b] + (c + gx[j]) * dp
                            f = evaluate_local(model, params, wix, wiy, wiz, so * math.cos(phi),
                                               so * math.sin(phi), mu)
                            if f < f_min:
                                f_min = f
                                where[0] = theta_i[a]
                                where[1] = phi_i[b]
                                where[2] = math.acos(mu)
                                where[3] = (c + gx[j]) * dp
                            total += gw[k] * gw[j] * f
                    out[a, b, c, r] = 0.5 * total * ds * dp
    return out, f_min, where


@setup
def both_ways(model, params, wi, wo):
    """(f(wi_k, wo_k), f(wo_k, wi_k)) for rows of unit vectors wi, wo (n, 3)."""
    n = wi.shape[0]
    out = np.empty((n, 2))
    for k in range(n):
        out[k, 0] = evaluate_local(model, params, wi[k, 0], wi[k, 1], wi[k, 2],
                                   wo[k, 0], wo[k, 1], wo[k, 2])
        out[k, 1] = evaluate_local(model, params, wo[k, 0], wo[k, 1], wo[k, 2],
                                   wi[k, 0], wi[k, 1], wi[k, 2])
    return out


@setup
def sample_many(model, params, wix, wiy, wiz, u1, u2):
    """Rows (wox, woy, woz, weight) of sample_local for one incidence and arrays of randoms."""
    n = u1.shape[0]
    out = np.empty((n, 4))
    for k in range(n):
        wox, woy, woz, w = sample_local(model, params, wix, wiy, wiz, u1[k], u2[k])
        out[k, 0] = wox
        out[k, 1] = woy
        out[k, 2] = woz
        out[k, 3] = w
    return out


@setup
def f_and_pdf(model, params, wix, wiy, wiz, wo):
    """Rows (f, pdf) at the outgoing directions wo (n, 3) for one incidence."""
    n = wo.shape[0]
    out = np.empty((n, 2))
    for k in range(n):
        out[k, 0] = evaluate_local(model, params, wix, wiy, wiz, wo[k, 0], wo[k, 1], wo[k, 2])
        out[k, 1] = pdf_local(model, params, wix, wiy, wiz, wo[k, 0], wo[k, 1], wo[k, 2])
    return out
