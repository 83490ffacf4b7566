"""Tables for the local estimate of the nadir-viewing polar-cap radiance (Lu, Lw_nadir, Rrs).

The cap average of the radiance a collision sends up to a level is
    (1/dOmega) integral over the cap of w p(u . W) g(mu_W) dW,   g(mu) = exp(-dtau/mu) / mu,
where u is the packet's direction and W runs over the cap (half-angle beta about straight up).
A local estimate in the exact nadir direction alone has infinite variance with forward-peaked
phase functions (for Petzold 4 pi integral of p^2 dOmega = 4e6); the cap integral of p is bounded
by 1/dOmega. g varies by less than (dtau + 1)(1 - cos beta) over the cap, so it is expanded to
first order about the cap's mean cosine mu_bar:
    integral p g dW = M0 g(mu_bar) + M1 g'(mu_bar) + O(g'' (1 - cos beta)^2),
    M0(alpha) = integral_cap p dW,   M1(alpha) = integral_cap p (mu_W - mu_bar) dW,
which depend only on the angle alpha between u and the cap axis. The neglected term is below
(dtau^2/8)(1 - cos beta)^2 = 2e-6 dtau^2 relative for the 5 deg cap, and its weight exp(-dtau)
keeps it below 1e-5 overall. M0 and M1 are integrals over the scattering angle psi of
q(psi) = 2 pi p sin(psi) times the share of the circle of radius psi about u that lies in the
cap, which spherical trigonometry gives in closed form (cos mu_W = cos alpha cos psi +
sin alpha sin psi cos phi; inside when cos phi >= X).

For 0+ the air cap (half-angle beta) is the water cap of half-angle asin(sin beta / n); the
air-side average brings the Fresnel transmittance t and the solid-angle factor mu_w / mu_a
(L_air = t L_water / n^2 and n^2 mu_w dOmega_w = mu_a dOmega_a), so g there is
exp(-tau/mu) h(mu) with h = t(mu) / mu_a(mu).

Through the wind-roughened sea the air cap receives light from every in-water direction W with
the weight K(mu_W) of kernel/rough_cap.py (a smooth lobe a few degrees wide about straight up):
the 0+ average is integral of w p(u . W) K(mu_W) g(mu_W) dW with g = exp(-tau/mu)/mu, expanded
as above about K's mean cosine mu_bar, with M0 = integral p K dW and M1 = integral p K (mu_W -
mu_bar) dW (RoughCap). The neglected term, (g''/2) integral p K (mu_W -
mu_bar)^2, is below 1e-4 tau^2 exp(-tau) relative to the first for K lobes within 15 deg of
straight up (wind speeds to 20 m/s).
"""
from __future__ import annotations

import functools
import hashlib
import math
from dataclasses import dataclass, field

import numpy as np

from ..kernel import rough_cap

# alpha grid: fine where the cap and the forward peak overlap, coarser beyond
ALPHA_FINE_SPAN_CAPS = 4.0
ALPHA_FINE_NODES = 801
ALPHA_COARSE_NODES = 1800
PSI_NODES = 300


def alpha_grid(beta: float) -> tuple[float, float, float, int]:
    """(fine end, fine step, coarse step, fine node count) of the two uniform pieces."""
    fine_end = min(math.pi / 2, ALPHA_FINE_SPAN_CAPS * beta)
    fine_step = fine_end / (ALPHA_FINE_NODES - 1)
    coarse_step = (math.pi - fine_end) / (ALPHA_COARSE_NODES - 1)
    return fine_end, fine_step, coarse_step, ALPHA_FINE_NODES


def alpha_nodes(beta: float) -> np.ndarray:
    fine_end, _, _, _ = alpha_grid(beta)
    return np.concatenate([np.linspace(0.0, fine_end, ALPHA_FINE_NODES),
                           np.linspace(fine_end, math.pi, ALPHA_COARSE_NODES)[1:]])


def cumulative(density, breaks: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(psi, integral of q from 0 to psi, integral of q cos(psi)) on a fine grid that holds the
    density's own break points, so a tabulated q (linear between them) is integrated exactly and
    a forward spike in its first interval keeps its mass."""
    psi = np.unique(np.concatenate([breaks[(breaks >= 0.0) & (breaks <= math.pi)],
                                    np.linspace(0.0, math.pi, 4001),
                                    np.geomspace(1e-9, math.pi, 4001)]))
    q = density(psi)
    step = np.diff(psi)
    mass = 0.5 * (q[1:] + q[:-1]) * step
    qc = q * np.cos(psi)
    mass_cos = 0.5 * (qc[1:] + qc[:-1]) * step
    return (psi, np.concatenate([[0.0], np.cumsum(mass)]),
            np.concatenate([[0.0], np.cumsum(mass_cos)]))


# A phase function's cap moments are linear in its cumulative integrals (linear interpolation
# is linear in the tabulated values), so on one angle grid they are sparse matrices times the
# integrals. Built for a grid once OPERATOR_AFTER phase functions on it have asked (0.8 s, the
# time of 40 direct evaluations; then 24x faster each): a 180-layer chlorophyll profile has
# 433 distinct Fournier-Forand components on one grid (its packing: 17 s cold before, 4 s after).
# The matrices sum the same terms in another order: M0 and M1 agree with the direct sums to
# 5e-15 of the largest M0 (tests/test_cap_tables.py).
OPERATOR_AFTER = 16


def interpolation_operator(points: np.ndarray, weights: np.ndarray, grid: np.ndarray):
    """The sparse matrix S (rows of points x grid nodes) with (S @ f)[a] = sum over j of
    weights[a, j] * np.interp(points[a, j], grid, f), for points within the grid."""
    from scipy.sparse import csr_matrix  # here: only scenes with many phase functions need it
    below = np.clip(np.searchsorted(grid, points, side="right") - 1, 0, len(grid) - 2)
    frac = np.clip((points - grid[below]) / (grid[below + 1] - grid[below]), 0.0, 1.0)
    rows = np.broadcast_to(np.arange(points.shape[0])[:, None], points.shape).ravel()
    values = np.concatenate([(weights * (1.0 - frac)).ravel(), (weights * frac).ravel()])
    nodes = np.concatenate([below.ravel(), below.ravel() + 1])
    # repeated (row, node) pairs are summed
    return csr_matrix((values, (np.concatenate([rows, rows]), nodes)),
                      shape=(points.shape[0], len(grid)))


def interval_weights(w: np.ndarray) -> np.ndarray:
    """Per node j, the weight of F(psi_j) in sum_i (F(psi_i+1) - F(psi_i)) w_i (rows of w)."""
    edge = np.zeros((w.shape[0], 1))
    return np.hstack([edge, w]) - np.hstack([w, edge])


@dataclass(frozen=True)
class LinearInCdf:
    """A cap whose moments (M0, M1 at each alpha) are linear in a phase function's cumulative
    integrals (cumulative()): moments() evaluates them directly (direct()), or, for the
    OPERATOR_AFTER-th phase function on an angle grid and later ones, by that grid's sparse
    matrices (operator(), apply())."""
    _operators: dict = field(default_factory=dict, init=False, repr=False, compare=False)
    _asked: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def moments(self, table: tuple[np.ndarray, np.ndarray, np.ndarray]
                ) -> tuple[np.ndarray, np.ndarray]:
        key = hashlib.sha1(table[0].tobytes()).digest()
        if key not in self._operators:
            self._asked[key] = self._asked.get(key, 0) + 1
            if self._asked[key] < OPERATOR_AFTER:
                return self.direct(table)
            self._operators[key] = self.operator(table[0])
        return self.apply(self._operators[key], table)


@dataclass(frozen=True)
class CapGeometry(LinearInCdf):
    """What the moments need of a cap of half-angle beta (mean cosine mu_bar) at each alpha,
    whatever the phase function (cap_geometry)."""
    inside: np.ndarray      # the radius of the circles wholly inside the cap
    cos_alpha: np.ndarray
    psi: np.ndarray         # quadrature angles of the other circles (alpha x nodes)
    phi0: np.ndarray        # per interval: the half-angle of its circle's arc in the cap
    arc_mu: np.ndarray      # that arc's mean cosine to the axis times its share phi0 / pi
    mu_bar: float

    def direct(self, table):
        """Circles of radius psi <= beta - alpha lie wholly in the cap; for the others the
        probability between neighbouring quadrature angles (exact, from the cumulative
        integral) is weighted by the share of the circle in the cap at their midpoint."""
        psi_grid, cdf, cdf_cos = table
        m0 = np.interp(self.inside, psi_grid, cdf)
        m1 = self.cos_alpha * np.interp(self.inside, psi_grid, cdf_cos)
        mass = np.diff(np.interp(self.psi, psi_grid, cdf), axis=1)
        m0 = m0 + np.sum(mass * self.phi0 / math.pi, axis=1)
        m1 = m1 + np.sum(mass * self.arc_mu, axis=1)
        return m0, m1 - self.mu_bar * m0

    def operator(self, grid):
        whole = self.inside[:, None]
        return (interpolation_operator(whole, np.ones_like(whole), grid)
                + interpolation_operator(self.psi, interval_weights(self.phi0 / math.pi), grid),
                interpolation_operator(self.psi, interval_weights(self.arc_mu), grid),
                interpolation_operator(whole, self.cos_alpha[:, None], grid))

    def apply(self, operator, table):
        _, cdf, cdf_cos = table
        on_cdf, m1_on_cdf, m1_on_cdf_cos = operator
        m0 = on_cdf @ cdf
        return m0, m1_on_cdf @ cdf + m1_on_cdf_cos @ cdf_cos - self.mu_bar * m0


def cap_geometry(beta: float, mu_bar: float, alphas: np.ndarray) -> CapGeometry:
    """The CapGeometry of the cap of half-angle beta (mean cosine mu_bar) at the alpha grid
    alphas: the angles of the circles wholly inside it, the quadrature angles psi of the
    others, and per interval between them the share of its circle inside the cap (phi0 / pi)
    and that arc's mean cosine to the axis times the share. Built once for all the phase
    functions of a scene (the trigonometry costs ten times one table's interpolation), and its
    arrays kept for the process's next scenes (_cap_arrays); each call gives a CapGeometry of
    its own, whose count of phase functions (LinearInCdf: when the sparse matrices take over)
    starts at 0, so a scene's tables do not depend on the scenes packed before it."""
    return CapGeometry(**_cap_arrays(beta, _key(alphas)), mu_bar=mu_bar)


def _key(alphas: np.ndarray) -> bytes:
    """An alpha grid as the kept geometries' key (np.frombuffer gives it back)."""
    return np.ascontiguousarray(alphas, np.float64).tobytes()


def _read_only(fields: dict) -> dict:
    """The fields of a kept geometry, its arrays made read-only: later scenes share them."""
    for value in fields.values():
        if isinstance(value, np.ndarray):
            value.setflags(write=False)
    return fields


# the arrays of the last CAP_ARRAYS_KEPT caps (56 MB each on the default alpha grid; a scene
# uses two, the water cap and the flat air cap's water side): 0.4-0.5 s each to build, which
# every scene whose cap moments are not remembered (a phase function new to the process: a
# sweep over g or a particle backscattering ratio; Case-1 chlorophyll alone is not) paid twice
CAP_ARRAYS_KEPT = 4


@functools.lru_cache(maxsize=CAP_ARRAYS_KEPT)
def _cap_arrays(beta: float, alpha_bytes: bytes) -> dict[str, np.ndarray]:
    """cap_geometry's arrays (read-only: shared by the scenes), for alphas given as bytes."""
    alphas = np.frombuffer(alpha_bytes, dtype=np.float64)
    alpha = alphas[:, None]
    inside = np.clip(beta - alphas, 0.0, None)
    lo = np.abs(alphas - beta)[:, None]
    hi = np.minimum(math.pi, alphas + beta)[:, None]
    s = np.unique(np.concatenate([np.linspace(0.0, 1.0, PSI_NODES),
                                  np.geomspace(1e-7, 1.0, PSI_NODES),
                                  1.0 - np.geomspace(1e-7, 1.0, PSI_NODES)]))
    psi = lo + (hi - lo) * s[None, :]
    mid = 0.5 * (psi[:, 1:] + psi[:, :-1])
    with np.errstate(invalid="ignore", divide="ignore"):
        x = (math.cos(beta) - np.cos(alpha) * np.cos(mid)) / (np.sin(alpha) * np.sin(mid))
    phi0 = np.arccos(np.clip(np.nan_to_num(x, nan=1.0, posinf=1.0, neginf=-1.0), -1.0, 1.0))
    # mean of cos(angle to the axis) over the arc |phi| < phi0, times the arc's share
    arc_mu = (phi0 * np.cos(alpha) * np.cos(mid)
              + np.sin(alpha) * np.sin(mid) * np.sin(phi0)) / math.pi
    return _read_only({"inside": inside, "cos_alpha": np.cos(alphas), "psi": psi, "phi0": phi0,
                       "arc_mu": arc_mu})


def air_factor(mu_w: np.ndarray, n: float, transmittance) -> np.ndarray:
    """h(mu_w) = t(mu_w) / mu_a(mu_w) for the water-side directions of the air cap, with t the
    surface's transmittance from the water (a function of the in-water cosine)."""
    if n == 1.0:   # no refraction: mu_a = mu_w
        return np.array([transmittance(float(m)) for m in mu_w]) / mu_w
    sin_a = np.sqrt(np.clip(1.0 - mu_w ** 2, 0.0, 1.0)) * n
    mu_a = np.sqrt(np.clip(1.0 - sin_a ** 2, 0.0, 1.0))
    t = np.array([transmittance(float(m)) for m in mu_w])
    return t / mu_a


# K of the rough sea's air cap: found on a coarse grid of angles to ROUGH_SEARCH_DEG, then
# tabulated on ROUGH_MU_NODES nodes uniform in mu down to where it falls below ROUGH_FLOOR of
# its peak (and stays there), ROUGH_MARGIN_DEG beyond; quadrature over the air cap: Gauss-
# Legendre in 1 - cos (ROUGH_POLAR_NODES) and the midpoint rule in azimuth (ROUGH_AZIMUTHS)
ROUGH_SEARCH_DEG = 60.0
ROUGH_FLOOR = 1e-13
ROUGH_MARGIN_DEG = 1.0
ROUGH_MU_NODES = 801
ROUGH_POLAR_NODES = 16
ROUGH_AZIMUTHS = 64
# the circles of scattering angle psi that meet K's support: ROUGH_PSI_NODES uniform nodes,
# each circle averaged at ROUGH_RING_NODES azimuths (midpoint rule on [0, pi])
ROUGH_PSI_NODES = 401
ROUGH_RING_NODES = 48


@dataclass(frozen=True)
class RoughCap(LinearInCdf):
    """The rough sea's air cap, as the moments need it: K on mu_nodes (its mean cosine mu_bar
    and integral mass), and per alpha the psi intervals that meet its support with the circle
    averages A (of K) and B (of K (mu - mu_bar)) at their midpoints."""
    mu_nodes: np.ndarray
    density: np.ndarray
    mu_bar: float
    mass: float
    psi: np.ndarray
    a: np.ndarray
    b: np.ndarray

    def direct(self, table):
        """The probability of each psi interval (exact, from the cumulative integral of q)
        times the circle averages at its midpoint."""
        psi_grid, cdf, _ = table
        mass = np.diff(np.interp(self.psi, psi_grid, cdf), axis=1)
        return np.sum(mass * self.a, axis=1), np.sum(mass * self.b, axis=1)

    def operator(self, grid):
        return (interpolation_operator(self.psi, interval_weights(self.a), grid),
                interpolation_operator(self.psi, interval_weights(self.b), grid))

    def apply(self, operator, table):
        return operator[0] @ table[1], operator[1] @ table[1]


def rough_air_density(alpha: float, n: float, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """(mu_nodes, K): kernel/rough_cap.py's K for the air cap of half-angle beta through facets
    of Beckmann roughness alpha, on a uniform grid in mu over its support."""
    x, w = np.polynomial.legendre.leggauss(ROUGH_POLAR_NODES)
    polar, weights = 0.5 * (x + 1.0), 0.5 * w
    azimuths = (np.arange(ROUGH_AZIMUTHS) + 0.5) * (math.pi / ROUGH_AZIMUTHS)
    search = np.radians(np.linspace(0.0, ROUGH_SEARCH_DEG, 121))
    coarse = rough_cap.air_cap_density(alpha, n, beta, np.cos(search), polar, weights, azimuths)
    above = np.nonzero(coarse > ROUGH_FLOOR * coarse.max())[0]
    end = min(math.radians(ROUGH_SEARCH_DEG), search[above[-1]] + math.radians(ROUGH_MARGIN_DEG))
    mu = np.linspace(math.cos(end), 1.0, ROUGH_MU_NODES)
    return mu, rough_cap.air_cap_density(alpha, n, beta, mu, polar, weights, azimuths)


def rough_cap_geometry(alphas: np.ndarray, alpha: float, n: float, beta: float) -> RoughCap:
    """The RoughCap of the air cap of half-angle beta through facets of roughness alpha, at
    the alpha grid alphas (the angles between a packet's direction and straight up); its
    arrays kept for the process's next scenes as cap_geometry's are."""
    return RoughCap(**_rough_arrays(_key(alphas), alpha, n, beta))


# the arrays of the last ROUGH_ARRAYS_KEPT rough caps (25 MB each on the default alpha grid,
# 0.2 s to build)
ROUGH_ARRAYS_KEPT = 2


@functools.lru_cache(maxsize=ROUGH_ARRAYS_KEPT)
def _rough_arrays(alpha_bytes: bytes, alpha: float, n: float, beta: float) -> dict:
    """rough_cap_geometry's fields (the arrays read-only: shared by the scenes), for alphas
    given as bytes."""
    # (a writable copy: Numba compiles ring_averages anew for a read-only array's type)
    alphas = np.frombuffer(alpha_bytes, dtype=np.float64).copy()
    mu, density = rough_air_density(alpha, n, beta)
    # integrals over the upper sphere of K and K mu: K linear in mu, dOmega = 2 pi dmu
    mass = 2.0 * math.pi * np.trapezoid(density, mu)
    mu_bar = float(2.0 * math.pi * np.trapezoid(density * mu, mu) / mass)
    reach = math.acos(mu[0])
    lo = np.clip(alphas - reach, 0.0, None)
    hi = np.minimum(math.pi, alphas + reach)
    psi = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, ROUGH_PSI_NODES)[None, :]
    rings = (np.arange(ROUGH_RING_NODES) + 0.5) * (math.pi / ROUGH_RING_NODES)
    a, b = rough_cap.ring_averages(alphas, psi, mu, density, mu_bar, rings)
    return _read_only({"mu_nodes": mu, "density": density, "psi": psi, "a": a, "b": b,
                       "mu_bar": mu_bar, "mass": float(mass)})
