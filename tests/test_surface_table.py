"""The Cox-Munk surface sampled from its table (kernel/surface/cox_munk_table.py, scene/
surface_table.py) against its reference, the facet walk (kernel/surface/cox_munk.py): the
reflectance per incidence from both sides, the leaving directions (moments and binned), energy
closure, reciprocity, whole scenes; the cell layout, the disk cache, the configuration.

Statistical checks use fixed streams. Their standard errors count the table's own noise where
it matters: a table is an estimate from WALKS_PER_NODE walks per incidence node, so a quantity
of the table differs from the walk's by about the standard error of that many walks (quoted
with each test). Bounds: |z| < 4; binned chi-square below dof + 4 sqrt(2 dof)."""
import math

import numba
import numpy as np
import pytest

import oceanmc
from oceanmc import config as cfg
from oceanmc.config.base import ConfigError
from oceanmc.kernel.rng import batch_state, uniform
from oceanmc.kernel.surface import cox_munk_table as layout
from oceanmc.kernel.surface import dispatch
from oceanmc.scene import surface as surface_packer
from oceanmc.scene import surface_table
from surface_helpers import cell_transfer, projected

N_WATER = 1.34
WIND = 7.0
# incidences (deg) from both sides: nodes (0), between nodes, near the critical angle (48.3)
ANGLES = (0.0, 20.0, 40.0, 47.0, 55.0, 70.0, 85.0)


def rough(**surface):
    config = cfg.Surface(model="cox_munk", n_water=N_WATER, **surface)
    packed = surface_packer.pack(config, N_WATER)
    return packed[0], surface_packer.pool(config, packed)


@pytest.fixture(scope="module")
def seven():
    """The 7 m/s surface's record and table (built once, or read from the cache)."""
    return rough(wind_speed_m_s=WIND)


@numba.njit
def draws(surface, floats, ux, uy, uz, n, rng, tabulated):
    """n samples (ox, oy, oz, weight, transmitted) of the surface from direction (ux, uy, uz),
    from its table or by its walk."""
    out = np.empty((n, 5))
    for i in range(n):
        if tabulated:
            ox, oy, oz, w, t = dispatch.sample(surface, ux, uy, uz, uniform(rng), rng, floats)
        else:
            ox, oy, oz, w, t = dispatch.sample(surface, ux, uy, uz, uniform(rng), rng)
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4] = ox, oy, oz, w, t
    return out


def incident(theta_deg, from_air):
    t = math.radians(theta_deg)
    return math.sin(t), 0.0, math.cos(t) * (1.0 if from_air else -1.0)


def table_reflectance(table, theta_deg, from_air):
    """The table's R at an incidence: linear in t = sqrt(1 - mu) between nodes."""
    x = math.sqrt(1.0 - math.cos(math.radians(theta_deg))) * (layout.NODES - 1)
    k = min(int(x), layout.NODES - 2)
    f = x - k
    at = (0 if from_air else 1) * layout.NODES + k
    return (1.0 - f) * table[at] + f * table[at + 1]


def table_reflectance_stderr(alpha, theta_deg, from_air, seed, replicates=8):
    """The standard error of a table's R at an incidence: the spread of R over independent
    tables' worth of walks at that incidence (WALKS_PER_NODE walks of cox_munk_table.walk_node
    each, Latin hypercube strata as the builder draws them)."""
    walks = surface_table.WALKS_PER_NODE
    n1, n2 = (1.0, N_WATER) if from_air else (N_WATER, 1.0)
    branch, t, s, w = (np.empty(2 * walks, dtype=np.int64), np.empty(2 * walks),
                       np.empty(2 * walks), np.empty(2 * walks))
    values = []
    for b in range(replicates):
        stream = batch_state(seed, b)
        permutations = np.random.default_rng(stream)
        strata = np.stack([permutations.permutation(walks) for _ in range(3)])
        count = layout.walk_node(alpha, n1, n2, math.cos(math.radians(theta_deg)), walks,
                                 strata, stream, branch, t, s, w)
        values.append(w[:count][branch[:count] == layout.REFLECTED].sum() / walks)
    return float(np.std(values, ddof=1))


def test_refined_cells_have_the_levels_probabilities():
    """refined_bin (kernel) and edge_levels (builder) describe the same cells: a fine uniform
    grid of draws falls into each cell in proportion to its probability, and the position
    within the cell maps the draw linearly onto the cell's level interval."""
    for n in (layout.POLAR_BINS, layout.AZIMUTH_BINS):
        levels = surface_table.edge_levels(n)
        assert levels.size == n + 2 * layout.TAIL_SPLITS + 1
        assert np.all(np.diff(levels) > 0.0) and levels[0] == 0.0 and levels[-1] == 1.0
        v = (np.arange(200_000) + 0.5) / 200_000
        cells = np.array([layout.refined_bin(x, n) for x in v])
        cell = cells[:, 0].astype(int)
        assert np.allclose(levels[cell] + cells[:, 1] * np.diff(levels)[cell], v, atol=1e-12)


def test_energy_closure_and_directions(seven):
    """Every draw from both sides at 0 to 89.9 deg leaves with weight 1 on exactly one side,
    heading away from the surface, a unit vector; the table's R is in [0, 1] at every node,
    so reflected + transmitted = incident."""
    surface, table = seven
    r = table[:layout.REFLECTANCES]
    assert np.all((r >= 0.0) & (r <= 1.0))
    for k, theta in enumerate(ANGLES + (89.9,)):
        for from_air in (True, False):
            ux, uy, uz = incident(theta, from_air)
            out = draws(surface, table, ux, uy, uz, 20_000, batch_state(21, k), True)
            assert np.all(out[:, 3] == 1.0)
            transmitted = out[:, 4] == 1.0
            assert np.all(out[transmitted, 2] * uz > 0.0)
            assert np.all(out[~transmitted, 2] * uz < 0.0)
            assert np.allclose(np.sum(out[:, :3] ** 2, axis=1), 1.0, atol=1e-12)


@pytest.mark.parametrize("from_air", [True, False])
def test_reflectance_per_angle_matches_the_walk(seven, from_air):
    """R of the table at each incidence against the walk's fraction reflected in 200,000 walks:
    |z| < 4, the standard error the walk's binomial one and the table's own (the spread of R
    over 8 tables' worth of walks, table_reflectance_stderr). From the water this covers total
    internal reflection (47-85 deg)."""
    surface, table = seven
    alpha = float(surface["alpha_u"])
    n = 200_000
    for k, theta in enumerate(ANGLES):
        ux, uy, uz = incident(theta, from_air)
        out = draws(surface, table, ux, uy, uz, n, batch_state(22, k), False)
        r_walk = 1.0 - out[:, 4].mean()
        r_table = table_reflectance(table, theta, from_air)
        se = math.hypot(math.sqrt(max(r_walk * (1.0 - r_walk), 1.0 / n) / n),
                        table_reflectance_stderr(alpha, theta, from_air, 23 + k))
        assert abs(r_table - r_walk) / se < 4.0, (theta, r_table, r_walk, se)


def leaving_coordinates(out, uz):
    """(branch, cosine, azimuth from the incident plane in [0, pi]) of draws (incidence in the
    x-z plane)."""
    return out[:, 4], np.abs(out[:, 2]), np.abs(np.arctan2(out[:, 1], out[:, 0]))


@pytest.mark.parametrize("from_air", [True, False])
def test_leaving_directions_match_the_walk(seven, from_air):
    """At each incidence, per branch, the mean leaving cosine and the mean cosine of the
    relative azimuth of 100,000 table draws against 100,000 walks (|z| < 4; standard error:
    the two samples' and the table's own, that of WALKS_PER_NODE walks), and a binned
    chi-square over (branch, 5-deg polar bands, 30-deg azimuth sectors) below dof + 4
    sqrt(2 dof), each bin's variance n p (2 + n / WALKS_PER_NODE) for the table's noise."""
    surface, table = seven
    n = 100_000
    inflation = 1.0 + 0.5 * n / surface_table.WALKS_PER_NODE
    for k, theta in enumerate(ANGLES):
        ux, uy, uz = incident(theta, from_air)
        tab = leaving_coordinates(draws(surface, table, ux, uy, uz, n, batch_state(24, k),
                                        True), uz)
        ref = leaving_coordinates(draws(surface, table, ux, uy, uz, n, batch_state(25, k),
                                        False), uz)
        for branch in (0.0, 1.0):
            a, b = tab[0] == branch, ref[0] == branch
            if b.sum() < 100:
                continue
            for x, y in ((tab[1][a], ref[1][b]), (np.cos(tab[2][a]), np.cos(ref[2][b]))):
                se = math.sqrt(x.var() / x.size + y.var() / y.size
                               + y.var() / (surface_table.WALKS_PER_NODE * b.mean()))
                assert abs(x.mean() - y.mean()) / se < 4.0, (theta, branch, x.mean(), y.mean())
        bins = [[-0.5, 0.5, 1.5], np.cos(np.radians(np.arange(90.0, -1.0, -5.0))),
                np.radians(np.arange(0.0, 181.0, 30.0))]
        h_tab = np.histogramdd(np.c_[tab], bins=bins)[0].ravel()
        h_ref = np.histogramdd(np.c_[ref], bins=bins)[0].ravel()
        used = h_tab + h_ref > 20
        chi2 = float(((h_tab - h_ref)[used] ** 2 / (h_tab + h_ref)[used]).sum()) / inflation
        dof = int(used.sum())
        assert chi2 < dof + 4.0 * math.sqrt(2.0 * dof), (theta, chi2, dof)


@numba.njit
def steep_transmissions(surface, floats, from_air, t_max, cut_cos, n, rng, tabulated):
    """Of n photons meeting the surface at incidences uniform in t = sqrt(1 - mu) on [0,
    t_max] (azimuth 0), how many are transmitted steeper than the cut (|oz| < cut_cos)."""
    hits = 0
    sign = 1.0 if from_air else -1.0
    for _ in range(n):
        t = t_max * uniform(rng)
        mu = 1.0 - t * t
        s = math.sqrt(1.0 - mu * mu)
        if tabulated:
            ox, oy, oz, w, transmitted = dispatch.sample(surface, s, 0.0, sign * mu,
                                                         uniform(rng), rng, floats)
        else:
            ox, oy, oz, w, transmitted = dispatch.sample(surface, s, 0.0, sign * mu,
                                                         uniform(rng), rng)
        if transmitted and abs(oz) < cut_cos:
            hits += 1
    return hits


@pytest.mark.parametrize("from_air, t_max, cut", [(True, 0.5, 35.0), (True, 1.0, 55.0),
                                                  (False, 0.5, 75.0), (False, 0.4, 60.0)])
def test_the_tails_stay_where_the_walk_puts_them(seven, from_air, t_max, cut):
    """The light transmitted steeper than a cut angle (by steep facets or several: 4e-4 to
    0.04 of it here), incidences spread over t in [0, t_max] (25 to 63 nodes), 2,000,000
    table draws against as many walks: |z| < 4, the variance the two counts' plus the table's
    own (a tail share p estimated from WALKS_PER_NODE walks at each node spanned: n^2 p /
    (WALKS_PER_NODE nodes)). Tail cells split only down to 2^-5 of their share (instead of
    2^-9) smear up to 5e-4 of the light out to each node's farthest walk; that layout,
    emulated on this table, gives z = 4.1 in the first case (the table itself 1.6). Tails
    rarer than about 1 / WALKS_PER_NODE at one incidence are beyond the table's resolution."""
    surface, table = seven
    n = 2_000_000
    cut_cos = math.cos(math.radians(cut))
    tab, ref = (steep_transmissions(surface, table, from_air, t_max, cut_cos, n,
                                    batch_state(29, seed), tabulated)
                for seed, tabulated in ((1, True), (2, False)))
    nodes = t_max * (layout.NODES - 1)
    se = math.sqrt(tab + ref + n * ref / (surface_table.WALKS_PER_NODE * nodes))
    assert abs(tab - ref) / se < 4.0, (tab, ref, se)


@pytest.mark.parametrize("from_air", [True, False])
def test_the_table_is_reciprocal(seven, from_air):
    """The tabulated BSDF keeps the walk's reciprocity (Heitz et al. 2016, 5.3; Veach 1997,
    5.2): P(A->B) C_A / n_B^2 = P(B->A) C_B / n_A^2 for reflection (n_A = n_B) and
    transmission, estimated from 400,000 draws per direction (C the cells' projected solid
    angles), |z| < 4. Cells of 15 x 20 deg and more: each spans several incidence nodes."""
    surface, table = seven
    d = math.radians
    a = (d(15.0), d(30.0), d(0.0), d(20.0))
    n = 400_000
    for k, (b_cell, transmit) in enumerate((((d(25.0), d(45.0), d(170.0), d(200.0)), False),
                                            ((d(10.0), d(25.0), d(170.0), d(200.0)), True))):
        n_a, n_b = (1.0, N_WATER) if from_air else (N_WATER, 1.0)
        if not transmit:
            n_b = n_a
        b_out = tuple(-x for x in b_cell) if transmit else b_cell
        a_back = tuple(-x for x in a) if transmit else a
        p_ab = cell_transfer(surface, table, from_air, a, b_out, n, batch_state(26, k)) / n
        p_ba = cell_transfer(surface, table, from_air != transmit, b_cell, a_back, n,
                             batch_state(27, k)) / n
        lhs, rhs = p_ab * projected(a) / n_b ** 2, p_ba * projected(b_cell) / n_a ** 2
        se = math.hypot(math.sqrt(p_ab / n) * projected(a) / n_b ** 2,
                        math.sqrt(p_ba / n) * projected(b_cell) / n_a ** 2)
        assert p_ab > 1e-3 and abs(lhs - rhs) / se < 4.0, (transmit, lhs, rhs)


@pytest.fixture
def small_tables(tmp_path, monkeypatch):
    """Tables of 500 walks a node in a cache folder of their own (fast to build)."""
    monkeypatch.setattr(surface_table, "TABLE_DIR", tmp_path / "surface_tables")
    monkeypatch.setattr(surface_table, "WALKS_PER_NODE", 500)
    return tmp_path / "surface_tables"


def test_the_cache_keeps_a_table_and_rebuilds_a_bad_one(small_tables, monkeypatch):
    """The first call builds and writes the table (one file, no temporary left); the second
    reads it without building; a corrupt or truncated file, or one of another size, is built
    again and replaced, never an error; the key tells slopes and n_water apart."""
    alpha = 0.2
    first = surface_table.table(alpha, N_WATER)
    files = sorted(small_tables.iterdir())
    assert [f.suffix for f in files] == [".npy"]
    built = surface_table.build

    def refuse(*args, **kwargs):
        raise AssertionError("built although cached")
    monkeypatch.setattr(surface_table, "build", refuse)
    assert np.array_equal(surface_table.table(alpha, N_WATER), first)
    monkeypatch.setattr(surface_table, "build", built)
    for bad in (b"not a numpy file", files[0].read_bytes()[:1000],
                lambda: np.save(files[0], np.zeros(10))):
        if callable(bad):
            bad()
        else:
            files[0].write_bytes(bad)
        assert np.array_equal(surface_table.table(alpha, N_WATER), first)
        assert np.array_equal(np.load(files[0]), first)
    assert sorted(small_tables.iterdir()) == files
    assert surface_table.cache_path(alpha, 1.33) != files[0]
    assert surface_table.cache_path(0.21, N_WATER) != files[0]


def test_a_table_is_the_same_whatever_the_threads(small_tables):
    """Each node has its own stream: 1 and 2 threads give the same table, bit for bit."""
    assert np.array_equal(surface_table.build(0.2, N_WATER, threads=1),
                          surface_table.build(0.2, N_WATER, threads=2))


@pytest.mark.parametrize("surface, tabulated", [
    ({"wind_speed_m_s": 7.0}, True),
    ({"wind_speed_m_s": 0.0}, True),
    ({"wind_speed_m_s": 7.0, "method": "walk"}, False),
    ({"wind_speed_m_s": 7.0, "wind_direction_deg": 30.0}, False),
    ({"mean_square_slope": 1e-4}, False),
    ({"mean_square_slope": 1e-4, "method": "table"}, True),
])
def test_the_default_method(surface, tabulated):
    """table by default; the walk with a wind direction (anisotropic slopes) or a mean square
    slope below the calm sea's 0.003 (sharper than the table's nodes), or when asked."""
    config = cfg.Surface(model="cox_munk", **surface)
    assert config.tabulated() == tabulated
    assert surface_packer.pack(config, N_WATER)[0]["tabulated"] == int(tabulated)


@pytest.mark.parametrize("surface, message", [
    ({"model": "cox_munk", "wind_speed_m_s": 7, "wind_direction_deg": 30, "method": "table"},
     "the table is of isotropic slopes"),
    ({"model": "flat", "method": "walk"}, "belong to surface.model = 'cox_munk'"),
    ({"model": "cox_munk", "wind_speed_m_s": 7, "method": "exact"}, "surface.method"),
])
def test_bad_method_is_one_line(surface, message):
    with pytest.raises(ConfigError) as err:
        oceanmc.load_config({"surface": surface, "water": {"layers": [
            {"thickness_m": 1.0, "a": 0.1, "b": 0.1}]}, "bottom": {"model": "black"}})
    text = str(err.value)
    assert message in text and "\n" not in text


def z_scores(a, b):
    """{quantity: z of table run a against walk run b, elementwise} for every output both runs
    have with finite, non-zero standard errors."""
    out = {}
    for name in a.quantities:
        if name not in b.quantities:
            continue
        se = np.hypot(a.stderr(name), b.stderr(name))
        diff = np.asarray(a[name] - b[name], dtype=float)
        ok = np.isfinite(se) & (se > 0.0) & np.isfinite(diff)
        if ok.any():
            out[name] = diff[ok] / se[ok]
    return out


@pytest.mark.parametrize("wavelengths", [[550.0], [440.0, 550.0, 670.0]])
def test_whole_scenes_agree_with_the_walk(wavelengths):
    """configs/windy_case1.yaml (7 m/s, sun 32 deg, Harrison-Coombes sky, Case-1 water, local
    estimates, upward bias) at one and at three wavelengths, 200,000 photons in 32 batches,
    surface.method table against walk, z over the two runs' batch standard errors (about 2,200
    outputs at one wavelength): every irradiance, Rrs, local estimate and budget term within
    |z| < 4; the radiance quads (hundreds per level, so a bound of 4 would fail by chance:
    two walk runs of different seeds reach 4.1 here) within 4.5; over all outputs the mean z^2
    below 1.25 (measured between runs of the same method: 1.01-1.10, above 1 for the 32
    batches' t distribution and quads that few photons reach)."""
    from oceanmc.run.simulation import simulate
    base = oceanmc.load_config("configs/windy_case1.yaml").model_dump()
    base.update(photons=200_000, batches=32, wavelengths_nm=wavelengths)
    runs = {}
    for method in ("table", "walk"):
        base["surface"]["method"] = method
        runs[method] = simulate(oceanmc.load_config(base), threads=2)
    z = z_scores(runs["table"], runs["walk"])
    assert {"air/Rrs_nadir", "air/Rrs_local", "Ed", "Eu", "radiance", "air/radiance"} <= set(z)
    for name, values in z.items():
        bound = 4.5 if values.size > 100 else 4.0
        assert np.abs(values).max() < bound, (name, np.abs(values).max())
    every = np.concatenate(list(z.values()))
    assert (every ** 2).mean() < 1.25, (every.size, (every ** 2).mean())
