"""Shared helpers for the physics tests: z-scores with a Bonferroni-style bound, chi-square
goodness-of-fit on histogram cells, and a few independent references (written here from the
textbook formulas, not taken from oceanmc) that several test modules need.

Every statistical assertion here has two sides (DESIGN.md section 5):
- a z-score bound |z| < z_max, where z_max grows with the number of compared quantities so that
  the family-wise false-alarm rate stays that of a single |z| < 4 test (p ~ 6e-5);
- a cap on the relative error, so that a test with a huge standard error cannot pass by being
  underpowered.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import stats

Z_SINGLE = 4.0   # |z| bound for one compared quantity


# --- z-scores ---------------------------------------------------------------------------------

def z_bound(n_compared: int, z_single: float = Z_SINGLE, dof: int | None = None) -> float:
    """The |z| bound that keeps the family-wise two-sided false-alarm probability of n_compared
    independent z-tests equal to that of one normal test at z_single (Bonferroni). When the
    standard error is itself estimated from few batches, z follows Student's t with dof =
    batches - 1 degrees of freedom (heavier tails), and the bound is taken from it."""
    n = max(1, int(n_compared))
    p_single = 2.0 * stats.norm.sf(z_single)
    if dof is None:
        return float(stats.norm.isf(0.5 * p_single / n))
    return float(stats.t.isf(0.5 * p_single / n, dof))


def zscores(estimate, reference, stderr) -> np.ndarray:
    """(estimate - reference) / stderr, elementwise. A zero standard error (an estimate without
    noise, e.g. exact weights; or one at the level of rounding) gives z = 0 where the estimate equals the reference to 1e-9
    relative (rounding in the tally sums) and +-inf otherwise."""
    est = np.asarray(estimate, dtype=np.float64)
    ref = np.asarray(reference, dtype=np.float64)
    se = np.asarray(stderr, dtype=np.float64)
    est, ref, se = np.broadcast_arrays(est, ref, se)
    diff = est - ref
    z = np.zeros(est.shape)
    # a standard error at the level of rounding in the batch sums counts as none
    noisy = se > 1e-12 * np.maximum(np.abs(ref), np.abs(est))
    z[noisy] = diff[noisy] / se[noisy]
    exact = ~noisy
    tol = 1e-9 * np.maximum(np.abs(ref[exact]), 1e-300)
    z[exact] = np.where(np.abs(diff[exact]) <= tol, 0.0, np.copysign(np.inf, diff[exact]))
    return z


def assert_z(estimate, reference, stderr, *, rel_max: float | None = None,
             abs_max: float | None = None, n_compared: int | None = None,
             z_single: float = Z_SINGLE, dof: int | None = None, what: str = "") -> np.ndarray:
    """Asserts |z| below the Bonferroni bound for the number of compared values (by default the
    number of elements), and |estimate - reference| <= rel_max |reference| (or <= abs_max where
    given, for references near 0). dof: degrees of freedom of a batch standard error (batches - 1;
    see z_bound). Returns the z-scores (for reporting)."""
    est = np.atleast_1d(np.asarray(estimate, dtype=np.float64))
    ref = np.broadcast_to(np.asarray(reference, dtype=np.float64), est.shape)
    se = np.broadcast_to(np.asarray(stderr, dtype=np.float64), est.shape)
    assert np.all(np.isfinite(est)), f"{what}: non-finite estimate {est}"
    assert np.all(np.isfinite(se)), f"{what}: non-finite standard error {se}"
    z = zscores(est, ref, se)
    n = est.size if n_compared is None else n_compared
    bound = z_bound(n, z_single, dof)
    worst = int(np.argmax(np.abs(z)))
    assert np.all(np.abs(z) < bound), (
        f"{what}: |z| = {abs(z.flat[worst]):.2f} >= {bound:.2f} (over {n} values) at index "
        f"{np.unravel_index(worst, est.shape)}: estimate {est.flat[worst]:.6g} +- "
        f"{se.flat[worst]:.3g}, reference {ref.flat[worst]:.6g}")
    if rel_max is not None or abs_max is not None:
        err = np.abs(est - ref)
        allowed = np.zeros(est.shape)
        if rel_max is not None:
            allowed = np.maximum(allowed, rel_max * np.abs(ref))
        if abs_max is not None:
            allowed = np.maximum(allowed, abs_max)
        bad = err > allowed
        if np.any(bad):
            i = int(np.argmax(err - allowed))
            raise AssertionError(
                f"{what}: error {err.flat[i]:.3g} above the cap {allowed.flat[i]:.3g} at index "
                f"{np.unravel_index(i, est.shape)}: estimate {est.flat[i]:.6g} +- "
                f"{se.flat[i]:.3g}, reference {ref.flat[i]:.6g} (rel_max={rel_max}, "
                f"abs_max={abs_max})")
    return z


def assert_same(a, se_a, b, se_b, **kwargs) -> np.ndarray:
    """Two independent estimates of the same quantity agree: z = (a - b)/sqrt(se_a^2 + se_b^2);
    the relative cap is taken against b."""
    se = np.sqrt(np.asarray(se_a, dtype=np.float64) ** 2 + np.asarray(se_b, dtype=np.float64) ** 2)
    return assert_z(a, b, se, **kwargs)


def dof_of(result) -> int:
    """Degrees of freedom of a Result's batch standard errors."""
    return int(result.attrs["batches"]) - 1


def batch_mean_se(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard error over the leading (batch) axis."""
    values = np.asarray(values, dtype=np.float64)
    return values.mean(axis=0), values.std(axis=0, ddof=1) / math.sqrt(values.shape[0])


def sample_mean_se(samples: np.ndarray) -> tuple[float, float]:
    samples = np.asarray(samples, dtype=np.float64)
    return float(samples.mean()), float(samples.std(ddof=1) / math.sqrt(samples.size))


# --- chi-square -------------------------------------------------------------------------------

def merge_bins(observed: np.ndarray, expected: np.ndarray, min_expected: float = 20.0
               ) -> tuple[np.ndarray, np.ndarray]:
    """Merges neighbouring cells (in order) until each holds at least min_expected expected
    counts; the remainder joins the last cell."""
    obs_out, exp_out = [], []
    o_acc = e_acc = 0.0
    for o, e in zip(observed, expected):
        o_acc += o
        e_acc += e
        if e_acc >= min_expected:
            obs_out.append(o_acc)
            exp_out.append(e_acc)
            o_acc = e_acc = 0.0
    if e_acc > 0.0 or o_acc > 0.0:
        if exp_out:
            obs_out[-1] += o_acc
            exp_out[-1] += e_acc
        else:
            obs_out.append(o_acc)
            exp_out.append(e_acc)
    return np.array(obs_out), np.array(exp_out)


def chi2_gof(observed, probabilities, *, min_expected: float = 20.0) -> tuple[float, int, float]:
    """Pearson chi-square of cell counts against cell probabilities (which must sum to 1: the
    cells cover the whole domain). Returns (statistic, degrees of freedom, p-value)."""
    observed = np.asarray(observed, dtype=np.float64).ravel()
    probabilities = np.asarray(probabilities, dtype=np.float64).ravel()
    assert abs(probabilities.sum() - 1.0) < 1e-6, \
        f"cell probabilities sum to {probabilities.sum()}, not 1"
    assert np.all(probabilities >= -1e-15), "negative cell probability"
    n = observed.sum()
    obs, exp = merge_bins(observed, n * np.clip(probabilities, 0.0, None), min_expected)
    # cells with no probability at all must see no sample
    stat, p = stats.chisquare(obs, exp * (obs.sum() / exp.sum()))
    return float(stat), len(obs) - 1, float(p)


def assert_chi2(observed, probabilities, *, p_min: float = 1e-4, rel_cap: float = 0.05,
                min_cap_count: float = 10000.0, min_expected: float = 20.0,
                what: str = "") -> tuple[float, int, float]:
    """Chi-square goodness of fit (p-value above p_min) plus a power check: every cell expected
    to hold at least min_cap_count samples must match within rel_cap, and there must be such
    cells (so that too few samples cannot pass); cells of zero probability must be empty.
    rel_cap=None skips the power check (for a fine histogram whose marginals get it)."""
    observed = np.asarray(observed, dtype=np.float64).ravel()
    probabilities = np.asarray(probabilities, dtype=np.float64).ravel()
    n = observed.sum()
    empty = probabilities <= 0.0
    assert not np.any(observed[empty] > 0), \
        f"{what}: {observed[empty].sum():.0f} samples in cells of zero probability"
    stat, dof, p = chi2_gof(observed, probabilities, min_expected=min_expected)
    assert dof >= 5, f"{what}: only {dof} degrees of freedom; the test has no power"
    assert p > p_min, f"{what}: chi-square {stat:.1f} on {dof} dof, p = {p:.2e} < {p_min:g}"
    print(f"{what}: chi-square {stat:.1f} on {dof} dof, p = {p:.3f}")
    if rel_cap is None:
        return stat, dof, p
    expected = n * probabilities
    big = expected >= min_cap_count
    assert big.any(), f"{what}: no cell expects {min_cap_count} samples; use more samples"
    rel = np.abs(observed[big] - expected[big]) / expected[big]
    assert rel.max() < rel_cap, \
        f"{what}: a well-populated cell is off by {rel.max():.3%} (cap {rel_cap:.1%})"
    return stat, dof, p


# --- independent physics references -----------------------------------------------------------

def fresnel_reference(n1: float, n2: float, theta_i: float) -> float:
    """Unpolarized Fresnel reflectance in the sine/tangent form (Born & Wolf 1.5.3, Eqs. 35a-b),
    written independently of oceanmc.kernel.surface.fresnel (which uses the cosine form)."""
    s = n1 / n2 * math.sin(theta_i)
    if s >= 1.0:
        return 1.0
    if theta_i == 0.0:
        return ((n1 - n2) / (n1 + n2)) ** 2
    theta_t = math.asin(s)
    rs = math.sin(theta_i - theta_t) ** 2 / math.sin(theta_i + theta_t) ** 2
    rp = math.tan(theta_i - theta_t) ** 2 / math.tan(theta_i + theta_t) ** 2
    return 0.5 * (rs + rp)


def chandrasekhar_h(w0: float, nodes: int = 400):
    """Chandrasekhar's H function for isotropic scattering with albedo w0, from the iteration
    1/H(mu) = sqrt(1 - w0) + (w0/2) int_0^1 mu' H(mu') / (mu + mu') dmu' (Chandrasekhar 1960,
    Radiative Transfer, Eq. V.(35)) on Gauss-Legendre nodes; returns a vectorised H(mu)
    (Nystrom interpolation, exact to the quadrature)."""
    x, wts = np.polynomial.legendre.leggauss(nodes)
    mu = 0.5 * (x + 1.0)
    wt = 0.5 * wts
    s = math.sqrt(1.0 - w0)
    h = np.ones(nodes)
    for _ in range(10_000):
        new = 1.0 / (s + 0.5 * w0 * np.sum(wt * mu * h / (mu[:, None] + mu), axis=1))
        done = np.max(np.abs(new - h)) < 1e-15
        h = new
        if done:
            break

    def H(m):
        m = np.atleast_1d(np.asarray(m, dtype=np.float64))
        return 1.0 / (s + 0.5 * w0 * np.sum(wt * mu * h / (m[:, None] + mu), axis=1))
    return H
