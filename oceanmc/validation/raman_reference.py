"""An independent reference for water Raman scattering (numpy and scipy only; nothing from oceanmc).

Written to check the main kernel's inelastic transport against code that shares none of its
logic. Two calculations of the same scene, plus the Raman ingredients they share:

- single_scattering(): deterministic quadrature of the once-Raman-scattered light (b_el = 0);
- second_order_bound(): an analytic upper bound on the twice-Raman light it leaves out;
- reference_walk(): a slow, plain analog Monte Carlo that changes each photon's wavelength
  explicitly and follows every Raman and elastic order.

Physics (DESIGN.md section 7.4; ../shared/data/raman_coxmunk_notes.md section 2):

- Raman scattering coefficient at the excitation wavelength l' (nm), energy units (the HydroLight
  default; Marshall & Smith 1990; Bartlett et al. 1998, Appl. Opt. 37, 3324 give 2.7e-4 and 5.3
  in photon units):  b_R(l') = b488 (488 / l')**exponent  [1/m], b488 = 2.6e-4, exponent = 5.5.
  It is the loss rate of the beam at l' (the same fraction for energy and for photons).
- Wavenumber redistribution: Walrafen's four Gaussians in the wavenumber shift dk (1/cm)
  (Walrafen 1967, J. Chem. Phys. 47, 114; Mobley 1994, Light and Water, Table 5.3):
  weights 0.41/0.39/0.10/0.10, centres 3250/3425/3530/3625, FWHM 210/175/140/140; g(dk) is
  normalised to 1 over dk. Emission l from excitation l': 1e7/l = 1e7/l' - dk, so per nm of
  emission f(l' -> l) = (1e7 / l**2) g(1e7/l' - 1e7/l)  [1/nm].
- Raman conserves photons: the energy emitted at l is the energy removed at l' times l'/l.
- Phase function about the incident direction (Mobley 1994, section 5.13):
  p(psi) = 3 / (4 pi (3 + beta)) (1 + beta cos^2 psi)  [1/sr], beta = 0.55 (0.067 (1 + 0.55 cos^2)).

Scene: one homogeneous plane-parallel layer 0 <= z <= d (z positive downward), absorption a(l)
and elastic scattering b_el(l) (isotropic) as vectorised callables of wavelength in nm, plus
Raman; c(l) = a(l) + b_el(l) + b_R(l). The sun's collimated beam enters at z = 0 going straight
down with downward plane irradiance E0(l') (W m^-2 nm^-1, default 1). There is no interface:
nothing is reflected at z = 0, and nothing comes back from below z = d (a black bottom).
Outputs are RAMAN light only (at least one Raman event), in W m^-2 nm^-1 at the emission
wavelengths: Eu_top (upward plane irradiance leaving z = 0), Ed_bottom (downward plane
irradiance at z = d) and Eou_top (upward scalar irradiance at z = 0, the integral of radiance
over the upward hemisphere).
"""
from __future__ import annotations

import math

import numpy as np
from scipy import integrate

# --- Raman ingredients ---------------------------------------------------------------------------

# Walrafen (1967) via Mobley (1994) Table 5.3: weight, centre (1/cm), FWHM (1/cm)
WALRAFEN_WEIGHTS = np.array([0.41, 0.39, 0.10, 0.10])
WALRAFEN_CENTRES = np.array([3250.0, 3425.0, 3530.0, 3625.0])
WALRAFEN_FWHM = np.array([210.0, 175.0, 140.0, 140.0])
WALRAFEN_SIGMA = WALRAFEN_FWHM / (2.0 * math.sqrt(2.0 * math.log(2.0)))

# The shift range over which g is not negligible: 2700 is 6.2 sigma below the widest line's
# centre, 4200 is 9.7 sigma above the highest; the mass outside is below 1e-9.
DK_MIN, DK_MAX = 2700.0, 4200.0

B488 = 2.6e-4
EXPONENT = 5.5
BETA = 0.55

H_PLANCK = 6.62607015e-34   # J s
C_LIGHT = 299792458.0       # m/s


def raman_b(wavelength_nm, b488: float = B488, exponent: float = EXPONENT):
    """b_R(l') = b488 (488 / l')**exponent [1/m], the Raman loss rate at excitation l' (nm)."""
    return b488 * (488.0 / np.asarray(wavelength_nm, dtype=np.float64)) ** exponent


def walrafen_g(dk):
    """Walrafen's wavenumber-shift density g(dk) [cm], normalised to 1 over dk (1/cm).

    Each line is a Gaussian of the given FWHM; written as A_j N(dk; centre_j, sigma_j) with the
    weights summing to 1 (equal to the notes' form with its normalising constant)."""
    dk = np.asarray(dk, dtype=np.float64)[..., None]
    x = (dk - WALRAFEN_CENTRES) / WALRAFEN_SIGMA
    dens = WALRAFEN_WEIGHTS * np.exp(-0.5 * x * x) / (WALRAFEN_SIGMA * math.sqrt(2.0 * math.pi))
    return dens.sum(axis=-1) / WALRAFEN_WEIGHTS.sum()


def raman_redistribution(excitation_nm, emission_nm):
    """f(l' -> l) = (1e7 / l**2) g(1e7/l' - 1e7/l)  [per nm of emission wavelength]."""
    lp = np.asarray(excitation_nm, dtype=np.float64)
    lam = np.asarray(emission_nm, dtype=np.float64)
    return 1e7 / lam ** 2 * walrafen_g(1e7 / lp - 1e7 / lam)


def raman_emission_photons(l_prime, step_nm: float = 0.01):
    """Integral over the emission wavelength l of f(l' -> l) dl: the fraction of the photons
    removed at l' that reappear at some l. It must be 1 (Raman conserves photons); computed by
    Simpson's rule on a uniform l grid covering shifts 2000..5000 1/cm (over 14 sigma beyond the
    lines), so it checks the Jacobian 1e7/l**2 and the normalisation of g independently."""
    out = []
    for lp in np.atleast_1d(np.asarray(l_prime, dtype=np.float64)):
        k = 1e7 / lp
        lo, hi = 1e7 / (k - 2000.0), 1e7 / (k - 5000.0)
        n = int(math.ceil((hi - lo) / step_nm)) | 1          # odd number of points for Simpson
        lam = np.linspace(lo, hi, max(n, 3))
        out.append(integrate.simpson(raman_redistribution(lp, lam), x=lam))
    out = np.array(out)
    return out if np.ndim(l_prime) else float(out[0])


def raman_phase(cos_psi, beta: float = BETA):
    """p(psi) = 3 / (4 pi (3 + beta)) (1 + beta cos^2 psi) [1/sr]; integrates to 1 over 4 pi."""
    c = np.asarray(cos_psi, dtype=np.float64)
    return 3.0 / (4.0 * math.pi * (3.0 + beta)) * (1.0 + beta * c * c)


def sample_raman_cos(u, beta: float = BETA):
    """cos psi distributed as (1 + beta x^2) on [-1, 1], by inverting the CDF exactly.

    F(x) = (x + 1 + beta (x^3 + 1)/3) / (2 + 2 beta/3) = u is, times 3/beta, the monotone cubic
    x^3 + p x + q = 0 with p = 3/beta, q = p (1 + beta/3 - u (2 + 2 beta/3)); Cardano's formula
    gives its one real root (one since p > 0), and a Newton step polishes it."""
    u = np.asarray(u, dtype=np.float64)
    if beta == 0.0:
        return 2.0 * u - 1.0
    p = 3.0 / beta
    # beta x^3/3 + x + (1 + beta/3) - u (2 + 2 beta/3) = 0, divided by beta/3:
    q = p * ((1.0 + beta / 3.0) - u * (2.0 + 2.0 * beta / 3.0))
    disc = np.sqrt(0.25 * q * q + p ** 3 / 27.0)
    x = np.cbrt(-0.5 * q + disc) + np.cbrt(-0.5 * q - disc)
    # one Newton step removes the cancellation error of Cardano's formula
    x = x - (x ** 3 + p * x + q) / (3.0 * x * x + p)
    return np.clip(x, -1.0, 1.0)


def _callable(fn, default: float):
    if fn is None:
        return lambda lam: np.full(np.shape(lam), default, dtype=np.float64)
    return lambda lam: np.broadcast_to(np.asarray(fn(lam), dtype=np.float64), np.shape(lam))


def _source_and_attenuation(absorption, irradiance, b488: float, exponent: float):
    """E0(l') and c(l) = a(l) + b_R(l) of the analytic calculations (no elastic scattering)."""
    a_fn = _callable(absorption, 0.0)

    def c_fn(x):
        return a_fn(x) + raman_b(x, b488, exponent)

    return _callable(irradiance, 1.0), c_fn


# --- analytic single scattering ------------------------------------------------------------------


def _h(x):
    """(1 - exp(-x)) / x for x >= 0, with its limit 1 at x = 0."""
    x = np.asarray(x, dtype=np.float64)
    small = x < 1e-8
    return np.where(small, 1.0 - 0.5 * x, -np.expm1(-x) / np.where(small, 1.0, x))


def _k(s1, s2):
    """integral_0^1 exp(-s1 t - s2 (1 - t)) dt = (exp(-s2) - exp(-s1)) / (s1 - s2), stably."""
    return np.exp(-np.minimum(s1, s2)) * _h(np.abs(s1 - s2))


def _mu_quadrature(nodes: int, mu_cut: float = 0.0):
    """Composite Gauss-Legendre nodes and weights on mu in [0, 1]. Panels crowd toward mu = 0,
    where exp(-c d / mu) switches on and the scalar irradiance's 1/mu weighting acts; mu_cut (the
    grazing rule's discontinuity) is made a panel edge."""
    edges = [0.0, 0.005, 0.02, 0.06, 0.15, 0.35, 0.65, 1.0]
    if 0.0 < mu_cut < 1.0:
        edges = sorted(set(edges) | {mu_cut})
    edges = np.array(edges)
    x, w = np.polynomial.legendre.leggauss(nodes)
    mus, wts = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        mus.append(0.5 * (b - a) * x + 0.5 * (b + a))
        wts.append(0.5 * (b - a) * w)
    return np.concatenate(mus), np.concatenate(wts)


def _inverse_mu(mu, mu_cut: float):
    """Scalar-irradiance score per unit crossing weight: 1/|mu|, or 2/mu_cut below mu_cut (the
    surface-flux grazing rule, exact for radiance constant below mu_cut, finite variance)."""
    amu = np.abs(mu)
    if mu_cut <= 0.0:
        return 1.0 / amu
    return np.where(amu >= mu_cut, 1.0 / np.maximum(amu, mu_cut), 2.0 / mu_cut)


def single_scattering(wavelengths_nm, depth_m, absorption, *, b488: float = B488,
                      exponent: float = EXPONENT, beta: float = BETA, irradiance=None,
                      mu_cut: float = 0.0, step_nm: float = 0.05, mu_nodes: int = 24):
    """Once-Raman-scattered irradiances of the scene above, with no elastic scattering (b_el = 0).

    The beam E0(l') exp(-c(l') z) is Raman-scattered at depth z; the volume source at emission l
    per unit solid angle is S(z, psi) = p(psi) integral dl' E0(l') exp(-c(l') z) b_R(l')
    f(l' -> l) (l'/l); each emitted ray is attenuated by exp(-c(l) path) to the top (upward,
    cos psi = -mu) or the bottom (downward, cos psi = mu), with c = a + b_R. With mu = |cos|:

        Eu_top    = 2 pi int_0^1 dmu        int_0^d S exp(-c z / mu) dz
        Eou_top   = 2 pi int_0^1 dmu / mu   int_0^d S exp(-c z / mu) dz
        Ed_bottom = 2 pi int_0^1 dmu        int_0^d S exp(-c (d - z) / mu) dz

    The z integrals are done in closed form; mu by composite Gauss-Legendre (7 panels of
    mu_nodes); l' by Simpson's rule with a step <= step_nm nm over the shifts DK_MIN..DK_MAX
    (l' from 1e7/(1e7/l + 4200) to 1e7/(1e7/l + 2700); the Walrafen lines are ~5 nm wide).
    With mu_cut > 0, Eou_top is instead the expectation of the grazing-rule estimator (1/mu
    replaced by 2/mu_cut below mu_cut), to compare with reference_walk(..., mu_cut=mu_cut).

    Accuracy: this is EXACTLY the light that has been Raman-scattered once and not otherwise
    scattered (a second Raman event removes light from it, which exp(-c(l) path) accounts for),
    up to quadrature error (~1e-8 relative). As an estimate of ALL Raman light it neglects the
    second and higher Raman orders, an absolute error O((b_R d)^2 E0) (relative O(b_R d) times a
    log factor from grazing paths; second_order_bound() bounds it): in a 2 m layer with
    a ~ 0.02 1/m the higher orders are 14-39% of this at b488 = 2.6e-2 over 450-600 nm, and
    at most 0.5% (by the bound) at the default 2.6e-4. This is why reference_walk() also
    returns its once-Raman part. Returns dict(Eu_top, Ed_bottom, Eou_top) of arrays over
    wavelengths_nm [W m^-2 nm^-1].
    """
    lam = np.atleast_1d(np.asarray(wavelengths_nm, dtype=np.float64))
    d = float(depth_m)
    e0_fn, c_fn = _source_and_attenuation(absorption, irradiance, b488, exponent)

    mu, wmu = _mu_quadrature(mu_nodes, mu_cut)
    pw = 2.0 * math.pi * wmu * raman_phase(mu, beta)        # 2 pi p(mu) dmu (p is even in cos)
    qmu = _inverse_mu(mu, mu_cut)
    out = {k: np.zeros(lam.size) for k in ("Eu_top", "Ed_bottom", "Eou_top")}
    for i, l in enumerate(lam):
        lo, hi = 1e7 / (1e7 / l + DK_MAX), 1e7 / (1e7 / l + DK_MIN)
        n = int(math.ceil((hi - lo) / step_nm)) + 1
        lp = np.linspace(lo, hi, n + (n % 2 == 0))            # odd count for Simpson
        # source per metre of depth at z = 0, per nm of l' and per nm of l (energy at l)
        src = e0_fn(lp) * raman_b(lp, b488, exponent) * raman_redistribution(lp, l) * (lp / l)
        s1 = (c_fn(lp) * d)[:, None]                          # optical depth of the beam to d
        s2 = (float(c_fn(np.array([l]))[0]) * d / mu)[None, :]  # slant optical depth at l
        top = d * _h(s1 + s2)                                 # int_0^d exp(-c'z - c z/mu) dz
        bottom = d * _k(s1, s2)                               # int_0^d exp(-c'z - c(d-z)/mu) dz
        out["Eu_top"][i] = integrate.simpson(src * (top @ pw), x=lp)
        out["Eou_top"][i] = integrate.simpson(src * ((top * qmu) @ pw), x=lp)
        out["Ed_bottom"][i] = integrate.simpson(src * (bottom @ pw), x=lp)
    return out


def second_order_bound(wavelengths_nm, depth_m, absorption, *, b488: float = B488,
                       exponent: float = EXPONENT, beta: float = BETA, irradiance=None,
                       step_nm: float = 0.1, grid_nm: float = 0.25, mu_nodes: int = 12):
    """Upper bound on Eu_top + Ed_bottom of the TWICE-Raman-scattered light (b_el = 0), the
    leading term single_scattering() neglects: the energy emitted at l by second Raman events
    in the whole layer, which is at least what leaves through the top and bottom.

        P1(l')     = integral_0^d E_o1(z, l') dz   (track length of the once-Raman light at l':
                     each emitted ray contributes (1 - exp(-c' L)) / c', L its distance to the
                     boundary, weighted by p(psi) and by the once-Raman source at its depth)
        emitted(l) = integral dl' b_R(l') f(l' -> l) (l'/l) P1(l')

    P1 is tabulated every grid_nm nm and interpolated linearly; its l'' integral uses Simpson's
    rule with step_nm. The third and higher orders are smaller again by a factor of order
    b_R d (times a log factor from grazing paths) and are not included. Returns an array over
    wavelengths_nm [W m^-2 nm^-1].
    """
    lam = np.atleast_1d(np.asarray(wavelengths_nm, dtype=np.float64))
    d = float(depth_m)
    e0_fn, c_fn = _source_and_attenuation(absorption, irradiance, b488, exponent)

    def line_grid(l, step):               # excitation wavelengths that feed emission l
        lo, hi = 1e7 / (1e7 / l + DK_MAX), 1e7 / (1e7 / l + DK_MIN)
        n = int(math.ceil((hi - lo) / step)) + 1
        return np.linspace(lo, hi, n + (n % 2 == 0))

    mu, wmu = _mu_quadrature(mu_nodes)
    pw = 2.0 * math.pi * wmu * raman_phase(mu, beta)
    lp_lo = 1e7 / (1e7 / lam.min() + DK_MAX)
    lp_hi = 1e7 / (1e7 / lam.max() + DK_MIN)
    tab = np.linspace(lp_lo, lp_hi, int(math.ceil((lp_hi - lp_lo) / grid_nm)) + 1)
    p1 = np.empty(tab.size)
    for j, l1 in enumerate(tab):
        l2 = line_grid(l1, step_nm)
        src = e0_fn(l2) * raman_b(l2, b488, exponent) * raman_redistribution(l2, l1) * (l2 / l1)
        c1 = float(c_fn(np.array([l1]))[0])
        s2 = (c_fn(l2) * d)[:, None]          # beam optical depth at l''
        s1 = (c1 * d / mu)[None, :]           # slant optical depth of the once-Raman ray at l'
        # int_0^d exp(-c'' z) [(1 - exp(-c' (d - z)/mu)) + (1 - exp(-c' z/mu))] dz
        track = d * (2.0 * _h(s2) - _k(s2, s1) - _h(s2 + s1))
        p1[j] = integrate.simpson(src * (track @ pw), x=l2) / c1
    out = np.empty(lam.size)
    for i, l in enumerate(lam):
        l1 = line_grid(l, step_nm)
        out[i] = integrate.simpson(raman_b(l1, b488, exponent) * raman_redistribution(l1, l)
                                   * (l1 / l) * np.interp(l1, tab, p1), x=l1)
    return out


# --- analog Monte Carlo with explicit wavelength changes ------------------------------------------

SPECTRAL_KEYS = ("Eu_top", "Ed_bottom", "Eou_top")
CHUNK = 500_000           # photons walked at once (memory: a few tens of MB)
BUDGET_KEYS = ("incident", "raman_top", "raman_bottom", "direct_bottom", "elastic_top",
               "elastic_bottom", "absorbed")


class _Binner:
    """Emission bins [l_i - h, l_i + h]: searchsorted on interleaved edges when they do not
    overlap, else one mask per bin."""

    def __init__(self, centres, width):
        self.centres = centres
        self.h = 0.5 * width
        order = np.argsort(centres)
        self.order = order
        c = centres[order]
        self.fast = bool(np.all(np.diff(c) >= 2.0 * self.h * (1.0 - 1e-12)))
        self.edges = np.column_stack([c - self.h, c + self.h]).ravel()

    def add(self, acc, lam, weight):
        if lam.size == 0:
            return
        if self.fast:
            j = np.searchsorted(self.edges, lam, side="right") - 1
            inside = (j >= 0) & (j % 2 == 0) & (j < self.edges.size)
            if inside.any():
                sums = np.bincount(j[inside] // 2, weights=weight[inside],
                                   minlength=self.centres.size)
                acc[self.order] += sums
        else:
            for i, c in enumerate(self.centres):
                m = np.abs(lam - c) <= self.h
                acc[i] += weight[m].sum()


def _photons(w, lam):
    """Photon flux [photons s^-1 m^-2] carried by energy weight w [W m^-2] at lam [nm]."""
    return float(np.sum(w * lam) * 1e-9 / (H_PLANCK * C_LIGHT))


def _walk_batch(rng, n, d, a_fn, bel_fn, e0_fn, b488, exponent, beta, lo, hi, binner,
                mu_cut, max_flights):
    nb = binner.centres.size
    spec = {k + s: np.zeros(nb) for k in SPECTRAL_KEYS for s in ("", "_once", "_multi")}
    budget = dict.fromkeys(BUDGET_KEYS, 0.0)

    lam = rng.uniform(lo, hi, n)                      # continuous excitation wavelength
    w = e0_fn(lam) * (hi - lo)                        # sum / n estimates integrals over l'
    budget["incident"] = _photons(w, lam)
    z = np.zeros(n)
    mu = np.ones(n)                                   # direction cosine, + downward
    n_raman = np.zeros(n, dtype=np.int64)
    scattered = np.zeros(n, dtype=bool)               # any event yet (for the budget only)

    cum_w = np.cumsum(WALRAFEN_WEIGHTS) / WALRAFEN_WEIGHTS.sum()
    for _ in range(max_flights):
        if lam.size == 0:
            break
        ka = a_fn(lam)
        kel = bel_fn(lam)
        kr = raman_b(lam, b488, exponent)
        c = ka + kel + kr
        z1 = z + mu * rng.exponential(size=lam.size) / c   # exponential free path, rate c(l)

        # escapes: through the top going up, through the bottom going down
        for where, esc in (("top", z1 <= 0.0), ("bottom", z1 >= d)):
            if not esc.any():
                continue
            le, we, me, ne = lam[esc], w[esc], np.abs(mu[esc]), n_raman[esc]
            r = ne > 0
            once = ne == 1
            multi = ne > 1
            key = "Eu_top" if where == "top" else "Ed_bottom"
            for suffix, sel in (("", r), ("_once", once), ("_multi", multi)):
                binner.add(spec[key + suffix], le[sel], we[sel])
                if where == "top":
                    wq = we[sel] * _inverse_mu(me[sel], mu_cut)
                    binner.add(spec["Eou_top" + suffix], le[sel], wq)
            budget["raman_" + where] += _photons(we[r], le[r])
            el = ~r & scattered[esc]
            budget["elastic_" + where] += _photons(we[el], le[el])
            if where == "bottom":
                budget["direct_bottom"] += _photons(we[~r & ~scattered[esc]],
                                                    le[~r & ~scattered[esc]])

        # interactions inside: absorption / elastic (isotropic) / Raman, by a : b_el : b_R
        keep = (z1 > 0.0) & (z1 < d)
        xi = rng.uniform(size=lam.size) * c
        absorbed = keep & (xi < ka)
        budget["absorbed"] += _photons(w[absorbed], lam[absorbed])
        elastic = keep & ~absorbed & (xi < ka + kel)
        raman = keep & ~absorbed & ~elastic
        keep &= ~absorbed

        mu = mu.copy()
        mu[elastic] = rng.uniform(-1.0, 1.0, int(elastic.sum()))
        m = int(raman.sum())
        if m:
            # shift: choose a Walrafen line, then a Gaussian wavenumber shift in it
            line = np.searchsorted(cum_w, rng.uniform(size=m), side="right")
            line = np.minimum(line, WALRAFEN_WEIGHTS.size - 1)
            dk = WALRAFEN_CENTRES[line] + WALRAFEN_SIGMA[line] * rng.standard_normal(m)
            k_new = 1e7 / lam[raman] - dk
            if np.any(k_new <= 0.0):
                raise ValueError("a Raman shift went beyond zero wavenumber (wavelength > ~2.8 um)")
            lam_new = 1e7 / k_new
            w = w.copy()
            w[raman] *= lam[raman] / lam_new          # photons conserved: energy times l'/l
            lam = lam.copy()
            lam[raman] = lam_new
            # new direction about the old one: cos psi from p, azimuth uniform
            cpsi = sample_raman_cos(rng.uniform(size=m), beta)
            phi = rng.uniform(0.0, 2.0 * math.pi, m)
            mu0 = mu[raman]
            sin0 = np.sqrt(np.maximum(0.0, 1.0 - mu0 * mu0))
            spsi = np.sqrt(np.maximum(0.0, 1.0 - cpsi * cpsi))
            mu[raman] = np.clip(mu0 * cpsi + sin0 * spsi * np.cos(phi), -1.0, 1.0)
            n_raman = n_raman + raman
        scattered = scattered | elastic | raman

        lam, w, z, mu, n_raman, scattered = (lam[keep], w[keep], z1[keep], mu[keep],
                                             n_raman[keep], scattered[keep])
    else:
        if lam.size:
            raise RuntimeError(f"{lam.size} photons still alive after {max_flights} flights")
    return spec, budget


def reference_walk(wavelengths_nm, depth_m, absorption, *, elastic=None, b488: float = B488,
                   exponent: float = EXPONENT, beta: float = BETA,
                   excitation_range_nm=(350.0, 700.0), irradiance=None, photons: int = 1_000_000,
                   seed: int = 0, bin_nm: float = 2.0, batches: int = 20, mu_cut: float = 0.0,
                   max_flights: int = 100_000):
    """Analog Monte Carlo of the scene above with explicit wavelength changes (slow, plain).

    Each photon gets a continuous excitation wavelength l' uniform in excitation_range_nm =
    (lo, hi) and energy weight E0(l') (hi - lo), so that (sum over photons)/photons estimates
    integrals over l' in [lo, hi] (light excited outside it is absent: choose the range to cover
    1e7/(1e7/l + 4200) .. 1e7/(1e7/l + 2700) for every emission bin of interest, further for
    multiple Raman orders). It enters at z = 0 going down, flies exponential free paths of rate
    c(l) = a + b_el + b_R at its current wavelength, and at each interaction is absorbed,
    scattered isotropically, or Raman-scattered, with probabilities a : b_el : b_R. A Raman
    event draws dk from the Walrafen mixture, sets 1e7/l = 1e7/l' - dk, multiplies the energy
    weight by l'/l (photon conservation), draws cos psi from 1 + beta cos^2 psi exactly (inverse
    CDF) and a uniform azimuth, and counts one more Raman order. All orders are followed until
    every photon has been absorbed or has left through z = 0 or z = d. Photons are processed in
    numpy arrays, one flight per loop pass.

    Scoring: Raman photons crossing z = 0 upward (Eu_top: weight, Eou_top: weight/|mu|) and
    z = d downward (Ed_bottom) into emission bins [l_i - bin_nm/2, l_i + bin_nm/2], divided by
    bin_nm. A bin value is the AVERAGE of the spectral density over the bin, which differs from
    the density at the centre by (bin_nm^2 / 24) f'' (f'' the second derivative in nm): keep
    bins small (2 nm) and the inputs smooth, or average the reference over the same bin. Eou's
    1/|mu| score has a logarithmically divergent variance (grazing photons: the radiance leaving
    at grazing angles is finite), so its standard error is less trustworthy than Eu's and Ed's;
    mu_cut > 0 scores 2/mu_cut instead below mu_cut (finite variance; single_scattering() with
    the same mu_cut gives that estimator's exact expectation).

    Returns a dict: wavelengths; for each of Eu_top, Ed_bottom, Eou_top a (mean, standard error)
    pair of arrays [W m^-2 nm^-1]; the same with suffix "_once" for photons with exactly one
    Raman event (with b_el = 0 that is exactly what single_scattering() computes) and "_multi"
    for two or more (compare with second_order_bound()); and "budget",
    a dict of (mean, standard error) photon fluxes [photons s^-1 m^-2] over all wavelengths:
    incident, raman_top, raman_bottom, direct_bottom (never scattered), elastic_top and
    elastic_bottom (scattered, never Raman), absorbed; these sum to the incident flux photon by
    photon (energy weight times l/l' is conserved). Standard errors are the sample standard
    deviation of `batches` independent batches over sqrt(batches). Random numbers come from
    numpy.random.default_rng(seed).
    """
    lam_out = np.atleast_1d(np.asarray(wavelengths_nm, dtype=np.float64))
    lo, hi = map(float, excitation_range_nm)
    if not (0.0 < lo < hi):
        raise ValueError("excitation_range_nm must be (lo, hi) with 0 < lo < hi")
    if batches < 2 or photons < batches:
        raise ValueError("need at least 2 batches and one photon per batch")
    d = float(depth_m)
    a_fn = _callable(absorption, 0.0)
    bel_fn = _callable(elastic, 0.0)
    e0_fn = _callable(irradiance, 1.0)
    binner = _Binner(lam_out, float(bin_nm))
    rng = np.random.default_rng(seed)

    spec_b, budget_b = [], []
    for n in np.diff(np.linspace(0, photons, batches + 1).astype(np.int64)):
        spec, budget = None, None
        for m in np.diff(np.arange(0, n + CHUNK, CHUNK).clip(max=n)):   # bounded memory
            if m == 0:
                continue
            sp, bu = _walk_batch(rng, int(m), d, a_fn, bel_fn, e0_fn, b488, exponent, beta,
                                 lo, hi, binner, float(mu_cut), max_flights)
            if spec is None:
                spec, budget = sp, bu
            else:
                spec = {k: spec[k] + sp[k] for k in spec}
                budget = {k: budget[k] + bu[k] for k in budget}
        spec_b.append({k: v / (n * bin_nm) for k, v in spec.items()})
        budget_b.append({k: v / n for k, v in budget.items()})

    def stats(vals):
        vals = np.asarray(vals)
        return vals.mean(axis=0), vals.std(axis=0, ddof=1) / math.sqrt(batches)

    out = {"wavelengths": lam_out}
    for k in spec_b[0]:
        out[k] = stats([s[k] for s in spec_b])
    out["budget"] = {k: tuple(float(v) for v in stats([b[k] for b in budget_b]))
                     for k in BUDGET_KEYS}
    return out


# Lee, Z., Hu, C., Shang, S., Du, K., Lewis, M., Arnone, R. and Brewin, R. (2013). Penetration of
# UV-visible solar radiation in the global oceans: insights from ocean color remote sensing.
# J. Geophys. Res. Oceans 118, 4241-4255, Eq. 11: the Raman factor of an observed Rrs at a band,
# RF = alpha Rrs(443) / Rrs(550) + beta1 Rrs(550)^beta2 (Rrs in 1/sr), the light without Raman
# being Rrs / (1 + RF). Coefficients per band as NASA's l2gen applies them (src/l2gen/raman.c,
# L. McKinna 2015), not checked against the paper's table; the same 18 numbers in an
# independent copy that cites the paper (GitHub kelseybisson/GIOP, single_wv_comps.m, commit
# d195509; its band 555 for 551) and in NASA's l2gen copies (checked 2026-11-29); OceanOptics/
# MISCToolbox's correct_Raman.m writes beta2 without its minus sign, which would make RF fall
# in clearer water: band (nm): (alpha, beta1, beta2)
LEE_2013 = {412.0: (0.003, 0.014, -0.022), 443.0: (0.004, 0.015, -0.023),
            488.0: (0.011, 0.010, -0.051), 531.0: (0.015, 0.010, -0.070),
            551.0: (0.017, 0.010, -0.080), 667.0: (0.018, 0.010, -0.081)}
LEE_2013_BANDS_NM = tuple(LEE_2013)


def lee_2013_raman_share(rrs443: float, rrs550: float, band_nm: float = 551.0) -> float:
    """The Raman share of Rrs at one of Lee et al. (2013)'s bands, RF / (1 + RF), by their
    empirical Eq. 11 from the whole (Raman included) Rrs at 443 and 550 nm in 1/sr."""
    alpha, beta1, beta2 = LEE_2013[band_nm]
    factor = alpha * rrs443 / rrs550 + beta1 * rrs550 ** beta2
    return factor / (1.0 + factor)
