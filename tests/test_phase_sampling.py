"""Phase-function samplers against their densities: chi-square tests of sampled scattering
angles over histogram cells whose probabilities come from independent references (analytic
formulas, or the data file read here), mean-cosine z-tests, backscatter fractions, and the
normalisation of the kernel's evaluate().

Samples are drawn through oceanmc.kernel.phase.dispatch.sample_cos on the scene arrays that
oceanmc.scene.build makes from a config, i.e. the path the photon loop uses (component choice of
mixtures and two-term HG included)."""
import math
from importlib import resources

import numpy as np
import pytest
from numba import njit
from scipy import integrate, optimize

import oceanmc
from oceanmc import scene
from oceanmc.scene import phase_tables
from oceanmc.kernel.phase import dispatch

from stats_helpers import assert_chi2, assert_z

N_SAMPLES = 400_000


@njit(cache=False)
def _draw(sc, layer, u_pick, u):
    medium, mf, mi = sc
    out = np.empty(u.shape[0])
    for i in range(u.shape[0]):
        out[i] = dispatch.sample_cos(medium[0], mf, mi, layer, 0, u_pick[i], u[i])
    return out


@njit(cache=False)
def _evaluate(sc, layer, mu):
    medium, mf, mi = sc
    out = np.empty(mu.shape[0])
    for i in range(mu.shape[0]):
        out[i] = dispatch.evaluate(medium[0], mf, mi, layer, mu[i])
    return out


def scene_arrays(phase: dict, b: float = 1.0):
    layer = {"thickness_m": 1.0, "a": 0.1, "phase": phase}
    if phase["model"] != "mixture":
        layer["b"] = b   # a mixture's b is the sum of its components'
    config = oceanmc.load_config({"water": {"layers": [layer]}, "bottom": {"model": "black"}})
    built = scene.build(config)
    return built.medium, built.floats, built.ints


def sample(phase: dict, n: int = N_SAMPLES, seed: int = 1) -> np.ndarray:
    sc = scene_arrays(phase)
    rng = np.random.default_rng(seed)
    cos = _draw(sc, 0, rng.random(n), rng.random(n))
    assert np.all(np.isfinite(cos)) and np.all(np.abs(cos) <= 1.0)
    return cos


def counts_in_psi(cos: np.ndarray, psi_edges: np.ndarray) -> np.ndarray:
    """Histogram of scattering angles (rad) over psi_edges (0 .. pi)."""
    psi = np.arccos(np.clip(cos, -1.0, 1.0))
    counts, _ = np.histogram(psi, bins=psi_edges)
    return counts


def forward_edges(first: float = 1e-4, n_log: int = 30, n_lin: int = 60) -> np.ndarray:
    """Cells in scattering angle: log-spaced near the forward peak, linear beyond 0.3 rad."""
    return np.concatenate([[0.0], np.geomspace(first, 0.3, n_log),
                           np.linspace(0.3, math.pi, n_lin + 1)[1:]])


# --- independent references -------------------------------------------------------------------

def hg_cdf_mu(g, mu):
    """P(cos <= mu) for Henyey-Greenstein (integrated analytically from -1)."""
    mu = np.asarray(mu, dtype=np.float64)
    if g == 0.0:
        return 0.5 * (mu + 1.0)
    return (1.0 - g * g) / (2.0 * g) * (1.0 / np.sqrt(1.0 + g * g - 2.0 * g * mu)
                                        - 1.0 / (1.0 + g))


def hg_pdf(g, mu):
    return (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * mu) ** 1.5)


def hg_cell_probs(g, psi_edges):
    mu = np.cos(psi_edges)
    return hg_cdf_mu(g, mu[:-1]) - hg_cdf_mu(g, mu[1:])


def quadratic_cell_probs(beta, psi_edges):
    """p ~ 1 + beta cos^2: P(cell) from the antiderivative mu + beta mu^3 / 3."""
    mu = np.cos(psi_edges)
    F = mu + beta * mu ** 3 / 3.0
    return (F[:-1] - F[1:]) / (2.0 + 2.0 * beta / 3.0)


def ff_phase(psi, n, slope):
    """Fournier-Forand phase function, 1/sr (Fournier & Forand 1994; Fournier & Jonasz 1999;
    Mobley et al. 2002, Eq. 1), written out from the paper's notation."""
    nu = (3.0 - slope) / 2.0
    half = np.sin(psi / 2.0) ** 2
    d = 4.0 / (3.0 * (n - 1.0) ** 2) * half
    d180 = 4.0 / (3.0 * (n - 1.0) ** 2)
    dn = d ** nu
    first = (nu * (1.0 - d) - (1.0 - dn) + (d * (1.0 - dn) - nu * (1.0 - d)) / half) \
        / (4.0 * math.pi * (1.0 - d) ** 2 * dn)
    second = (1.0 - d180 ** nu) * (3.0 * np.cos(psi) ** 2 - 1.0) \
        / (16.0 * math.pi * (d180 - 1.0) * d180 ** nu)
    return first + second


def ff_backscatter(n, slope):
    nu = (3.0 - slope) / 2.0
    d90 = 4.0 / (3.0 * (n - 1.0) ** 2) * math.sin(math.pi / 4.0) ** 2
    return 1.0 - (1.0 - d90 ** (nu + 1.0) - 0.5 * (1.0 - d90 ** nu)) / ((1.0 - d90) * d90 ** nu)


def ff_parameters(bb):
    """(n, slope) on the line n = 1.01 + 0.1542 (slope - 3) (Mobley et al. 2002) with the
    requested backscatter fraction."""
    slope = optimize.brentq(lambda s: ff_backscatter(1.01 + 0.1542 * (s - 3.0), s) - bb,
                            3.0001, 5.5, xtol=1e-13)
    return 1.01 + 0.1542 * (slope - 3.0), slope


def ff_mass(a, b, n, slope):
    """Probability of a <= psi <= b, integrated in log(psi) (the forward peak is a power law)."""
    f = lambda t: 2.0 * math.pi * ff_phase(math.exp(t), n, slope) * math.sin(math.exp(t)) \
        * math.exp(t)
    return integrate.quad(f, math.log(a), math.log(b), epsabs=0.0, epsrel=1e-10, limit=200)[0]


def ff_cell_probs(bb, psi_edges):
    """Cell probabilities of FF; the first cell [0, psi_1] takes the rest of the unit total
    (FF integrates to exactly 1), which is checked separately."""
    n, slope = ff_parameters(bb)
    probs = np.array([ff_mass(a, b, n, slope) for a, b in zip(psi_edges[1:-1], psi_edges[2:])])
    return np.concatenate([[1.0 - probs.sum()], probs])


def linear_q_cell_probs(nodes, q, psi_edges):
    """Cell probabilities of a density q(psi) (per radian) piecewise linear between nodes,
    integrated exactly (q is evaluated at every node and cell edge, so trapezoids are exact)."""
    grid = np.union1d(nodes, psi_edges)
    qg = np.interp(grid, nodes, q)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (qg[1:] + qg[:-1]) * np.diff(grid))])
    at_edges = np.interp(psi_edges, grid, cum)
    total = cum[-1]
    return np.diff(at_edges) / total


# Petzold as the data file's header defines it, read here with numpy.
PETZOLD_FILE = resources.files("oceanmc") / "data" / "petzold_average_particle.csv"


def petzold_reference():
    """(nodes psi in rad, q at nodes, mass below the first node, normalisation): 2 pi p sin psi
    linear between the tabulated nodes; below 0.1 deg p = p(0.12589 deg)(0.12589/psi)^1.346,
    integrated analytically (with sin psi = psi, exact to 1e-7 there)."""
    lines = PETZOLD_FILE.read_text().splitlines()
    rows = np.array([[float(x) for x in line.split(",")] for line in lines
                     if line.strip() and not line.startswith(("#", "angle"))])
    deg, p = rows[:, 0], rows[:, 1]
    psi = np.radians(deg)
    q = 2.0 * math.pi * p * np.sin(psi)
    p_ref = p[np.isclose(deg, 0.12589)][0]
    x0 = math.radians(0.12589)
    m = 1.346
    # int_0^psi0 2 pi p_ref (x0/x)^m x dx = 2 pi p_ref x0^m psi0^(2 - m) / (2 - m)
    below = 2.0 * math.pi * p_ref * x0 ** m * psi[0] ** (2.0 - m) / (2.0 - m)
    above = float(np.sum(0.5 * (q[1:] + q[:-1]) * np.diff(psi)))
    return psi, q, below, below + above


def petzold_cell_probs(psi_edges):
    """psi_edges[1] must be the first node (0.1 deg): the first cell is the power-law part."""
    psi, q, below, total = petzold_reference()
    assert psi_edges[0] == 0.0 and math.isclose(psi_edges[1], psi[0])
    rest = linear_q_cell_probs(psi, q, psi_edges[1:]) * (total - below) / total
    return np.concatenate([[below / total], rest])


def petzold_edges(split: int = 3) -> np.ndarray:
    """0, then the table's nodes with every interval split in `split` (to test the sampler's
    inversion inside an interval, not only at the nodes)."""
    psi, *_ = petzold_reference()
    fine = [psi[0]]
    for a, b in zip(psi[:-1], psi[1:]):
        fine += list(np.linspace(a, b, split + 1)[1:])
    return np.concatenate([[0.0], fine])


def petzold_moments():
    """(g, bb/b) of the reference, integrating the linear pieces exactly in closed form."""
    psi, q, below, total = petzold_reference()
    g = 0.0
    back = 0.0
    for a, b, qa, qb in zip(psi[:-1], psi[1:], q[:-1], q[1:]):
        s = (qb - qa) / (b - a)
        # int (qa + s (x - a)) cos x dx
        lin = lambda x: (qa + s * (x - a)) * math.sin(x) + s * math.cos(x)
        g += lin(b) - lin(a)
        if a >= math.pi / 2.0 - 1e-12:
            back += 0.5 * (qa + qb) * (b - a)
    # below 0.1 deg cos psi = 1 to 1.5e-6
    g += below
    return g / total, back / total


# --- tests ------------------------------------------------------------------------------------

def test_isotropic():
    cos = sample({"model": "isotropic"})
    edges = np.linspace(0.0, math.pi, 61)
    assert_chi2(counts_in_psi(cos, edges), 0.5 * (np.cos(edges[:-1]) - np.cos(edges[1:])),
                what="isotropic")
    counts, _ = np.histogram(cos, bins=np.linspace(-1, 1, 41))
    assert_chi2(counts, np.full(40, 1 / 40), what="isotropic in cos")


@pytest.mark.parametrize("model, beta", [("rayleigh", 1.0), ("pure_water", 0.835)])
def test_quadratic(model, beta):
    cos = sample({"model": model})
    edges = np.arccos(np.linspace(1.0, -1.0, 31))
    assert_chi2(counts_in_psi(cos, edges), quadratic_cell_probs(beta, edges), what=model)
    # the textbook normalisations: (3/16 pi) for Rayleigh, 0.06225 for pure sea water
    const = 1.0 / (2.0 * math.pi * (2.0 + 2.0 * beta / 3.0))
    assert const == pytest.approx(3.0 / (16.0 * math.pi) if beta == 1.0 else 0.06225, rel=2e-4)
    # <cos> = 0 and <cos^2> = (1/3 + beta/5)/(1 + beta/3)
    m2 = (1.0 / 3.0 + beta / 5.0) / (1.0 + beta / 3.0)
    se2 = np.std(cos ** 2) / math.sqrt(cos.size)
    assert_z(np.mean(cos ** 2), m2, se2, rel_max=0.01, what=f"{model} <cos^2>")
    assert_z(np.mean(cos), 0.0, np.std(cos) / math.sqrt(cos.size), abs_max=0.005,
             what=f"{model} <cos>")


HG_G = [-0.9, -0.5, 0.0, 0.3, 0.8, 0.95, 0.99]


@pytest.mark.parametrize("g", HG_G)
def test_henyey_greenstein(g):
    cos = sample({"model": "henyey_greenstein", "g": g}, seed=7)
    edges = forward_edges(1e-4, n_lin=40)
    assert_chi2(counts_in_psi(cos, edges), hg_cell_probs(g, edges), what=f"HG g={g}")
    # <cos> = g
    mean, se = np.mean(cos), np.std(cos, ddof=1) / math.sqrt(cos.size)
    assert_z(mean, g, se, abs_max=0.005, what=f"HG g={g} <cos>")


def test_henyey_greenstein_near_one():
    """g = 0.9999 (allowed by the schema): still a valid sampler, <cos> = g, no NaN."""
    g = 0.9999
    cos = sample({"model": "henyey_greenstein", "g": g}, seed=9)
    edges = forward_edges(1e-6, n_log=40)
    assert_chi2(counts_in_psi(cos, edges), hg_cell_probs(g, edges), what="HG g=0.9999")
    mean, se = np.mean(cos), np.std(cos, ddof=1) / math.sqrt(cos.size)
    assert_z(mean, g, se, abs_max=1e-4, what="HG 0.9999 <cos>")


@pytest.mark.parametrize("g1, g2, alpha", [(0.95, -0.5, 0.95), (0.7, -0.3, 0.6)])
def test_two_term_hg(g1, g2, alpha):
    cos = sample({"model": "two_term_hg", "g1": g1, "g2": g2, "alpha": alpha}, seed=11)
    edges = forward_edges(1e-4)
    probs = alpha * hg_cell_probs(g1, edges) + (1.0 - alpha) * hg_cell_probs(g2, edges)
    assert_chi2(counts_in_psi(cos, edges), probs, what="two-term HG")
    mean, se = np.mean(cos), np.std(cos, ddof=1) / math.sqrt(cos.size)
    assert_z(mean, alpha * g1 + (1 - alpha) * g2, se, abs_max=0.005, what="TTHG <cos>")


@pytest.mark.parametrize("bb", [0.0183, 0.005, 0.1])
def test_fournier_forand(bb):
    n, slope = ff_parameters(bb)
    # FF integrates to 1 (Fournier & Jonasz 1999): check the reference before trusting it
    total = ff_mass(1e-14, math.pi, n, slope)
    assert total == pytest.approx(1.0, abs=2e-3)
    cos = sample({"model": "fournier_forand", "bb_ratio": bb}, seed=13)
    edges = forward_edges(1e-6, n_log=40)
    assert_chi2(counts_in_psi(cos, edges), ff_cell_probs(bb, edges), what=f"FF bb={bb}")
    # the requested backscatter fraction: from the samples (binomial z-test) and the table
    back = np.mean(cos < 0.0)
    assert_z(back, bb, math.sqrt(bb * (1 - bb) / cos.size), rel_max=0.05,
             what=f"FF bb={bb} sampled backscatter fraction")
    psi, q, _ = phase_tables.fournier_forand_table(bb)
    g_table, bb_table = phase_tables.moments(psi, q)
    assert bb_table == pytest.approx(bb, rel=1e-3)
    # and the table's mean cosine is FF's
    g_ref = ff_mass_weighted_cos(n, slope)
    assert g_table == pytest.approx(g_ref, abs=2e-3)


def ff_mass_weighted_cos(n, slope):
    f = lambda t: 2.0 * math.pi * ff_phase(math.exp(t), n, slope) * math.sin(math.exp(t)) \
        * math.exp(t) * math.cos(math.exp(t))
    lo = integrate.quad(f, math.log(1e-14), math.log(0.2), epsrel=1e-10, limit=200)[0]
    hi = integrate.quad(lambda x: 2.0 * math.pi * ff_phase(x, n, slope) * math.sin(x)
                        * math.cos(x), 0.2, math.pi, epsrel=1e-10, limit=200)[0]
    return lo + hi


def test_petzold():
    g_ref, bb_ref = petzold_moments()
    # the header's numbers follow from the header's definition
    assert abs(g_ref - 0.924) < 6e-4
    assert abs(bb_ref - 0.0181) < 6e-5
    # the kernel's table has them too
    psi, q, _ = phase_tables.petzold_table()
    g_tab, bb_tab = phase_tables.moments(psi, q)
    assert abs(g_tab - 0.924) < 6e-4 and abs(bb_tab - 0.0181) < 6e-5
    cos = sample({"model": "petzold"}, n=1_000_000, seed=17)
    edges = petzold_edges()
    assert_chi2(counts_in_psi(cos, edges), petzold_cell_probs(edges), what="Petzold")
    mean, se = np.mean(cos), np.std(cos, ddof=1) / math.sqrt(cos.size)
    assert_z(mean, g_ref, se, abs_max=0.002, what="Petzold <cos>")
    back = np.mean(cos < 0.0)
    assert_z(back, bb_ref, math.sqrt(bb_ref * (1 - bb_ref) / cos.size), rel_max=0.03,
             what="Petzold backscatter fraction")


USER_NODES_DEG = np.array([1.0, 3.0, 8.0, 20.0, 45.0, 90.0, 120.0, 150.0, 170.0])
USER_VALUES = np.array([40.0, 12.0, 2.5, 0.6, 0.12, 0.05, 0.06, 0.09, 0.11])


@pytest.mark.parametrize("style", ["csv", "whitespace"])
def test_user_table(tmp_path, style):
    """A user table (any scale, nodes not reaching 0 or 180 deg: q = 0 there): 2 pi p sin psi is
    linear between nodes, as the schema documents."""
    scale = 7.3
    if style == "csv":
        text = "# a made-up particle phase function\nangle_deg,value\n" + "".join(
            f"{a},{scale * v}\n" for a, v in zip(USER_NODES_DEG, USER_VALUES))
    else:
        text = "".join(f"  {a:g}\t {scale * v:.10g}\n" for a, v in zip(USER_NODES_DEG,
                                                                       USER_VALUES))
    path = tmp_path / f"phase.{style}"
    path.write_text(text)
    cos = sample({"model": "table", "file": str(path)}, seed=19)
    nodes = np.concatenate([[0.0], np.radians(USER_NODES_DEG), [math.pi]])
    q = np.concatenate([[0.0], 2 * math.pi * USER_VALUES * np.sin(np.radians(USER_NODES_DEG)),
                        [0.0]])
    edges = np.unique(np.concatenate([nodes, np.linspace(0.0, math.pi, 91)]))
    assert_chi2(counts_in_psi(cos, edges), linear_q_cell_probs(nodes, q, edges),
                what=f"user table ({style})")


def test_mixture():
    """Pure water + Petzold particles + an HG component, weighted by their b."""
    comps = [(0.02, {"model": "pure_water"}), (0.3, {"model": "petzold"}),
             (0.1, {"model": "henyey_greenstein", "g": 0.5})]
    phase = {"model": "mixture",
             "components": [{"b": b, "phase": p} for b, p in comps]}
    cos = sample(phase, n=600_000, seed=23)
    edges = petzold_edges(split=2)
    wsum = sum(b for b, _ in comps)
    probs = (comps[0][0] * quadratic_cell_probs(0.835, edges)
             + comps[1][0] * petzold_cell_probs(edges)
             + comps[2][0] * hg_cell_probs(0.5, edges)) / wsum
    assert_chi2(counts_in_psi(cos, edges), probs, what="mixture")
    g_mix = (comps[1][0] * petzold_moments()[0] + comps[2][0] * 0.5) / wsum
    mean, se = np.mean(cos), np.std(cos, ddof=1) / math.sqrt(cos.size)
    assert_z(mean, g_mix, se, abs_max=0.003, what="mixture <cos>")


# --- evaluate(): the densities the kernel would use for local estimates ------------------------

EVAL_CASES = [
    ({"model": "isotropic"}, lambda mu: np.full_like(mu, 1.0 / (4.0 * math.pi))),
    ({"model": "rayleigh"}, lambda mu: 3.0 / (16.0 * math.pi) * (1.0 + mu ** 2)),
    ({"model": "pure_water"}, lambda mu: (1.0 + 0.835 * mu ** 2)
     / (2.0 * math.pi * (2.0 + 2.0 * 0.835 / 3.0))),
    ({"model": "henyey_greenstein", "g": 0.8}, lambda mu: hg_pdf(0.8, mu)),
    ({"model": "henyey_greenstein", "g": -0.4}, lambda mu: hg_pdf(-0.4, mu)),
    ({"model": "two_term_hg", "g1": 0.9, "g2": -0.4, "alpha": 0.8},
     lambda mu: 0.8 * hg_pdf(0.9, mu) + 0.2 * hg_pdf(-0.4, mu)),
]


@pytest.mark.parametrize("phase, reference", EVAL_CASES,
                         ids=["isotropic", "rayleigh", "pure_water", "hg", "hg_neg", "tthg"])
def test_evaluate_analytic(phase, reference):
    sc = scene_arrays(phase)
    mu = np.linspace(-1.0, 1.0, 201)
    np.testing.assert_allclose(_evaluate(sc, 0, mu), reference(mu), rtol=1e-10)


@pytest.mark.parametrize("phase", [{"model": "petzold"},
                                   {"model": "fournier_forand", "bb_ratio": 0.0183}])
def test_evaluate_tabulated(phase):
    sc = scene_arrays(phase)
    psi = np.linspace(0.05, math.pi - 0.01, 400)
    values = _evaluate(sc, 0, np.cos(psi))
    if phase["model"] == "petzold":
        nodes, q, _, total = petzold_reference()
        ref = np.interp(psi, nodes, q) / total / (2.0 * math.pi * np.sin(psi))
        np.testing.assert_allclose(values, ref, rtol=2e-3)
    else:
        n, slope = ff_parameters(phase["bb_ratio"])
        np.testing.assert_allclose(values, ff_phase(psi, n, slope), rtol=2e-3)
    # normalised over the sphere
    x = np.concatenate([np.geomspace(1e-9, 0.1, 4000), np.linspace(0.1, math.pi, 4000)[1:]])
    total = np.trapezoid(2.0 * math.pi * np.sin(x) * _evaluate(sc, 0, np.cos(x)), x)
    assert total == pytest.approx(1.0, abs=0.02)


def test_evaluate_mixture_is_b_weighted():
    phase = {"model": "mixture", "components": [
        {"b": 0.3, "phase": {"model": "henyey_greenstein", "g": 0.9}},
        {"b": 0.1, "phase": {"model": "rayleigh"}}]}
    sc = scene_arrays(phase)
    mu = np.linspace(-1.0, 1.0, 101)
    ref = 0.75 * hg_pdf(0.9, mu) + 0.25 * 3.0 / (16.0 * math.pi) * (1.0 + mu ** 2)
    np.testing.assert_allclose(_evaluate(sc, 0, mu), ref, rtol=1e-10)


@pytest.mark.parametrize("shape", ["forward", "zero_beyond_1_rad", "few_nodes"])
def test_guide_table_finds_the_interval_a_bisection_finds(shape):
    """The sampler starts its search from a guide table (kernel/phase/tabulated.py); the interval
    it finds must be the one with cdf[i] <= u < cdf[i + 1], for tables with flat stretches of
    the CDF (q = 0) and tables with fewer nodes than cells of interest, and for u at the cells'
    edges, where u * G rounds."""
    from oceanmc.kernel.phase import tabulated
    if shape == "few_nodes":
        psi = np.radians([0.0, 1.0, 20.0, 90.0, 180.0])
        q = np.array([0.0, 5.0, 0.0, 0.0, 1.0])
    else:
        psi = np.concatenate([[0.0], np.geomspace(1e-10, 0.2, 2500),
                              np.linspace(0.2, math.pi, 1001)[1:]])
        q = np.exp(-20.0 * psi) * np.sin(psi) + 1e-9
        if shape == "zero_beyond_1_rad":
            q = np.where(psi > 1.0, 0.0, q)
    psi, q, cdf = phase_tables.normalised(psi, q)
    guide = phase_tables.guide(cdf)
    n = len(psi)
    pool = np.concatenate([psi, q, cdf])
    cells = n - 1
    edges = np.arange(cells + 1) / cells
    u = np.concatenate([np.random.default_rng(3).random(20_000), edges[:-1],
                        np.nextafter(edges[1:], 0.0), np.nextafter(edges[:-1], 1.0), cdf[:-1]])
    u = u[u < 1.0]   # the kernel's uniform draws lie in [0, 1)
    expected = np.searchsorted(cdf, u, side="right") - 1
    found = np.array([tabulated.sample_angle(pool, guide, 0, n, 2 * n, 0, n, x)[0] for x in u])
    assert np.array_equal(found, expected)
