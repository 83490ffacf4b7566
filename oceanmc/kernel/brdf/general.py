"""The general BRDF sampler: the textbook recipe (rho_dh as the weight, a CDF for the reflected
azimuth, then a conditional CDF for the polar angle given the azimuth) with the integrals
tabulated once per scene (brdf_tables.py) instead of once per ray, and made exact by weighting.

Tables, at offset o = params[BRDF_SAMPLER_AT] of the bottom parameter array:
  [n_ti, n_pi, n_t, n_p, 0, 0, 0, 0, s_edges (n_t + 1), then one block per incident node]
Incident nodes: theta_i = a pi/2 / (n_ti - 1), a = 0 .. n_ti - 1, times (anisotropic BRDFs only)
phi_i = b 2 pi / n_pi. Outgoing cells: n_t polar bands of equal width in theta_o (s_edges are
cos^2 of their edges) times n_p bands of equal width in dphi = phi_o - phi_i over [0, 2 pi).
Each node's block holds, for its tabulated density P_cell (the integral of f cos over the cell
over rho_dh, mixed with 1% of the cosine-weighted density so that no cell where f > 0 has zero
probability):
  col_cdf (n_p)       the CDF of the reflected azimuth band (the BRDF integrated over theta_o)
  cond_cdf (n_p, n_t) the CDF of the polar band given the azimuth band
  dens (n_p, n_t)     2 P_cell / (delta s delta dphi): within a cell the sampler draws s = cos^2
                      and dphi uniformly, so its density per steradian is dens * cos(theta_o)
                      (proportional to the cosine, like f cos for a smooth f).

An incident direction between nodes uses node a or a + 1 with the linear-interpolation weights
(and likewise in phi_i), chosen with u1, which is then rescaled and reused. The density actually
sampled is therefore the interpolation-weighted mixture of the nodes' densities, which density()
evaluates exactly, and the caller's weight f cos / pdf = f / density() is exact for any table:
the tabulation only decides how constant the weights are (for a Lambertian BRDF they are exactly
rho), never their expectation, which is rho_dh(wi) (brdf_tables.py documents the accuracy)."""
import math

from ..compile import kernel
from ..models import BRDF_SAMPLER_AT
from ..search import interval

HEADER = 8
TWO_PI = 2.0 * math.pi


@kernel
def layout(params):
    o = int(params[BRDF_SAMPLER_AT])
    n_ti = int(params[o])
    n_pi = int(params[o + 1])
    n_t = int(params[o + 2])
    n_p = int(params[o + 3])
    s_at = o + HEADER
    blocks = s_at + n_t + 1
    block = n_p + 2 * n_p * n_t
    return n_ti, n_pi, n_t, n_p, s_at, blocks, block


@kernel
def incident_nodes(n_ti, n_pi, wix, wiy, wiz):
    """(a, t, b, tb, phi_i): nodes a, a + 1 in theta_i with weights 1 - t, t; nodes b, b + 1
    (mod n_pi) in phi_i with weights 1 - tb, tb; the azimuth of wi."""
    theta_i = math.acos(min(1.0, max(0.0, wiz)))
    x = theta_i * (n_ti - 1) / (0.5 * math.pi)
    a = min(int(x), n_ti - 2)
    t = min(1.0, max(0.0, x - a))
    phi_i = math.atan2(wiy, wix)
    b = 0
    tb = 0.0
    if n_pi > 1:
        y = (phi_i - TWO_PI * math.floor(phi_i / TWO_PI)) * n_pi / TWO_PI
        b = min(int(y), n_pi - 1)
        tb = min(1.0, max(0.0, y - b))
    return a, t, b, tb, phi_i


@kernel
def node_density(params, blocks, block, n_t, n_p, node, c, r):
    return params[blocks + node * block + n_p + n_p * n_t + c * n_t + r]


@kernel
def density(params, wix, wiy, wiz, wox, woy, woz):
    """pdf(wo) / cos(theta_o) of the sampler for incidence wi (1/sr)."""
    n_ti, n_pi, n_t, n_p, s_at, blocks, block = layout(params)
    a, t, b, tb, phi_i = incident_nodes(n_ti, n_pi, wix, wiy, wiz)
    theta_o = math.acos(min(1.0, max(0.0, woz)))
    r = min(int(theta_o * n_t / (0.5 * math.pi)), n_t - 1)
    dphi = math.atan2(woy, wox) - phi_i
    dphi = dphi - TWO_PI * math.floor(dphi / TWO_PI)
    c = min(int(dphi * n_p / TWO_PI), n_p - 1)
    total = 0.0
    for da in range(2):
        wa = t if da == 1 else 1.0 - t
        if wa == 0.0:
            continue
        for db in range(2):
            wb = tb if db == 1 else 1.0 - tb
            if wb == 0.0:
                continue
            node = (a + da) * n_pi + (b + db) % n_pi
            total += wa * wb * node_density(params, blocks, block, n_t, n_p, node, c, r)
    return total


@kernel
def pdf(params, wix, wiy, wiz, wox, woy, woz):
    if woz <= 0.0:
        return 0.0
    return density(params, wix, wiy, wiz, wox, woy, woz) * woz


@kernel
def rescale(u, lo, hi):
    """Where u lies in [lo, hi), as a fraction in [0, 1)."""
    width = hi - lo
    if width <= 0.0:
        return 0.5
    return min(max((u - lo) / width, 0.0), 1.0 - 1e-16)


@kernel
def sample(params, wix, wiy, wiz, u1, u2):
    """(wox, woy, woz, pdf / cos(theta_o)) for incidence wi."""
    n_ti, n_pi, n_t, n_p, s_at, blocks, block = layout(params)
    a, t, b, tb, phi_i = incident_nodes(n_ti, n_pi, wix, wiy, wiz)
    if u1 < 1.0 - t:
        u1 = rescale(u1, 0.0, 1.0 - t)
    else:
        u1 = rescale(u1, 1.0 - t, 1.0)
        a += 1
    if n_pi > 1:
        if u1 < 1.0 - tb:
            u1 = rescale(u1, 0.0, 1.0 - tb)
        else:
            u1 = rescale(u1, 1.0 - tb, 1.0)
            b = (b + 1) % n_pi
    base = blocks + (a * n_pi + b) * block
    # the azimuth band c, then the polar band r: the k with cdf[k - 1] <= u < cdf[k], cdf[-1] = 0
    # (the CDF's last entry, 1, is not read)
    c = interval(params, base, -1, n_p - 1, u1) + 1
    u1 = rescale(u1, params[base + c - 1] if c > 0 else 0.0, params[base + c])
    row = base + n_p + c * n_t
    r = interval(params, row, -1, n_t - 1, u2) + 1
    u2 = rescale(u2, params[row + r - 1] if r > 0 else 0.0, params[row + r])
    s = params[s_at + r] + u2 * (params[s_at + r + 1] - params[s_at + r])
    mu = math.sqrt(min(1.0, max(0.0, s)))
    sin_o = math.sqrt(max(0.0, 1.0 - s))
    phi_o = phi_i + (c + u1) * TWO_PI / n_p
    wox = sin_o * math.cos(phi_o)
    woy = sin_o * math.sin(phi_o)
    return wox, woy, mu, density(params, wix, wiy, wiz, wox, woy, mu)
