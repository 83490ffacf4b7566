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

from .models import FLUX_ED, FLUX_EOD, FLUX_EOU, FLUX_EU


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


@njit(error_model="numpy", cache=True)
def phi_band(ux, uy, n_phi):
    """Band index with band 0 centred on phi = 0 (the sun's travel azimuth)."""
    phi = math.atan2(uy, ux)
    k = int(math.floor(phi * n_phi / (2.0 * math.pi) + 0.5))
    return k % n_phi


@njit(error_model="numpy", cache=True)
def inverse_mu(uz, mu_cut, beam):
    """1/|mu|, or 2/mu_cut below the cut for diffuse light. A collimated beam (the unscattered
    sun) always gets the exact 1/|mu|: every packet of it has the same mu, so there is no
    variance to tame, and the rule's assumption (radiance constant near the horizon) fails."""
    amu = abs(uz)
    return 1.0 / amu if (amu >= mu_cut or beam) else 2.0 / mu_cut


@njit(error_model="numpy", cache=True, inline="always")
def score(sc, flux, radiance, level, w, ux, uy, uz, beam):
    """A crossing of tally level `level` (an in-water depth, or the air levels after them);
    beam: the packet is still part of the collimated solar beam."""
    w_over_mu = w * inverse_mu(uz, sc.mu_cut, beam)
    if uz > 0.0:
        flux[level, FLUX_ED] += w
        flux[level, FLUX_EOD] += w_over_mu
    else:
        flux[level, FLUX_EU] += w
        flux[level, FLUX_EOU] += w_over_mu
    if sc.tally_radiance:
        band = theta_band(uz, sc.theta_mu_edges)
        col = 0 if sc.theta_is_cap[band] else phi_band(ux, uy, sc.n_phi)
        radiance[level, band, col] += w_over_mu


@njit(error_model="numpy", cache=True, inline="always")
def score_air_up(sc, flux, radiance, w, ux, uy, uz, water_leaving, beam):
    """Light travelling up at 0+: all of it at sc.air_level, and what came out of the water also
    at the water-leaving level after it."""
    score(sc, flux, radiance, sc.air_level, w, ux, uy, uz, beam)
    if water_leaving:
        score(sc, flux, radiance, sc.air_level + 1, w, ux, uy, uz, beam)
