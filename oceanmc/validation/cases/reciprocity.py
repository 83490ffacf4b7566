"""Validation case reciprocity: the slab reflection function is symmetric when sun and viewer
swap."""
from __future__ import annotations

import math

import numpy as np

from ..context import Ctx
from ..stats import JK
from .common import Case, _plt, scene


def case_reciprocity(ctx: Ctx) -> None:
    tau_layer = {"thickness_m": 1.0, "a": 0.1, "b": 0.9,
                 "phase": {"model": "henyey_greenstein", "g": 0.5}}
    bottom = {"model": "lambertian", "reflectance": 0.3}
    bands = [(20.0, 30.0), (45.0, 55.0), (65.0, 75.0)]   # zenith angles (sun and view)
    edges = [0.0, 20.0, 30.0, 45.0, 55.0, 65.0, 75.0, 90.0, 105.0, 115.0, 125.0, 135.0, 150.0,
             160.0, 180.0]
    photons = ctx.pick(5_000_000, 200_000)
    x, w = np.polynomial.legendre.leggauss(3)
    m_est = {}   # (sun band, view band) -> JK over phi columns (4) of band-averaged radiance
    phi_c = None
    for bi, (lo, hi) in enumerate(bands):
        mu_lo, mu_hi = math.cos(math.radians(hi)), math.cos(math.radians(lo))
        acc = None
        for xk, wk in zip(x, w):
            mu0 = mu_lo + (mu_hi - mu_lo) * 0.5 * (xk + 1.0)
            th = math.degrees(math.acos(mu0))
            r = ctx.simulate(scene(f"slab tau 1, sun {th:.3f} deg (band {lo:g}-{hi:g})",
                                   photons, sun=th, surface="none", layers=[tau_layer],
                                   bottom=bottom, theta_edges=edges, phi_bands=4))
            rad = JK.of(r, "radiance")[0] * (0.5 * wk)
            acc = rad if acc is None else acc + rad
            phi_c = np.asarray(r.coords["phi"])
        e = np.asarray(edges)
        for vj, (vlo, vhi) in enumerate(bands):
            # the upward band whose zenith angles are vlo..vhi: theta 180 - vhi .. 180 - vlo
            i = int(np.searchsorted(e, 180.0 - vhi))
            m_est[(bi, vj)] = acc[i, :]
    pairs = [(0, 1), (0, 2), (1, 2)]
    for (i, j) in pairs:
        a, b = m_est[(i, j)], m_est[(j, i)]
        tag = f"sun band {bands[i][0]:g}-{bands[i][1]:g} / view band {bands[j][0]:g}-" \
              f"{bands[j][1]:g} vs swapped"
        ctx.compare_jk(f"{tag}: azimuthal mean, (L_ij - L_ji)/L_ij",
                       (a.mean() - b.mean()) / a.mean(), 0.0, rel_cap=None)
        ctx.compare_jk(f"{tag}: per azimuth band, (L_ij - L_ji)/L_ij", (a - b) / a, 0.0,
                       labels=[f"phi {p:g}" for p in phi_c])
        # relative precision of the comparison (power)
        d = (a.mean() - b.mean()) / a.mean()
        ctx.exact(f"{tag}: power, stderr of the relative difference <= "
                  f"{ctx.pick(0.01, 0.03):g}", float(d.stderr) <= ctx.pick(0.01, 0.03), 1.0)
    plt = _plt()
    fig, ax = plt.subplots(figsize=(4.8, 4.5))
    for (i, j) in pairs:
        a, b = m_est[(i, j)], m_est[(j, i)]
        ax.errorbar(a.value, b.value, xerr=a.stderr, yerr=b.stderr, fmt="o", ms=4,
                    label=f"bands {i + 1} <-> {j + 1}")
    lims = [min(ax.get_xlim()[0], ax.get_ylim()[0]), max(ax.get_xlim()[1], ax.get_ylim()[1])]
    ax.plot(lims, lims, "k-", lw=0.8)
    ax.set_xlabel("L(view band j; sun in band i) / Ed(0+)")
    ax.set_ylabel("L(view band i; sun in band j) / Ed(0+)")
    ax.legend(fontsize=8)
    ctx.figure(fig, "pairs", "Reciprocity: band-averaged reflected radiance with sun and viewer "
               "swapped, per azimuth column (0, 90, 180, 270 deg); the line is equality.")
    ctx.note("A slab with tau = 1 (a = 0.1, b = 0.9 /m, HG g = 0.5) over a Lambertian bottom "
             "(rho = 0.3, itself reciprocal), surface: none. For the plane-parallel reflection "
             "function rho(mu, mu0, dphi) = pi L / (mu0 F0) = rho(mu0, mu, dphi). With F0 = 1 "
             "on a plane normal to the beam this is L(mu; mu0)/mu0 = L(mu0; mu)/mu; oceanmc "
             "normalises to Ed(0+) = mu0 F0 = 1, so L/Ed0 itself is symmetric. Quad averaging "
             "would break the symmetry (the viewer averages over a band, the sun does not), so "
             "the sun is averaged over the same band too: three runs with the sun at the "
             "3-point Gauss-Legendre nodes in mu of each band, weighted. Then the double band "
             "average is symmetric exactly (up to the Gauss rule's error on a smooth function, "
             "far below the noise). Three zenith bands (20-30, 45-55, 65-75 deg) give three "
             "pairs; each is compared for the azimuthal mean and per 90 deg azimuth column "
             "(the relative azimuth of travel directions is the same in both configurations). "
             "Runs with the same batch count are paired batch by batch for the jackknife.")


CASE = Case("reciprocity", "Reciprocity of the reflection function", case_reciprocity,
            "L(mu; mu0) = L(mu0; mu) per unit Ed(0+), band-averaged both ways")
