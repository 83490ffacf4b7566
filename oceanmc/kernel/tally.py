"""Plane-crossing tallies: a photon of weight w crossing a level with direction cosine mu adds w
to Ed or Eu, w/|mu| to Eod or Eou and to the radiance of its quad (normalised by the quad's solid
angle and the photon count later, in results.py). Grazing crossings use the surface-flux rule:
1/|mu| is replaced by 2/mu_cut when |mu| < mu_cut, which is exact when the radiance is constant
over |mu| < mu_cut and keeps the variance finite (MCNP manual, F2 surface flux tally).

Levels: the in-water tally depths first, then sc.air_level (0+, all light) and sc.air_level + 1
(0+, water-leaving light only). Arrays are indexed, never sliced, in the loop: a view costs a
reference-count update."""
import math

from numba import njit

from .models import FEATURE_RADIANCE, FLUX_ED, FLUX_EOD, FLUX_EOU, FLUX_EU


@njit(error_model="numpy", cache=True)
def theta_band(uz, mu_edges):
    """Index i with mu_edges[i] >= uz > mu_edges[i + 1] (mu_edges falls from 1 to -1)."""
    lo = 0
    hi = mu_edges.shape[0] - 1
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if uz <= mu_edges[mid]:
            lo = mid
        else:
            hi = mid
    return lo


@njit(error_model="numpy", cache=True, inline="always")
def theta_band_fast(sc, uz):
    """theta_band by table: sc.theta_lookup[k] is the band of the top of the k-th of M equal
    cells of uz in [-1, 1]; lower values in the same cell can only be in that band or a later
    one, so a short walk down the edges finishes the job exactly."""
    m = sc.theta_lookup.shape[0]
    k = min(m - 1, int((uz + 1.0) * (0.5 * m)))
    band = sc.theta_lookup[k]
    last = sc.theta_mu_edges.shape[0] - 2
    while band < last and uz <= sc.theta_mu_edges[band + 1]:
        band += 1
    return band


@njit(error_model="numpy", cache=True)
def phi_band(ux, uy, n_phi):
    """Band index with band 0 centred on phi = 0 (the sun's travel azimuth)."""
    phi = math.atan2(uy, ux)
    k = int(math.floor(phi * n_phi / (2.0 * math.pi) + 0.5))
    return k % n_phi


@njit(error_model="numpy", cache=True, inline="always")
def phi_band_fast(sc, ux, uy):
    """phi_band without atan2: a polynomial guess of the azimuth (error < 0.0038 rad; Rajan et
    al. 2006, IEEE Signal Process. Mag. 23(3)). The bands are equal, so a guess farther than
    0.0063 rad (0.001 n bands) from an edge is the band; near an edge, exact tests against the
    edge directions (sign of the 2-D cross product) move it to the right band."""
    n = sc.n_phi
    if n <= 2:
        return phi_band(ux, uy, n)
    ax = abs(ux)
    ay = abs(uy)
    if ax >= ay:
        r = ay / ax if ax > 0.0 else 0.0
        angle = r * (0.25 * math.pi + 0.273 * (1.0 - r))
    else:
        r = ax / ay
        angle = 0.5 * math.pi - r * (0.25 * math.pi + 0.273 * (1.0 - r))
    if ux < 0.0:
        angle = math.pi - angle
    if uy < 0.0:
        angle = -angle
    x = angle * n / (2.0 * math.pi) + 0.5
    k = int(math.floor(x))
    frac = x - k
    k = k + n if k < 0 else (k - n if k >= n else k)
    if 0.001 * n < frac < 1.0 - 0.001 * n:
        return k
    # band k lies between edge k (inclusive) and edge k + 1 (exclusive), counterclockwise
    while sc.phi_edge_cos[k] * uy - sc.phi_edge_sin[k] * ux < 0.0:
        k = k - 1 if k > 0 else n - 1
    while True:
        up = k + 1 if k + 1 < n else 0
        if sc.phi_edge_cos[up] * uy - sc.phi_edge_sin[up] * ux < 0.0:
            return k
        k = up


@njit(error_model="numpy", cache=True)
def inverse_mu(uz, mu_cut, beam):
    """1/|mu|, or 2/mu_cut below the cut for diffuse light. A collimated beam (the unscattered
    sun) always gets the exact 1/|mu|: every packet of it has the same mu, so there is no
    variance to tame, and the rule's assumption (radiance constant near the horizon) fails."""
    amu = abs(uz)
    return 1.0 / amu if (amu >= mu_cut or beam) else 2.0 / mu_cut


@njit(error_model="numpy", cache=True, inline="always")
def score_levels(sc, features, flux, radiance, level, second, w, ux, uy, uz, beam):
    """A crossing of tally level `level` (an in-water depth, or the air levels after them), and
    of level `second` too when second >= 0 (the same crossing counted twice: the bands are found
    once); beam: the packet is still part of the collimated solar beam."""
    w_over_mu = w * inverse_mu(uz, sc.mu_cut, beam)
    col_e = FLUX_ED if uz > 0.0 else FLUX_EU
    col_eo = FLUX_EOD if uz > 0.0 else FLUX_EOU
    flux[level, col_e] += w
    flux[level, col_eo] += w_over_mu
    if second >= 0:
        flux[second, col_e] += w
        flux[second, col_eo] += w_over_mu
    if features & FEATURE_RADIANCE:
        band = theta_band_fast(sc, uz)
        col = 0 if sc.theta_is_cap[band] else phi_band_fast(sc, ux, uy)
        radiance[level, band, col] += w_over_mu
        if second >= 0:
            radiance[second, band, col] += w_over_mu


@njit(error_model="numpy", cache=True, inline="always")
def score(sc, features, flux, radiance, level, w, ux, uy, uz, beam):
    score_levels(sc, features, flux, radiance, level, -1, w, ux, uy, uz, beam)


@njit(error_model="numpy", cache=True, inline="always")
def score_air_up(sc, features, flux, radiance, w, ux, uy, uz, water_leaving, beam):
    """Light travelling up at 0+: all of it at sc.air_level, and what came out of the water also
    at the water-leaving level after it."""
    score_levels(sc, features, flux, radiance, sc.air_level,
                 sc.air_level + 1 if water_leaving else -1, w, ux, uy, uz, beam)
