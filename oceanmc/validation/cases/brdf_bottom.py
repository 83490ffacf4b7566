"""Validation case brdf_bottom: Lambertian and Minnaert bottoms without water or interface:
reflected flux against rho_dh(theta_i), reflected radiance against
(rho/pi)(cos t_i cos t_r)^k."""
from __future__ import annotations

import math

import numpy as np

from ...plot import half_polar
from .. import references as ref
from ..context import Ctx
from ..stats import JK
from .common import (Case, _plt, clear_layer, compare_symmetric_radiance, edges_of,
                     hemisphere_bands, scene)


def case_brdf(ctx: Ctx) -> None:
    rho = 0.8
    models = [("lambertian", 0.0), ("minnaert", 0.5), ("minnaert", 1.0), ("minnaert", 2.0)]
    base = ctx.pick(2_000_000, 100_000)
    polar = {}
    flux_pts = {}
    for model, k in models:
        angles = [0.0, 30.0, 60.0, 75.0] if k < 2 else [0.0, 30.0, 60.0]
        label_m = "Lambertian" if model == "lambertian" else f"Minnaert k={k:g}"
        for th in angles:
            mu_i = math.cos(math.radians(th))
            rho_dh = float(ref.minnaert_rho_dh(rho, k, mu_i))
            bottom = ({"model": "lambertian", "reflectance": rho} if model == "lambertian"
                      else {"model": "minnaert", "reflectance": rho, "k": k})
            photons = int(base * min(5.0, max(1.0, 0.4 / rho_dh)))
            r = ctx.simulate(scene(f"{label_m}, sun {th:g}", photons, sun=th, surface="none",
                                   layers=[clear_layer()], bottom=bottom, mode="analog"))
            tag = f"{label_m}, theta_i {th:g}"
            wl = JK.of(r, "budget/water_leaving")
            ctx.compare(f"{tag}: reflected flux vs rho_dh", wl.value, wl.stderr, rho_dh,
                        rel_cap=ctx.pick(0.01, 0.03))
            flux_pts[(k, th)] = (float(wl.value), float(wl.stderr), rho_dh)
            # deterministic: implicit weights are exactly rho_dh
            ri = ctx.simulate(scene(f"{label_m}, sun {th:g}, implicit", 200, sun=th,
                                    surface="none", layers=[clear_layer()], bottom=bottom,
                                    batches=2))
            ctx.exact(f"{tag}: implicit reflected weight == rho_dh",
                      ri["budget/water_leaving"], rho_dh, rtol=1e-9)
            # radiance distribution
            edges = edges_of(r)
            up = hemisphere_bands(edges, up=True)
            rad = JK.of(r, "radiance")[0]
            f = (lambda mu, k=k, mu_i=mu_i: ref.minnaert_radiance(rho, k, mu_i, mu))
            compare_symmetric_radiance(ctx, r, rad, edges, up, f, band_counts=True,
                                       band_check=f"{tag}: band-averaged reflected radiance",
                                       quad_check=f"{tag}: quad radiance", quad_cap=(0.04, 0.12))
            if th == 30.0:
                polar[label_m] = (r, edges, up, rad, k, mu_i)

    plt = _plt()
    from matplotlib.ticker import MaxNLocator
    fig, axes = plt.subplots(1, len(polar), subplot_kw={"projection": "polar"},
                             figsize=(4.2 * len(polar), 3.6))
    for ax, (label_m, (r, edges, up, rad, k, mu_i)) in zip(axes, polar.items()):
        phi = np.asarray(r.coords["phi"])
        j0 = int(np.argmin(np.abs(phi - 0.0)))
        j180 = int(np.argmin(np.abs(phi - 180.0)))
        view = 180.0 - 0.5 * (edges[up] + edges[up + 1])   # zenith angle of the reflected ray
        for j, sign, colour in ((j0, 1.0, "C0"), (j180, -1.0, "C1")):
            v, e = rad.value[up, j], rad.stderr[up, j]
            ok = e < 0.25 * np.maximum(v, 1e-300)     # leave out the few-photon horizon quads
            ax.errorbar(np.radians(sign * view[ok]), v[ok], yerr=e[ok], fmt="o", ms=3,
                        color=colour, label=f"MC quads, phi = {phi[j]:g}")
        t = np.linspace(-89.9, 89.9, 400)
        ax.plot(np.radians(t), ref.minnaert_radiance(rho, k, mu_i, np.cos(np.radians(t))), "k-",
                lw=1, label="analytic")
        ax.yaxis.set_major_locator(MaxNLocator(3))
        half_polar(ax, f"{label_m}, theta_i = 30 deg")
    axes[0].legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.1, -0.25))
    ctx.figure(fig, "polar", "Reflected radiance (per unit incident irradiance) in the principal "
               "plane, sun at 30 deg: MC quad averages (phi = 0 to the right, 180 to the left; "
               "angle = zenith angle of the reflected ray) against (rho/pi)(cos t_i cos t_r)^k.")

    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    t = np.linspace(0, 89, 200)
    for n, (model, k) in enumerate(models):
        ax.plot(t, ref.minnaert_rho_dh(rho, k, np.cos(np.radians(t))), color=f"C{n}", lw=1,
                label=f"k = {k:g}" + (" (Lambertian)" if k == 0 else ""))
        pts = [(th, v, e) for (kk, th), (v, e, _) in flux_pts.items() if kk == k]
        ax.errorbar([p[0] for p in pts], [p[1] for p in pts], yerr=[p[2] for p in pts],
                    fmt="o", color=f"C{n}", ms=4)
    ax.set_xlabel("incidence angle theta_i (deg)")
    ax.set_ylabel("reflected flux / incident flux")
    ax.legend(fontsize=8)
    ctx.figure(fig, "rho_dh", "Directional-hemispherical reflectance: MC (analog mode, points) "
               "against 2 rho cos^k(theta_i)/(k + 2), rho = 0.8.")
    ctx.note("Scene: a 1 m layer with a = b = 0 over the bottom, no refractive interface "
             "(surface: none), sun only, unit horizontal irradiance at the bottom. The reflected "
             "flux is budget/water_leaving, run in analog mode (the bottom absorbs or reflects "
             "each photon by a draw, probability rho_dh), so it has a binomial standard error; "
             "in implicit mode every photon carries exactly rho_dh (checked deterministically). "
             "The reflected radiance (rho/pi)(cos t_i cos t_r)^k is compared on every upward "
             "quad (level 0, the photons leaving) and on azimuthal band averages; references are "
             "quad averages (integrals over mu), including the tally's grazing rule in the "
             "85-90 deg band.")


CASE = Case("brdf_bottom", "Lambertian and Minnaert bottoms without water", case_brdf,
            "reflected flux vs rho_dh(theta_i), radiance vs (rho/pi)(cos t_i cos t_r)^k")
