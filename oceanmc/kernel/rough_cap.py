"""What the nadir polar cap's local estimate needs through the wind-roughened sea (setup only,
run once per scene; scene/cap_tables.py builds its tables from these).

The cap average at 0+ of the air radiance (half-angle beta about straight up, solid angle
dOmega_a) is, for any in-water radiance L_w,
    L_cap = integral over in-water directions i of L_w(i) K(i) dOmega_i,
    K(i) = 1 / (n^2 dOmega_a) integral over the cap of p_t(i | o) dOmega_o,
with p_t(i | o) the density of the direction in which light from the air, travelling -o, is
transmitted into the water (the surface's transmission lobe; by reciprocity of the dielectric
BSDF, f(i -> o) / n_air^2 = f(o -> i) / n_water^2, Veach 1997, PhD thesis, 5.2: the same
reversal as local_estimate.into_water_through_rough). K is a function of the angle of i from
straight up alone for isotropic slopes.

p_t is the single-facet transmission of Walter, Marschner, Li & Torrance (2007), "Microfacet
models for refraction through rough surfaces", EGSR, eqs. 16 and 21:
    p_t(t | o) = |o.h| |t.h| n^2 (1 - F(o.h)) D(h) / (|o.z| (o.h + n t.h)^2),   h = -(o + n t)/|.|,
with Beckmann's D(h) = exp(-tan^2 theta_h / alpha^2) / (pi alpha^2 cos^4 theta_h) (the slope
density of cox_munk.py) and the shadowing-masking G = 1: for the nadir cap (beta <= 10 deg) and
the in-water directions that receive its light, Smith's Lambda of either direction is below
exp(-(cot theta / alpha)^2) < 1e-30 for alpha < 0.5 (wind speeds to 40 m/s), so the facet walk's
light meets one facet and leaves (tests/test_rough_cap.py checks K against the walk's own
histogram)."""
import math

import numpy as np

from .compile import setup
from .surface.fresnel import fresnel


@setup
def air_cap_density(alpha, n, beta, mu_w, polar_nodes, polar_weights, azimuth_nodes):
    """K at in-water directions of cosine mu_w to straight up for the air cap of half-angle beta:
    Gauss-Legendre over the cap in (1 - cos theta_o) (polar_nodes, polar_weights on [0, 1]) and
    the midpoint rule over the azimuth (azimuth_nodes on [0, pi]; symmetric about the plane
    of i)."""
    out = np.zeros(mu_w.shape[0])
    one_minus = 1.0 - math.cos(beta)
    cap = 2.0 * math.pi * one_minus
    alpha2 = alpha * alpha
    n_phi = azimuth_nodes.shape[0]
    for w in range(mu_w.shape[0]):
        # t: the transmitted direction, pointing away from the surface into the water (z up)
        tx, tz = math.sqrt(max(0.0, 1.0 - mu_w[w] * mu_w[w])), -mu_w[w]
        total = 0.0
        for a in range(polar_nodes.shape[0]):
            oz = 1.0 - polar_nodes[a] * one_minus
            so = math.sqrt(max(0.0, 1.0 - oz * oz))
            ring = 0.0
            for b in range(n_phi):
                ox, oy = so * math.cos(azimuth_nodes[b]), so * math.sin(azimuth_nodes[b])
                hx, hy, hz = -(ox + n * tx), -oy, -(oz + n * tz)
                norm = math.sqrt(hx * hx + hy * hy + hz * hz)
                hx, hy, hz = hx / norm, hy / norm, hz / norm
                if hz <= 0.0:
                    continue
                o_h = ox * hx + oy * hy + oz * hz
                t_h = tx * hx + tz * hz
                if o_h <= 0.0 or t_h >= 0.0:
                    continue
                r = fresnel(1.0, n, o_h)[0]
                tan2 = (1.0 - hz * hz) / (hz * hz)
                d = math.exp(-tan2 / alpha2) / (math.pi * alpha2 * hz ** 4)
                den = o_h + n * t_h
                ring += o_h * -t_h * n * n * (1.0 - r) * d / (oz * den * den)
            total += polar_weights[a] * ring / n_phi
        # dOmega_o = 2 pi (1 - cos beta) d(node) over the azimuth's mean; / (n^2 dOmega_a)
        out[w] = total * cap / (n * n * cap)
    return out


@setup
def ring_averages(alphas, psi, mu_nodes, density, mu_bar, phi_nodes):
    """(A, B) at each alpha (rows) and each psi interval's midpoint (columns; psi holds each
    alpha's interval edges): the averages over the circle of directions W at angle psi from a
    direction at angle alpha from straight up of K(W) and K(W) (mu_W - mu_bar), with K linear
    in mu_W between the nodes mu_nodes (uniform, rising to 1; K is even in the angle from
    straight up, so smooth in mu) and 0 below them; phi_nodes on [0, pi] (midpoint rule: the
    circle is symmetric about the vertical plane of the direction)."""
    n_alpha, n_psi = psi.shape
    a = np.zeros((n_alpha, n_psi - 1))
    b = np.zeros((n_alpha, n_psi - 1))
    first = mu_nodes[0]
    per_step = 1.0 / (mu_nodes[1] - mu_nodes[0])
    last = mu_nodes.shape[0] - 1
    n_phi = phi_nodes.shape[0]
    cos_phi = np.cos(phi_nodes)
    for i in range(n_alpha):
        ca, sa = math.cos(alphas[i]), math.sin(alphas[i])
        for k in range(n_psi - 1):
            mid = 0.5 * (psi[i, k] + psi[i, k + 1])
            cp, sp = ca * math.cos(mid), sa * math.sin(mid)
            sum_k = 0.0
            sum_kb = 0.0
            for m in range(n_phi):
                mu = cp + sp * cos_phi[m]
                x = (mu - first) * per_step
                if x < 0.0:
                    continue
                node = min(int(x), last - 1)
                f = x - node
                value = (1.0 - f) * density[node] + f * density[node + 1]
                sum_k += value
                sum_kb += value * (mu - mu_bar)
            a[i, k] = sum_k / n_phi
            b[i, k] = sum_kb / n_phi
    return a, b
