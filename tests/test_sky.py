"""Sky radiance: maps from files, the Harrison & Coombes (1988) clear sky, the overcast alias.

The sampler draws sky photon directions with probability proportional to L cos dOmega (rows from
the marginal CDF, cells from the conditional CDF): chi-square of the drawn cells against
L (sin^2 theta_hi - sin^2 theta_lo) dphi / 2 computed here (Bonferroni over the tests), the
view -> travel convention (phi_travel = phi_view + 180 deg) on a one-cell map, and Harrison-
Coombes' weighted histogram against an independent quadrature of its formula. A map with
`sampling: cosine`: cells drawn in proportion to their cos dOmega (chi-square), each photon
weighted by exactly L(the cell it comes from, found here from its direction) pi / E, weights
averaging to 1. Through the engine: a uniform map, importance- or cosine-sampled, reproduces
`sky: uniform` (fluxes and radiances within standard errors); a map with a bright spot gives
the same tallies under both samplings; Harrison-Coombes gives the surface reflectance and the
sky radiance quads of the formula. Bad files give one ConfigError naming the file and the
problem.

OpenEXR sky images (.exr): the reader returns exactly the channel Y, or the Rec. 709 luminance
0.2126 R + 0.7152 G + 0.0722 B, or the channel named as `dataset`, oriented as a .npy map (row 0
= zenith, column 0 = phi_view 0), the upper half of a full-sphere (2:1) image; the same map as
.exr and as .npy gives bit-identical sampling tables; bad images give one error naming the file,
also on the command line (one line, exit 2).
"""
import math
import os
import subprocess
import sys

import h5py
import numpy as np
import OpenEXR
import pytest

import oceanmc
from oceanmc import scene
from oceanmc.scene import sky as sky_packer
from oceanmc.scene import sky_maps
from oceanmc.config import ConfigError, load_config
from oceanmc.kernel.rng import batch_state
from oceanmc.kernel.sources import sky_many

from conftest import REPO
from stats_helpers import (assert_chi2, assert_same, assert_z, batch_mean_se, fresnel_reference,
                           sample_mean_se)

N = 1.34
N_CHI2 = 6          # chi-square tests in this file (Bonferroni)


def base(sky, **over):
    config = {"photons": 2000, "batches": 4, "seed": 1,
              "illumination": {"Ed0": 1.0, "sun_zenith_deg": 40.0, "diffuse_fraction": 1.0,
                               "sky": sky},
              "surface": {"model": "flat", "n_water": N},
              "water": {"layers": [{"thickness_m": 1.0, "a": 0.0, "b": 0.0}]},
              "bottom": {"model": "black"},
              "tallies": {"depths_m": [0.0], "nadir_estimator": "crossing"}}
    config.update(over)
    return config


def draw(sky, n, seed=1, **over):
    sc = scene.build(load_config(base(sky, **over)))
    return sky_many(sc.sky, sc.floats, n, batch_state(seed, 0))


def view_angles(u):
    """(theta_view, phi_view in [0, 360)) in deg of the sky element a photon comes from."""
    theta = np.degrees(np.arccos(np.clip(u[:, 2], -1.0, 1.0)))
    phi = np.mod(np.degrees(np.arctan2(-u[:, 1], -u[:, 0])), 360.0)
    return theta, phi


def cell_mass(theta_edges, phi_edges, L):
    """L x integral of cos dOmega over each cell, normalised."""
    s = np.sin(np.radians(theta_edges)) ** 2
    m = L * np.diff(s)[:, None] * np.radians(np.diff(phi_edges))[None, :] / 2.0
    return m / m.sum()


# --- the sampler ------------------------------------------------------------------------------

def uneven_map(tmp_path, sampling):
    """An HDF5 map with uneven rows, columns starting at phi_view = -180 deg, dark cells, a dark
    row and one bright cell; returns (its sky config, theta_edges, phi_edges, L)."""
    theta_e = np.array([0.0, 10.0, 25.0, 35.0, 50.0, 60.0, 70.0, 80.0, 86.0, 90.0])
    phi_e = np.linspace(-180.0, 180.0, 25)
    L = np.random.default_rng(4).uniform(0.2, 3.0, size=(9, 24))
    L[3, 5:9] = 0.0
    L[7, :] = 0.0
    L[2, 12] = 40.0
    path = tmp_path / "sky.h5"
    with h5py.File(path, "w") as h5:
        h5["radiance"] = L
        h5["theta_edges_deg"] = theta_e
        h5["phi_edges_deg"] = phi_e
    return {"map": str(path), "sampling": sampling}, theta_e, phi_e, L


def test_map_sampling(tmp_path):
    """A map with structure, zeros and uneven cells (HDF5 with edges): the drawn cells follow
    L cos dOmega; weight factors are 1; directions travel downward."""
    sky, theta_e, phi_e, L = uneven_map(tmp_path, "importance")
    n = 300_000
    u = draw(sky, n)
    assert np.all(u[:, 3] == 1.0)
    assert np.all(u[:, 2] > 0.0)
    np.testing.assert_allclose(np.linalg.norm(u[:, :3], axis=1), 1.0, atol=1e-12)
    t, p = view_angles(u)
    p = np.where(p >= 180.0, p - 360.0, p)
    counts = np.histogram2d(t, p, bins=[theta_e, phi_e])[0]
    probs = cell_mass(theta_e, phi_e, L)
    assert_chi2(counts, probs, rel_cap=None, p_min=1e-3 / N_CHI2, what="map cells")
    assert_chi2(counts.sum(axis=1), probs.sum(axis=1), p_min=1e-3 / N_CHI2,
                what="map rows (theta marginal)")
    assert_chi2(counts.sum(axis=0), probs.sum(axis=0), p_min=1e-3 / N_CHI2, min_cap_count=5000,
                what="map columns (phi marginal)")


def test_view_to_travel_convention(tmp_path):
    """One bright cell seen at theta_view 30-34 deg, phi_view 176-184 deg (towards the sun, whose
    rays travel at phi = 0): every sky photon travels at theta 30-34 deg from nadir with phi
    within 4 deg of 0, i.e. along with the sun's rays."""
    L = np.zeros((45, 90))
    L[15:17, 44:46] = 1.0               # rows 2 deg, columns 4 deg
    np.save(tmp_path / "spot.npy", L)
    u = draw({"map": str(tmp_path / "spot.npy")}, 20_000)
    theta = np.degrees(np.arccos(u[:, 2]))
    phi = np.degrees(np.arctan2(u[:, 1], u[:, 0]))
    assert theta.min() >= 30.0 - 1e-9 and theta.max() <= 34.0 + 1e-9
    assert np.abs(phi).max() <= 4.0 + 1e-9
    assert np.mean(phi > 0) == pytest.approx(0.5, abs=0.02)


def test_cosine_map_sampling(tmp_path):
    """sampling: cosine draws directions with density cos / pi whatever L (the cells' counts
    follow their cos dOmega, dark cells included), and weights each photon by L(cell) pi / E:
    the packed weights are L pi / E with E summed here in degrees, every photon's weight is that
    of the cell its own direction points to (view convention: phi_view = phi_travel + 180 deg),
    and the weights average to 1 (exactly over the cell probabilities, within the standard
    error over the draws)."""
    sky, theta_e, phi_e, L = uneven_map(tmp_path, "cosine")
    sc = scene.build(load_config(base(sky)))
    solid_cos = cell_mass(theta_e, phi_e, np.ones_like(L))
    energy = np.sum(L * np.diff(np.sin(np.radians(theta_e)) ** 2)[:, None]
                    * np.radians(np.diff(phi_e))[None, :] / 2.0)
    expected_weight = L * math.pi / energy
    rec = sc.sky[0]
    cell_l = sc.floats[rec["cell_l"]:rec["cell_l"] + L.size].reshape(L.shape)
    np.testing.assert_allclose(cell_l, expected_weight, rtol=1e-12)
    assert np.sum(solid_cos * expected_weight) == pytest.approx(1.0, rel=1e-12)
    n = 300_000
    u = sky_many(sc.sky, sc.floats, n, batch_state(2, 0))
    assert np.all(u[:, 2] > 0.0)
    np.testing.assert_allclose(np.linalg.norm(u[:, :3], axis=1), 1.0, atol=1e-12)
    t, p = view_angles(u)
    p = np.where(p >= 180.0, p - 360.0, p)
    counts = np.histogram2d(t, p, bins=[theta_e, phi_e])[0]
    assert_chi2(counts, solid_cos, rel_cap=None, p_min=1e-3 / N_CHI2, what="cosine cells")
    assert_chi2(counts.sum(axis=1), solid_cos.sum(axis=1), p_min=1e-3 / N_CHI2,
                what="cosine rows (theta marginal)")
    assert_chi2(counts.sum(axis=0), solid_cos.sum(axis=0), p_min=1e-3 / N_CHI2,
                min_cap_count=5000, what="cosine columns (phi marginal)")
    row = np.searchsorted(theta_e, t, side="right") - 1
    col = np.searchsorted(phi_e, p, side="right") - 1
    # directions within 1e-7 deg of a cell edge may round to either side when converted here
    clear = ((np.min(np.abs(t[:, None] - theta_e[None, :]), axis=1) > 1e-7)
             & (np.min(np.abs(p[:, None] - phi_e[None, :]), axis=1) > 1e-7))
    assert clear.mean() > 0.999
    np.testing.assert_allclose(u[clear, 3], expected_weight[row[clear], col[clear]], rtol=1e-12)
    mean, se = sample_mean_se(u[:, 3])
    assert_z(mean, 1.0, se, rel_max=0.01, what="cosine-sampled mean weight")


def hc_radiance(u, sun_zenith_deg):
    """Harrison & Coombes (1988) Eqs. 3-5 for travel directions u (rows), written here."""
    s = math.radians(sun_zenith_deg)
    cos_psi = np.clip(u[..., 0] * math.sin(s) + u[..., 2] * math.cos(s), -1.0, 1.0)
    psi = np.arccos(cos_psi)
    return ((1.63 + 53.7 * np.exp(-5.49 * psi) + 2.04 * cos_psi ** 2 * math.cos(s))
            * (1.0 - np.exp(-0.19 / u[..., 2])) * (1.0 - math.exp(-0.53 / math.cos(s))))


def travel_rule(theta_lo, theta_hi, phi_lo, phi_hi, nt=64, nphi=64):
    """Gauss rule over travel directions in a (theta, phi) box (deg): directions and weights
    of dOmega."""
    x, w = np.polynomial.legendre.leggauss(nt)
    mu_a, mu_b = math.cos(math.radians(theta_hi)), math.cos(math.radians(theta_lo))
    mu = mu_a + (mu_b - mu_a) * (x + 1) / 2
    wm = w * (mu_b - mu_a) / 2
    y, v = np.polynomial.legendre.leggauss(nphi)
    ph = math.radians(phi_lo) + math.radians(phi_hi - phi_lo) * (y + 1) / 2
    wp = v * math.radians(phi_hi - phi_lo) / 2
    M, P = np.meshgrid(mu, ph, indexing="ij")
    u = np.stack([np.sqrt(1 - M ** 2) * np.cos(P), np.sqrt(1 - M ** 2) * np.sin(P), M], -1)
    return u, np.outer(wm, wp)


def hc_cos_integral(sun, theta_lo, theta_hi, phi_lo, phi_hi, weight=lambda mu: 1.0, split=4):
    """Integral of L cos (x weight(cos)) dOmega over a travel-direction box, with the box split
    so the circumsolar cusp (phi = 0, theta = sun) falls on sub-box edges."""
    ts = np.linspace(theta_lo, theta_hi, split + 1)
    ps = np.linspace(phi_lo, phi_hi, split + 1)
    if theta_lo < sun < theta_hi:
        ts = np.unique(np.append(ts, sun))
    if phi_lo < 0.0 < phi_hi:
        ps = np.unique(np.append(ps, 0.0))
    total = 0.0
    for a, b in zip(ts[:-1], ts[1:]):
        for c, d in zip(ps[:-1], ps[1:]):
            u, w = travel_rule(a, b, c, d)
            total += np.sum(w * hc_radiance(u, sun) * u[..., 2] * weight(u[..., 2]))
    return total


def test_harrison_coombes_sampling():
    """Weighted directions (weight factor L / L_cell) against the integral of L cos over coarse
    bins of the formula; E[factor] = 1 (the proposal's normalisation, from its 8 x 8 Gauss cell
    averages, is exact to the sampling precision)."""
    sun = 40.0
    n = 400_000
    u = draw("harrison_coombes", n, seed=3, illumination={
        "Ed0": 1.0, "sun_zenith_deg": sun, "diffuse_fraction": 1.0, "sky": "harrison_coombes"})
    m = u[:, 3]
    mean, se = m.mean(), m.std(ddof=1) / math.sqrt(n)
    assert_z(mean, 1.0, se, rel_max=1e-3, what="Harrison-Coombes mean weight factor")
    t_e = np.arange(0.0, 90.1, 10.0)
    p_e = np.arange(-180.0, 180.1, 30.0)
    theta = np.degrees(np.arccos(u[:, 2]))
    phi = np.degrees(np.arctan2(u[:, 1], u[:, 0]))
    est = np.histogram2d(theta, phi, bins=[t_e, p_e], weights=m)[0] / n
    est_sq = np.histogram2d(theta, phi, bins=[t_e, p_e], weights=m * m)[0] / n
    est_se = np.sqrt(np.maximum(est_sq - est ** 2, 0.0) / n)
    total = hc_cos_integral(sun, 0.0, 90.0, -180.0, 180.0, split=12)
    ref = np.array([[hc_cos_integral(sun, a, b, c, d, split=2) for c, d in zip(p_e[:-1],
                                                                                p_e[1:])]
                    for a, b in zip(t_e[:-1], t_e[1:])]) / total
    # the cap guards against a gross error: the dimmest bins (near the horizon) have a 4.6%
    # standard error, so 0.15 is 3.3 of those (seeds 3-8: max |z| 2.4-3.4, z mean 0, sd 1)
    z = assert_z(est, ref, est_se, rel_max=0.15, what="Harrison-Coombes weighted bins")
    # the brightest bin per solid angle is beside the sun (phi of travel -30..30 deg)
    per_sr = ref / -np.diff(np.cos(np.radians(t_e)))[:, None]
    assert np.unravel_index(np.argmax(per_sr), ref.shape)[1] in (5, 6)
    print(f"Harrison-Coombes: E[factor] = {mean:.5f} +- {se:.1e}; weighted bins max |z| "
          f"{np.max(np.abs(z)):.2f}; factor spread {m.std() / mean:.3f}")


def test_harrison_coombes_cell_quadrature():
    """The proposal's cell averages (8 x 8 Gauss per 1 x 2 deg cell) integrate L cos to 1e-6 of
    the finely split quadrature above (what makes E[factor] = 1)."""
    theta, phi, L = sky_maps.harrison_coombes_cells(40.0)
    s = np.sin(np.radians(theta)) ** 2
    table = np.sum(L * np.diff(s)[:, None] * np.radians(np.diff(phi))[None, :] / 2.0)
    fine = hc_cos_integral(40.0, 0.0, 90.0, -180.0, 180.0, split=12)
    assert table == pytest.approx(fine, rel=1e-6)


# --- the whole engine -------------------------------------------------------------------------

def engine_scene(sky, seed, photons=300_000):
    return base(sky, photons=photons, batches=20, seed=seed,
                water={"layers": [{"thickness_m": 1.0, "a": 0.05, "b": 0.2,
                                   "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
                bottom={"model": "lambertian", "reflectance": 0.3},
                tallies={"depths_m": [0.0, 1.0], "nadir_estimator": "crossing"})


def compare(a, b, names, what):
    """Every named quantity of two independent runs agrees within their standard errors
    (Bonferroni over all compared values); returns the largest |z|."""
    parts = [[], [], [], []]
    for name in names:
        ma, sa = batch_mean_se(a.quantities[name].batches)
        mb, sb = batch_mean_se(b.quantities[name].batches)
        for k, v in enumerate((ma, sa, mb, sb)):
            parts[k].append(np.atleast_1d(v).ravel())
    ma, sa, mb, sb = (np.concatenate(p) for p in parts)
    keep = (sa > 0) | (sb > 0)
    z = assert_same(mb[keep], sb[keep], ma[keep], sa[keep], dof=19, what=what)
    return float(np.max(np.abs(z)))


def fresnel_air_water(mu):
    """Unpolarized Fresnel reflectance from air into water at incidence cosines mu (array),
    checked against stats_helpers.fresnel_reference below."""
    mu = np.clip(mu, 1e-12, 1.0)
    ct = np.sqrt(1.0 - (1.0 - mu ** 2) / N ** 2)
    rs = (mu - N * ct) / (mu + N * ct)
    rp = (ct - N * mu) / (ct + N * mu)
    return 0.5 * (rs ** 2 + rp ** 2)


@pytest.mark.parametrize("sampling", ["importance", "cosine"])
def test_uniform_map_reproduces_uniform_sky(tmp_path, sampling):
    """A uniform map reproduces `sky: uniform`, importance-sampled (weights 1) or cosine-sampled
    (weights L pi / E = 1 to rounding)."""
    np.save(tmp_path / "uniform.npy", np.full((18, 36), 2.5))
    sky = {"map": str(tmp_path / "uniform.npy"), "sampling": sampling}
    weights = draw(sky, 10_000)[:, 3]
    np.testing.assert_allclose(weights, 1.0, rtol=1e-12)
    a = oceanmc.simulate(engine_scene("uniform", seed=1), threads=2)
    b = oceanmc.simulate(engine_scene(sky, seed=2), threads=2)
    names = ["Ed", "Eu", "Eod", "Eou", "budget/surface_reflection", "budget/water_leaving",
             "air/Eu"]
    worst = compare(a, b, names, "uniform map vs uniform")
    for name in ("Ed", "Eu", "budget/surface_reflection"):
        np.testing.assert_allclose(b[name], a[name], rtol=0.01)
    # radiance quads just above and below the surface (caps once)
    ra, sa = batch_mean_se(a.quantities["air/radiance"].batches)
    rb, sb = batch_mean_se(b.quantities["air/radiance"].batches)
    keep = np.ones(ra.shape, dtype=bool)
    keep[0, 1:] = keep[-1, 1:] = False
    z = assert_same(rb[keep], sb[keep], ra[keep], sa[keep], dof=19, what="air radiance quads")
    print(f"uniform map ({sampling}) vs uniform sky: max |z| "
          f"{max(worst, float(np.max(np.abs(z)))):.2f}")


def test_cosine_sampling_matches_importance(tmp_path):
    """A map with a bright spot (30x the background over 6 x 12 deg at zenith 38-44 deg,
    phi_view 144-156 deg: off the sun's plane, so a wrong azimuth convention would move it)
    gives the same tallies sampled cosine-weighted as importance-sampled: Ed, Eu, Eod, Eou at
    0- and 1 m, air Eu, the budget, and every radiance quad just above and just below the
    surface (caps once), within the Bonferroni bound of |z| over all compared values (dof 19),
    and Ed, Eu within 1% (the cosine run's relative standard errors there are ~0.2%)."""
    L = np.ones((45, 90))
    L[19:22, 36:39] = 30.0
    np.save(tmp_path / "spot.npy", L)
    runs = {sampling: oceanmc.simulate(engine_scene({"map": str(tmp_path / "spot.npy"),
                                                     "sampling": sampling},
                                                    seed=seed, photons=1_000_000), threads=2)
            for sampling, seed in (("importance", 3), ("cosine", 4))}
    a, b = runs["importance"], runs["cosine"]
    names = ["Ed", "Eu", "Eod", "Eou", "budget/surface_reflection", "budget/water_leaving",
             "air/Eu"]
    worst = compare(a, b, names, "cosine vs importance")
    for name in ("Ed", "Eu"):
        np.testing.assert_allclose(b[name], a[name], rtol=0.01)
    zs = []
    for name, level in (("air/radiance", ()), ("radiance", (0,))):
        ra, sa = batch_mean_se(a.quantities[name].batches)
        rb, sb = batch_mean_se(b.quantities[name].batches)
        ra, sa, rb, sb = ra[level], sa[level], rb[level], sb[level]
        keep = np.ones(ra.shape, dtype=bool)
        keep[0, 1:] = keep[-1, 1:] = False
        zs.append(assert_same(rb[keep], sb[keep], ra[keep], sa[keep], dof=19,
                              what=f"{name} quads, cosine vs importance"))
    # the spot's quads (sky at 0+: travel theta 35-45 deg, phi_travel = 324..336 deg, in the
    # bands centred on 330 and 345) are ~10x the background's: the comparison has power there
    spot = a["air/radiance"][4, 22]
    assert spot > 5.0 * a["air/radiance"][4, 6]
    assert b["air/radiance"][4, 22] == pytest.approx(spot, rel=0.1)
    print(f"cosine vs importance: max |z| "
          f"{max([worst] + [float(np.max(np.abs(z))) for z in zs]):.2f}")


def test_overcast_is_cardioidal():
    a = oceanmc.simulate(base("overcast", photons=4000), threads=1)
    b = oceanmc.simulate(base("cardioidal", photons=4000), threads=1)
    np.testing.assert_array_equal(a.quantities["air/radiance"].batches,
                                  b.quantities["air/radiance"].batches)


def test_harrison_coombes_engine():
    """Clear water over black: the surface reflects int L cos R dOmega / int L cos dOmega of the
    Harrison-Coombes sky (independent Fresnel and quadrature), and the downward sky quads at 0+
    read its quad-averaged radiance, scaled to Ed0."""
    sun = 40.0
    r = oceanmc.simulate(base("harrison_coombes", photons=400_000, batches=20, seed=5),
                         threads=2)
    total = hc_cos_integral(sun, 0.0, 90.0, -180.0, 180.0, split=12)
    for t in (0.1, 30.0, 60.0, 85.0):
        assert fresnel_air_water(np.array(math.cos(math.radians(t)))) == pytest.approx(
            fresnel_reference(1.0, N, math.radians(t)), rel=1e-12)
    refl = hc_cos_integral(sun, 0.0, 90.0, -180.0, 180.0, split=12,
                           weight=fresnel_air_water) / total
    assert_z(r["budget/surface_reflection"], refl, r.stderr("budget/surface_reflection"),
             rel_max=0.01, dof=19, what="Harrison-Coombes surface reflectance")
    edges = r.coords["theta_edges"]
    phi_e = r.coords["phi_edges"]
    est, se = batch_mean_se(r.quantities["air/radiance"].batches)
    ref, use = np.zeros(est.shape), np.zeros(est.shape, dtype=bool)
    for i in range(1, 9):                       # downward bands 5..85 deg (not the cap, horizon)
        for j in range(len(phi_e) - 1):
            u, w = travel_rule(edges[i], edges[i + 1], phi_e[j], phi_e[j + 1], 24, 24)
            ref[i, j] = np.sum(w * hc_radiance(u, sun)) / np.sum(w) / total
            use[i, j] = True
    z = assert_z(est[use], ref[use], se[use], dof=19, rel_max=0.12,
                 what="Harrison-Coombes sky quads at 0+")
    print(f"Harrison-Coombes: reflectance {r['budget/surface_reflection']:.5f} +- "
          f"{r.stderr('budget/surface_reflection'):.1e} vs {refl:.5f}; quads max |z| "
          f"{np.max(np.abs(z)):.2f}")


# --- configuration and bad files --------------------------------------------------------------

def sky_error(path, **kw):
    with pytest.raises(ConfigError) as err:
        scene.build(load_config(base(dict({"map": str(path)}, **kw))))
    return str(err.value)


def test_bad_sky_files(tmp_path):
    np.save(tmp_path / "vector.npy", np.ones(10))
    np.save(tmp_path / "cube.npy", np.ones((3, 4, 5)))
    np.save(tmp_path / "neg.npy", -np.ones((3, 4)))
    np.save(tmp_path / "nan.npy", np.full((3, 4), np.nan))
    np.save(tmp_path / "dark.npy", np.zeros((3, 4)))
    np.save(tmp_path / "nothing.npy", np.ones((0, 4)))
    (tmp_path / "empty.npy").write_bytes(b"")
    (tmp_path / "junk.npy").write_bytes(b"not a numpy file at all")
    (tmp_path / "sky.png").write_bytes(b"png")
    np.savez(tmp_path / "mono.npz", radiance=np.ones((3, 4)),
             theta_edges_deg=np.array([0.0, 40.0, 30.0, 90.0]))
    np.savez(tmp_path / "short.npz", radiance=np.ones((3, 4)),
             theta_edges_deg=np.array([0.0, 45.0, 90.0]))
    np.savez(tmp_path / "horizon.npz", radiance=np.ones((3, 4)),
             theta_edges_deg=np.array([0.0, 30.0, 60.0, 80.0]))
    np.savez(tmp_path / "span.npz", radiance=np.ones((3, 4)),
             phi_edges_deg=np.array([0.0, 90.0, 180.0, 270.0, 350.0]))
    np.savez(tmp_path / "other.npz", sky=np.ones((3, 4)))
    cases = {"missing.npy": "no such file", "empty.npy": "is empty",
             "junk.npy": "cannot read", "sky.png": "unknown file type",
             "vector.npy": "two-dimensional", "cube.npy": "two-dimensional",
             "neg.npy": "negative radiance", "nan.npy": "NaN", "dark.npy": "dark everywhere",
             "nothing.npy": "empty", "mono.npz": "increase strictly",
             "short.npz": "4 values", "horizon.npz": "0 to 90", "span.npz": "360",
             "other.npz": "no array 'radiance'"}
    for name, words in cases.items():
        msg = sky_error(tmp_path / name)
        assert "sky map" in msg and str(tmp_path / name) in msg and words in msg, (name, msg)
    # another dataset name
    scene.build(load_config(base({"map": str(tmp_path / "other.npz"), "dataset": "sky"})))
    # layout is for .exr images only
    msg = sky_error(tmp_path / "neg.npy", layout="sphere")
    assert "illumination.sky" in msg and "layout = 'sphere'" in msg and \
        "applies to .exr images" in msg and "\n" not in msg, msg


def test_sky_config(tmp_path):
    with pytest.raises(ConfigError, match="'uniform', 'cardioidal', 'overcast', "
                                          "'harrison_coombes' or a mapping {map}"):
        load_config(base("clear"))
    with pytest.raises(ConfigError, match="illumination.sky.map: required key is missing"):
        load_config(base({"file": "x.npy"}))
    with pytest.raises(ConfigError, match="illumination.sky.sampling = 'uniform': allowed: "
                                          "'importance' or 'cosine'"):
        load_config(base({"map": "x.npy", "sampling": "uniform"}))
    np.save(tmp_path / "sky.npy", np.ones((9, 36)))
    (tmp_path / "scene.yaml").write_text(
        "water: {layers: [{thickness_m: 1, a: 0.1, b: 0}]}\nbottom: {model: black}\n"
        "illumination: {diffuse_fraction: 0.5, sky: {map: sky.npy, sampling: cosine}}\n")
    config = load_config(tmp_path / "scene.yaml")
    assert config.illumination.sky.map == str((tmp_path / "sky.npy").resolve())
    assert config.illumination.sky.sampling == "cosine"
    from oceanmc.config import config_to_yaml
    import yaml
    again = load_config(yaml.safe_load(config_to_yaml(config)))
    assert again.illumination.sky == config.illumination.sky


# --- OpenEXR sky images -----------------------------------------------------------------------

def write_exr(path, channels, header=None):
    """A single-part scanline OpenEXR image with the given {name: 2-D float16/float32 array}."""
    OpenEXR.File(dict({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                      **(header or {})), channels).write(str(path))
    return path


def exr_sky(rows=6, cols=16):
    """R, G, B (float32) of a hemisphere map: a smooth background, one bright patch at rows 1-2,
    columns 3-4 (theta_view 15-45 deg, phi_view 67.5-112.5 deg for 6 x 16), a pure-red, a
    pure-green and a pure-blue pixel of value 1 in the last row, columns 9-11."""
    t = np.arange(rows)[:, None]
    p = np.arange(cols)[None, :]
    R = (1.0 + 0.1 * t + 0.01 * p).astype(np.float32)
    G = (2.0 + 0.05 * t - 0.02 * np.cos(p)).astype(np.float32)
    B = (0.5 + 0.2 * np.sin(p) ** 2 + 0.03 * t).astype(np.float32)
    for c in (R, G, B):
        c[1:3, 3:5] *= 40.0
        c[-1, 9:12] = 0.0
    R[-1, 9], G[-1, 10], B[-1, 11] = 1.0, 1.0, 1.0
    return R, G, B


def luminance(R, G, B):
    return (0.2126 * R.astype(np.float64) + 0.7152 * G.astype(np.float64)
            + 0.0722 * B.astype(np.float64))


def test_exr_map_reading(tmp_path):
    R, G, B = exr_sky()
    Y = (0.3 * R + 0.6 * G + 0.1 * B).astype(np.float32)   # not the Rec. 709 weights
    # RGB only: the Rec. 709 luminance, oriented as the image (row 0 = zenith, column 0 = phi 0)
    theta, phi, L = sky_maps.read_sky_map(write_exr(tmp_path / "rgb.exr",
                                                    {"R": R, "G": G, "B": B}))
    assert L.dtype == np.float64 and L.shape == (6, 16)
    np.testing.assert_array_equal(L, luminance(R, G, B))
    assert L[-1, 9] == 0.2126 and L[-1, 10] == 0.7152 and L[-1, 11] == 0.0722
    assert np.unravel_index(np.argmax(L), L.shape) in {(1, 3), (1, 4), (2, 3), (2, 4)}
    assert L[0, 0] < L[1, 3] / 20 and L[5, 3] < L[2, 3] / 20
    np.testing.assert_array_equal(theta, np.linspace(0.0, 90.0, 7))
    np.testing.assert_array_equal(phi, np.linspace(0.0, 360.0, 17))
    # alpha and other channels beside R, G, B are ignored
    _, _, L2 = sky_maps.read_sky_map(write_exr(tmp_path / "rgba.exr", {
        "R": R, "G": G, "B": B, "A": np.full_like(R, 0.5), "Z": -np.ones_like(R)}))
    np.testing.assert_array_equal(L2, L)
    # a Y channel wins over R, G, B; half floats are read as they are stored
    _, _, LY = sky_maps.read_sky_map(write_exr(tmp_path / "ry.exr",
                                               {"R": R, "G": G, "B": B, "Y": Y}))
    np.testing.assert_array_equal(LY, Y.astype(np.float64))
    Yh = Y.astype(np.float16)
    _, _, LH = sky_maps.read_sky_map(write_exr(tmp_path / "half.exr", {"Y": Yh}))
    np.testing.assert_array_equal(LH, Yh.astype(np.float64))
    # dataset names a channel, also one in a layer; uint pixels are read as they are
    _, _, LG = sky_maps.read_sky_map(tmp_path / "ry.exr", "G")
    np.testing.assert_array_equal(LG, G.astype(np.float64))
    _, _, LB = sky_maps.read_sky_map(write_exr(tmp_path / "layer.exr", {
        "sky.R": R, "sky.G": G, "sky.B": B, "Y": Y}), "sky.B")
    np.testing.assert_array_equal(LB, B.astype(np.float64))
    U = np.arange(1, 6 * 16 + 1, dtype=np.uint32).reshape(6, 16)
    _, _, LU = sky_maps.read_sky_map(write_exr(tmp_path / "uint.exr", {"Y": U}))
    np.testing.assert_array_equal(LU, U.astype(np.float64))
    # full sphere (width = 2 x height): rows 0..180 deg; only the upper half (the sky) is read,
    # the ground below may hold anything
    sphere = np.concatenate([Y[:4], np.full((4, 16), -7.0, np.float32)])
    sphere[5, 2] = np.nan
    _, _, LS = sky_maps.read_sky_map(write_exr(tmp_path / "sphere.exr", {"Y": sphere}))
    np.testing.assert_array_equal(LS, Y[:4].astype(np.float64))
    # any other shape is the upper hemisphere: 4 x 16, 8 x 15 and 8 x 17 are read whole
    for shape in ((4, 16), (8, 15), (8, 17)):
        img = np.random.default_rng(1).uniform(0.5, 2.0, shape).astype(np.float32)
        theta, phi, Lh = sky_maps.read_sky_map(write_exr(tmp_path / "h.exr", {"Y": img}))
        np.testing.assert_array_equal(Lh, img.astype(np.float64))
        assert theta.size == shape[0] + 1 and phi.size == shape[1] + 1
    # layout says it outright: a 2:1 hemisphere map (8 x 16) read whole, rows 0..90 deg; a
    # full sphere that is not 2:1 (8 x 15) read in its upper half, rows 0..90 deg of 0..180
    img = np.random.default_rng(2).uniform(0.5, 2.0, (8, 16)).astype(np.float32)
    theta, _, Lh = sky_maps.read_sky_map(write_exr(tmp_path / "h2.exr", {"Y": img}),
                                         layout="hemisphere")
    np.testing.assert_array_equal(Lh, img.astype(np.float64))
    np.testing.assert_allclose(theta, np.linspace(0.0, 90.0, 9))
    img = np.random.default_rng(3).uniform(0.5, 2.0, (8, 15)).astype(np.float32)
    theta, _, Ls = sky_maps.read_sky_map(write_exr(tmp_path / "s2.exr", {"Y": img}),
                                         layout="sphere")
    np.testing.assert_array_equal(Ls, img[:4].astype(np.float64))
    np.testing.assert_allclose(theta, np.linspace(0.0, 90.0, 5))


def assert_same_fields(a, b):
    """Two packed skies, (record, pool), are the same bit for bit."""
    (rec_a, pool_a), (rec_b, pool_b) = a, b
    assert rec_a.tobytes() == rec_b.tobytes()
    assert pool_a.dtype == pool_b.dtype and np.array_equal(pool_a, pool_b)


@pytest.mark.parametrize("sampling", ["importance", "cosine"])
def test_exr_map_same_tables_as_npy(tmp_path, sampling):
    """The same map as .exr (RGB luminance; Y of a full sphere) and as .npy gives bit-identical
    sky fields."""
    R, G, B = exr_sky(rows=9, cols=24)
    write_exr(tmp_path / "rgb.exr", {"R": R, "G": G, "B": B})
    np.save(tmp_path / "rgb.npy", luminance(R, G, B))
    Y = np.random.default_rng(2).uniform(0.1, 3.0, (10, 20)).astype(np.float32)
    Y[1, 7] = 300.0
    write_exr(tmp_path / "sphere.exr", {"Y": Y})
    np.save(tmp_path / "sphere.npy", Y[:5].astype(np.float64))
    for name in ("rgb", "sphere"):
        packed = [sky_packer.pack(load_config(base(
            {"map": str(tmp_path / f"{name}.{ext}"), "sampling": sampling})).illumination)
            for ext in ("exr", "npy")]
        assert_same_fields(*packed)
        rec = packed[0][0][0]
        assert (rec["n_rows"], rec["n_cols"]) == ((9, 24) if name == "rgb" else (5, 20))
    # and through the whole scene
    a = scene.build(load_config(base({"map": str(tmp_path / "rgb.exr"),
                                      "sampling": sampling})))
    b = scene.build(load_config(base({"map": str(tmp_path / "rgb.npy"),
                                      "sampling": sampling})))
    assert_same_fields((a.sky, a.floats), (b.sky, b.floats))


def test_bad_exr_files(tmp_path):
    ok = np.ones((5, 8), np.float32)       # not 2:1, so every row is sky
    neg = ok.copy()
    neg[2, 5] = -0.25
    nan = ok.copy()
    nan[1, 6] = np.nan
    write_exr(tmp_path / "neg.exr", {"Y": neg})
    write_exr(tmp_path / "negred.exr", {"R": neg, "G": ok, "B": ok})
    write_exr(tmp_path / "nan.exr", {"R": ok, "G": ok, "B": nan})
    write_exr(tmp_path / "inf.exr", {"Y": np.array([[1.0, np.inf], [1.0, 1.0]], np.float16)})
    write_exr(tmp_path / "odd.exr", {"Y": np.ones((3, 6), np.float32)})
    write_exr(tmp_path / "depth.exr", {"Z": ok, "A": ok})
    write_exr(tmp_path / "ap0.exr", {"R": ok, "G": ok, "B": ok}, {"chromaticities": (
        0.7347, 0.2653, 0.0, 1.0, 0.0001, -0.077, 0.32168, 0.33767)})
    write_exr(tmp_path / "dark.exr", {"Y": np.zeros((5, 8), np.float32)})
    OpenEXR.File([OpenEXR.Part({}, {"Y": ok}, name="a"),
                  OpenEXR.Part({}, {"Y": ok}, name="b")]).write(str(tmp_path / "parts.exr"))
    (tmp_path / "junk.exr").write_bytes(b"not an OpenEXR image at all, just some bytes")
    good = write_exr(tmp_path / "good.exr", {"Y": np.ones((40, 50), np.float32)},
                     {"compression": OpenEXR.NO_COMPRESSION}).read_bytes()
    (tmp_path / "cut.exr").write_bytes(good[: len(good) // 2])
    (tmp_path / "empty.exr").write_bytes(b"")
    cases = {"neg.exr": "negative value -0.25 in channel 'Y' at pixel row 2, column 5",
             "negred.exr": "negative value -0.25 in channel 'R' at pixel row 2, column 5",
             "nan.exr": "channel 'B' contains NaN or inf (at pixel row 1, column 6)",
             "inf.exr": "channel 'Y' contains NaN or inf (at pixel row 0, column 1)",
             "odd.exr": "needs an even height",
             "depth.exr": "no channel 'radiance' or 'Y', nor all of 'R', 'G', 'B' (found: "
                          "['A', 'Z'])",
             "ap0.exr": "not Rec. 709", "dark.exr": "dark everywhere",
             "parts.exr": "has 2 parts", "junk.exr": "cannot read it as OpenEXR",
             "cut.exr": "cannot read it as OpenEXR", "empty.exr": "is empty",
             "missing.exr": "no such file"}
    for name, words in cases.items():
        msg = sky_error(tmp_path / name)
        assert msg.startswith(f"sky map {tmp_path / name}: ") and words in msg, (name, msg)
        assert "\n" not in msg, (name, msg)
    msg = sky_error(tmp_path / "good.exr", dataset="radiance.Y")
    assert "no channel 'radiance.Y' (found: ['Y'])" in msg, msg
    # a sphere layout needs an even height whatever the shape
    msg = sky_error(tmp_path / "neg.exr", layout="sphere")
    assert "(5 x 8 pixels, layout sphere) needs an even height" in msg, msg
    # the right channel named: read
    scene.build(load_config(base({"map": str(tmp_path / "depth.exr"), "dataset": "A"})))


def test_bad_exr_on_the_command_line(tmp_path):
    """A truncated image (OpenEXRCore prints its own error to file descriptor 2, the bindings a
    warning to stdout): one line on stderr naming the file, nothing on stdout, exit 2."""
    good = write_exr(tmp_path / "good.exr", {"Y": np.ones((40, 50), np.float32)},
                     {"compression": OpenEXR.NO_COMPRESSION}).read_bytes()
    (tmp_path / "cut.exr").write_bytes(good[: len(good) // 2])
    (tmp_path / "scene.yaml").write_text(
        "water: {layers: [{thickness_m: 1, a: 0.1, b: 0}]}\nbottom: {model: black}\n"
        "illumination: {diffuse_fraction: 0.5, sky: {map: cut.exr}}\n")
    done = subprocess.run([sys.executable, "-m", "oceanmc", "run", "scene.yaml", "-o", "x.h5"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=600,
                          env=dict(os.environ, PYTHONPATH=str(REPO)))
    assert done.returncode == 2, done.stderr
    assert done.stdout == "", done.stdout
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    assert f"sky map {tmp_path / 'cut.exr'}: cannot read it as OpenEXR" in lines[0], lines[0]
    assert not (tmp_path / "x.h5").exists()


@pytest.mark.parametrize("sky", ["uniform", "cardioidal", "harrison_coombes"])
def test_the_sky_over_each_downward_quad_integrates_to_its_irradiance(sky):
    """scene.surface.sky_quad_radiance, air/rho's denominator: a unit sky's radiance over each
    quad its light travels down through sums, times cos and the solid angle, to 1 (to 1%: the
    cosine at each band's middle); 0 in the upward quads; a uniform sky is 1/pi everywhere,
    and the Harrison-Coombes sky is brightest in the quad around the sun (zenith 30 deg,
    travel azimuth 0), far above the one opposite."""
    from oceanmc.scene.grid import make_grid
    from oceanmc.scene.surface import sky_quad_radiance
    config = oceanmc.load_config({
        "illumination": {"sun_zenith_deg": 30, "sky": sky, "diffuse_fraction": 0.3},
        "water": {"layers": [{"thickness_m": 1, "a": 0.1, "b": 0.1}]},
        "bottom": {"model": "black"}})
    grid = make_grid(config.tallies)
    radiance = sky_quad_radiance(config.illumination, grid.theta_edges, grid.phi_edges,
                                 grid.is_cap)
    down = grid.theta < 90.0
    omega = grid.solid_angle.copy()
    omega[grid.is_cap, 1:] = 0.0   # a cap's one quad, counted once
    mu = np.cos(np.radians(grid.theta))[:, None]
    assert (radiance * mu * omega)[down].sum() == pytest.approx(1.0, abs=0.01)
    assert np.all(radiance[~down] == 0.0) and np.all(radiance[down] > 0.0)
    if sky == "uniform":
        assert np.allclose(radiance[down], 1.0 / math.pi)
    if sky == "harrison_coombes":
        band = int(np.searchsorted(grid.theta_edges, 30.0, side="right")) - 1
        toward, away = radiance[band, np.argmin(np.abs(grid.phi))], \
            radiance[band, np.argmin(np.abs(np.abs(grid.phi) - 180.0))]
        assert toward > 5.0 * away


def test_a_uniform_map_gives_the_uniform_sky_s_rho_denominators(tmp_path):
    """The sky radiance rho and rho_local divide by (scene.surface.sky_radiance) is read from a
    map's cells (they had no map before 2026-11-29: rho estimated it from the run, rho_local
    was left out): a uniform map's equals `sky: uniform`'s, over every mirror quad and in an
    exact direction, to rounding; so do the two runs' rho_local, whose sky part samples the
    surface with the same streams."""
    from oceanmc.scene.grid import make_grid
    from oceanmc.scene.surface import sky_quad_radiance
    np.save(tmp_path / "sky.npy", np.ones((9, 36)))
    scenes = [{"photons": 4000, "seed": 3, "tallies": {"depths_m": [0],
                                                       "local_directions_deg": [[140, 135]]},
               "illumination": {"sun_zenith_deg": 30, "diffuse_fraction": 0.3, "sky": sky},
               "surface": {"model": "cox_munk", "wind_speed_m_s": 5.0},
               "water": {"layers": [{"thickness_m": 1, "a": 0.1, "b": 0.1}]},
               "bottom": {"model": "black"}}
              for sky in ("uniform", {"map": str(tmp_path / "sky.npy")})]
    configs = [oceanmc.load_config(scene) for scene in scenes]
    grid = make_grid(configs[0].tallies)
    quads = [sky_quad_radiance(c.illumination, grid.theta_edges, grid.phi_edges, grid.is_cap)
             for c in configs]
    assert np.allclose(quads[0], quads[1], rtol=1e-12, atol=0.0)
    rho = [oceanmc.simulate(c)["air/rho_local"] for c in configs]
    assert np.all(rho[0] > 0.0) and np.allclose(rho[0], rho[1], rtol=1e-12, atol=0.0)


def test_map_radiance_reads_the_cell_the_sampler_draws_from():
    """sky_maps.map_radiance follows the sampler's convention (test_view_to_travel_convention):
    one bright cell at theta_view 30-34 deg, phi_view 176-184 deg is the radiance of light
    travelling at 32 deg from nadir along phi 0, not along phi 180; the map's irradiance is 1."""
    from oceanmc.scene.sky_maps import map_radiance
    L = np.zeros((45, 90))
    L[15:17, 44:46] = 1.0
    theta, phi = np.linspace(0.0, 90.0, 46), np.linspace(0.0, 360.0, 91)
    t = math.radians(32.0)
    dirs = np.array([[math.sin(t), 0.0, math.cos(t)], [-math.sin(t), 0.0, math.cos(t)]])
    along, against = map_radiance(theta, phi, L, dirs)
    s = np.sin(np.radians(theta)) ** 2
    cos_mass = np.diff(s)[15:17].sum() * np.radians(8.0) / 2.0   # the bright cells' integral
    assert along == pytest.approx(1.0 / cos_mass) and against == 0.0
