"""Validation case optical_manhole: radiance just below a flat surface under uniform and
cardioidal skies and under the sun (Snell's window, the n^2 law), total internal reflection of
upwelling light, sky reflectances and r_wa."""
from __future__ import annotations

import math

import numpy as np

from .. import references as ref
from ...plot import log_norm, polar_quads
from ..context import Ctx
from ..stats import JK
from .common import (N_WATER, Case, _plt, band_labels, band_refs, clear_layer,
                     compare_symmetric_radiance, edges_of, hemisphere_bands, scene)


def _fine_edges(step_down: float) -> list[float]:
    down = list(np.round(np.arange(0.0, 90.0 + 1e-9, step_down), 6))
    return down + [95.0, 105.0, 115.0, 125.0, 135.0, 145.0, 155.0, 165.0, 175.0, 180.0]


def _sky_manhole(ctx: Ctx, sky: str, photons: int):
    edges_cfg = _fine_edges(2.5)
    r = ctx.simulate(scene(f"{sky} sky, clear water, black bottom", photons, diffuse=1.0, sky=sky,
                           layers=[clear_layer()], bottom={"model": "black"},
                           theta_edges=edges_cfg, phi_bands=24))
    edges = edges_of(r)
    down = hemisphere_bands(edges, up=False)
    theta_c = ref.critical_angle_deg(N_WATER)
    mu_c = math.cos(math.radians(theta_c))
    r_sky = ref.sky_reflectance(N_WATER, sky)
    sr = JK.of(r, "budget/surface_reflection")
    ctx.compare(f"{sky} sky: surface reflectance (budget/surface_reflection)", sr.value,
                sr.stderr, r_sky, rel_cap=ctx.pick(0.005, 0.01))
    ed = JK.of(r, "Ed")[0]
    ctx.compare(f"{sky} sky: Ed(0-) = 1 - r_sky", ed.value, ed.stderr, 1.0 - r_sky,
                rel_cap=ctx.pick(0.002, 0.005))
    rad = JK.of(r, "radiance")[0]
    inside = np.array([i for i in down if edges[i] < theta_c])
    outside = np.array([i for i in down if edges[i] >= theta_c])
    f = (lambda mu: float(ref.radiance_below_surface(N_WATER, sky, mu)))
    band_ref = compare_symmetric_radiance(
        ctx, r, rad, edges, inside, f, points=[mu_c], quad_cap=(0.03, 0.09),
        band_check=f"{sky} sky: band-averaged L(0-) inside Snell's window vs t n^2 L_sky",
        quad_check=f"{sky} sky: quad L(0-) inside Snell's window")
    ctx.exact(f"{sky} sky: L(0-) on quads beyond the critical angle (no light there)",
              rad.value[outside, :], 0.0)
    return r, edges, inside, rad, band_ref


def case_manhole(ctx: Ctx) -> None:
    n = N_WATER
    theta_c = ref.critical_angle_deg(n)
    r_uni = ref.sky_reflectance(n, "uniform")
    r_card = ref.sky_reflectance(n, "cardioidal")
    r_wa = ref.uniform_upwelling_reflectance(n)
    ctx.exact("reference: critical angle asin(1/n) (deg) vs 48.27", theta_c, 48.27, atol=0.005)
    ctx.exact("reference: uniform-sky reflectance vs 0.0675", r_uni, 0.0675, atol=5e-5)
    ctx.exact("reference: cardioidal-sky reflectance vs 0.0522", r_card, 0.0522, atol=5e-5)
    ctx.exact("reference: r_wa (uniform upwelling) vs 0.4807", r_wa, 0.4807, atol=5e-5)
    ctx.exact("reference: r_wa = 1 - (1 - r_aw)/n^2 identity", r_wa, 1.0 - (1.0 - r_uni) / n ** 2,
              rtol=1e-9)

    photons = ctx.pick(4_000_000, 200_000)
    sky_runs = {}
    for sky in ("uniform", "cardioidal"):
        sky_runs[sky] = _sky_manhole(ctx, sky, photons)

    # the sun: Snell direction and the radiance (solid-angle) compression of a beam
    sun_edges = list(np.arange(0.0, 91.0, 1.0)) + [95.0, 105.0, 115.0, 125.0, 135.0, 145.0,
                                                   155.0, 165.0, 175.0, 180.0]
    sun_photons = ctx.pick(2_000_000, 100_000)
    for th in (20.0, 40.0, 60.0, 80.0):
        mu_s = math.cos(math.radians(th))
        r = ctx.simulate(scene(f"sun {th:g} deg, clear water, black bottom (analog)", sun_photons,
                               sun=th, layers=[clear_layer()], bottom={"model": "black"},
                               theta_edges=sun_edges, phi_bands=72, mode="analog"))
        edges = edges_of(r)
        t = 1.0 - ref.fresnel(1.0, n, mu_s)
        mu_w = float(ref.refracted_cos(1.0, n, mu_s))
        theta_w = math.degrees(math.acos(mu_w))
        i = int(np.searchsorted(edges, theta_w, side="right") - 1)
        rad = JK.of(r, "radiance")[0]
        phi_e = np.radians(np.asarray(r.coords["phi_edges"]))
        om = (math.cos(math.radians(edges[i])) - math.cos(math.radians(edges[i + 1]))) * \
            (phi_e[1] - phi_e[0])
        tag = f"sun {th:g} deg"
        ed = JK.of(r, "Ed")[0]
        ctx.compare(f"{tag}: Ed(0-) = 1 - R(theta_s)", ed.value, ed.stderr, t,
                    rel_cap=ctx.pick(0.005, 0.015))
        ctx.compare(f"{tag}: L(0-) on the quad holding theta_w = {theta_w:.3f} deg "
                    f"(band {edges[i]:g}-{edges[i + 1]:g}), = t / (mu_w Omega_q)",
                    rad.value[i, 0], rad.stderr[i, 0], t / (mu_w * om),
                    rel_cap=ctx.pick(0.005, 0.015))
        down = hemisphere_bands(edges, up=False)
        others = rad.value[down, :].copy()
        others[np.searchsorted(down, i), 0] = 0.0
        ctx.exact(f"{tag}: L(0-) on every other downward quad (Snell: the beam goes nowhere "
                  "else)", others, 0.0)
        air = JK.of(r, "air/radiance")
        i_air = int(np.searchsorted(edges, th, side="right") - 1)
        om_air = (math.cos(math.radians(edges[i_air])) - math.cos(math.radians(edges[i_air + 1]))) \
            * (phi_e[1] - phi_e[0])
        ratio = (rad[i, 0] * (mu_w * om)) / (air[i_air, 0] * (mu_s * om_air))
        ctx.compare_jk(f"{tag}: n^2 law for the beam, L_w mu_w Omega_w / (L_a mu_a Omega_a) "
                       "= t", ratio, t, rel_cap=ctx.pick(0.005, 0.015))

    # upwelling light from a Lambertian bottom: TIR outside the window, r_wa, n^2 law upward
    r = ctx.simulate(scene("sun at zenith, clear water, Lambertian bottom rho = 1",
                           ctx.pick(4_000_000, 200_000), sun=0.0, layers=[clear_layer()],
                           bottom={"model": "lambertian", "reflectance": 1.0}))
    edges = edges_of(r)
    eu = JK.of(r, "Eu")[0]
    wl = JK.of(r, "air/Eu_water_leaving")
    ctx.compare_jk("uniform upwelling light: r_wa = 1 - Eu_wl(0+)/Eu(0-)", 1.0 - wl / eu, r_wa,
                   rel_cap=ctx.pick(0.005, 0.015))
    rad = JK.of(r, "radiance")[0]
    n_t = len(edges) - 1
    down = hemisphere_bands(edges, up=False)
    beyond = np.array([i for i in down if edges[i] >= theta_c])
    mirror = n_t - 1 - beyond
    ctx.exact("TIR: L_down(0-) == L_up(0-) of the mirrored quad, every quad beyond the critical "
              "angle (ratio)", rad.value[beyond, :] / rad.value[mirror, :], 1.0, rtol=1e-12)
    partial = np.array([i for i in down if 0 < i and edges[i] < theta_c])
    ratio = rad.mean(axis=-1)[partial] / rad.mean(axis=-1)[n_t - 1 - partial]
    rwa_band = band_refs(edges, partial, lambda mu: float(ref.fresnel(n, 1.0, mu)),
                         points=[math.cos(math.radians(theta_c))])
    ctx.compare_jk("inside the window: L_down/L_up(mirrored) = band-averaged R_wa", ratio,
                   rwa_band, labels=band_labels(edges, partial), rel_cap=ctx.pick(0.01, 0.03))
    lw = JK.of(r, "air/Lw")
    up = hemisphere_bands(edges, up=True)
    l_up = eu / math.pi
    lw_ref = band_refs(edges, up, lambda mu: (1.0 - float(ref.fresnel(1.0, n, mu))) / n ** 2)
    ctx.compare_jk("water-leaving radiance: L_w(0+)/L_up(0-) = t/n^2 (band averages in air)",
                   lw.mean(axis=-1)[up] / l_up, lw_ref, labels=band_labels(edges, up),
                   rel_cap=ctx.pick(0.01, 0.03))
    tir_run = (r, edges, rad)

    # figures
    plt = _plt()
    fig, axes = plt.subplots(1, 2, subplot_kw={"projection": "polar"}, figsize=(10, 4.6))
    for ax, (title, (rr, ee, rd)) in zip(axes, (
            ("uniform sky, clear water, black bottom", (sky_runs["uniform"][0],
                                                        sky_runs["uniform"][1],
                                                        JK.of(sky_runs["uniform"][0],
                                                              "radiance")[0])),
            ("sun at zenith, Lambertian bottom (rho = 1)", tir_run))):
        dn = hemisphere_bands(ee, up=False)
        t_e = np.append(ee[dn], ee[dn[-1] + 1])
        vals = rd.value[dn, :].copy()
        norm = log_norm(vals)
        if ee[dn[0] + 1] <= 5.0 and "sun" in title:
            vals[0, :] = np.nan    # the transmitted sun's cap: off the scale
            norm = log_norm(vals, dynamic_range=np.inf)
        mesh = polar_quads(ax, t_e, rr.coords["phi_edges"], vals, norm)
        tt = np.linspace(0, 2 * np.pi, 361)
        ax.plot(tt, np.full_like(tt, theta_c), "w--", lw=1.2)
        ax.set_ylim(0, 90)
        ax.set_yticks([15, 30, 45, 60, 75, 90])
        ax.tick_params(labelsize=7)
        ax.set_title(title + f"\n(dashed: critical angle {theta_c:.2f} deg)", fontsize=9)
        fig.colorbar(mesh, ax=ax, shrink=0.75, label="L(0-) per unit Ed(0+)")
    ctx.figure(fig, "snell_window", "Downwelling radiance just below the surface, looking up "
               "(radius = polar angle of the direction of travel from nadir, i.e. the zenith "
               "angle one looks at; azimuth = phi). Left: Snell's window under a uniform sky "
               "ends at 48.27 deg. Right: with only upwelling light from the bottom outside the "
               "cone, the radiance there is that light totally reflected (the sun's cap is "
               "masked).")

    fig, ax = plt.subplots(figsize=(6, 4))
    tw = np.linspace(0, theta_c - 1e-6, 400)
    mu_a = np.sqrt(1 - n ** 2 * np.sin(np.radians(tw)) ** 2)
    ax.plot(tw, 1 - ref.fresnel(1.0, n, mu_a), "k-", lw=1, label="t(theta_a) (exact Fresnel)")
    for c, sky in (("C0", "uniform"), ("C1", "cardioidal")):
        rr, ee, inside, rd, band_ref = sky_runs[sky]
        centre = 0.5 * (ee[inside] + ee[inside + 1])
        # divide by n^2 L_sky at the band centre's air angle, for display
        mu_ac = np.sqrt(np.clip(1 - n ** 2 * np.sin(np.radians(centre)) ** 2, 0, 1))
        scale = n ** 2 * ref.sky_radiance_constant(sky) * ref.sky_shape(sky, mu_ac)
        band = rd.mean(axis=-1)
        ax.errorbar(centre[:-1], band.value[inside][:-1] / scale[:-1],
                    yerr=band.stderr[inside][:-1] / scale[:-1], fmt="o", ms=3, color=c,
                    label=f"MC, {sky} sky: L(0-) / (n^2 L_sky(theta_a))")
    ax.axvline(theta_c, color="grey", ls="--", lw=1)
    ax.set_xlabel("theta_w in water (deg)")
    ax.set_ylabel("transmittance")
    ax.legend(fontsize=8)
    ctx.figure(fig, "n2_law", "The n^2 law across the surface: band-averaged radiance just below "
               "the surface over n^2 L_sky (at the band centre) against Fresnel transmittance "
               "t(theta_a); the last band before the critical angle is omitted from the plot "
               "(partly outside the window) but checked as a quad average.")
    ctx.note("Sky scenes: Ed(0+) = 1 from a uniform (L = 1/pi) or cardioidal "
             "(L = 3 (1 + 2 cos theta)/(7 pi)) sky over a flat surface (n = 1.34) and clear water "
             "with a black bottom. Below the surface L = t(theta_a) n^2 L_sky(theta_a) inside "
             "Snell's window and nothing outside; references are quad averages of that "
             "function integrated over mu (split at the critical angle). The sun scenes run in "
             "analog mode on a 1 deg theta grid: the whole beam must land in the quad holding "
             "theta_w = asin(sin theta_s / n) with L mu Omega conserved up to t (the n^2 law "
             "for a beam: the refracted solid angle shrinks by mu_a/(n^2 mu_w)). The Lambertian "
             "scene makes uniform upwelling radiance L_up = Eu(0-)/pi under the surface: beyond "
             "the critical angle it is totally reflected (R = 1, so the downward quad equals its "
             "mirror image exactly), inside the window partly; r_wa = 0.4807 and the "
             "water-leaving radiance t L_up / n^2 follow.")


CASE = Case("optical_manhole", "Snell's window, the n^2 law and total internal reflection",
            case_manhole, "radiance below a flat surface under sky and sun; TIR; sky reflectances")
