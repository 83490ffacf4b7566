"""Validation case fresnel: the flat surface's reflectance from air and from water against the
exact Fresnel formula."""
from __future__ import annotations

import math

import numpy as np

from .. import references as ref
from ..context import Ctx
from ..stats import JK
from .common import (N_WATER, Case, _plt, band_labels, band_refs, clear_layer, edges_of,
                     scene)


def case_fresnel(ctx: Ctx) -> None:
    n = N_WATER
    angles = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 85.0, 89.0]
    quoted = {0.0: 0.02111, 60.0: 0.0610, 70.0: 0.135, 80.0: 0.350, 85.0: 0.585}
    for th, val in quoted.items():
        ctx.exact(f"reference: R({th:g} deg) vs DESIGN value {val}",
                  ref.fresnel(1.0, n, math.cos(math.radians(th))), val,
                  atol=0.5 * 10 ** -(len(str(val)) - 2))
    th_chk = np.radians([10, 30, 50, 70, 85])
    ctx.exact("reference: Fresnel (n form) vs angle form (sin/tan), air->water",
              ref.fresnel(1.0, n, np.cos(th_chk)), ref.fresnel_angle_form(1.0, n, th_chk),
              rtol=1e-10)
    th_chk_w = np.radians([10, 30, 45, 48])
    ctx.exact("reference: Fresnel (n form) vs angle form (sin/tan), water->air",
              ref.fresnel(n, 1.0, np.cos(th_chk_w)), ref.fresnel_angle_form(n, 1.0, th_chk_w),
              rtol=1e-10)

    photons = ctx.pick(2_000_000, 100_000)
    vals, errs, refs = [], [], []
    for th in angles:
        mu = math.cos(math.radians(th))
        r_ex = float(ref.fresnel(1.0, n, mu))
        r = ctx.simulate(scene(f"sun {th:g} deg over black water (analog)", photons, sun=th,
                               layers=[clear_layer()], bottom={"model": "black"}, mode="analog",
                               phi_bands=1))
        v = JK.of(r, "budget/surface_reflection")
        vals.append(float(v.value))
        errs.append(float(v.stderr))
        refs.append(r_ex)
        ri = ctx.simulate(scene(f"sun {th:g} deg over black water (implicit)", 200, sun=th,
                                layers=[clear_layer()], bottom={"model": "black"}, batches=2,
                                phi_bands=1))
        ctx.exact(f"air->water R({th:g} deg): implicit reflected weight == exact Fresnel",
                  ri["budget/surface_reflection"], r_ex, rtol=1e-9)
    ctx.compare("air->water R(theta_s) (budget/surface_reflection, analog)", vals, errs, refs,
                labels=[f"theta {a:g}" for a in angles], rel_cap=ctx.pick(0.01, 0.03))

    # water -> air at theta_w: the refracted sun sent back up by a half-silvered mirror bottom
    rho_m = 0.5
    spec, ratio_v, ratio_e, ratio_r, labels = [], [], [], [], []
    for th in (20.0, 50.0, 70.0):
        mu = math.cos(math.radians(th))
        mu_w = float(ref.refracted_cos(1.0, n, mu))
        r_aw = float(ref.fresnel(1.0, n, mu))
        r_wa = float(ref.fresnel(n, 1.0, mu_w))
        r = ctx.simulate(scene(f"sun {th:g} deg, mirror bottom rho = {rho_m} (analog)",
                               photons, sun=th, layers=[clear_layer()],
                               bottom={"model": "specular", "reflectance": rho_m},
                               mode="analog", phi_bands=1))
        rw = 1.0 - JK.of(r, "air/Eu_water_leaving") / JK.of(r, "Eu")[0]
        ratio_v.append(float(rw.value))
        ratio_e.append(float(rw.stderr))
        ratio_r.append(r_wa)
        labels.append(f"theta_s {th:g} (theta_w {math.degrees(math.acos(mu_w)):.2f})")
        v = JK.of(r, "budget/water_leaving")
        spec.append((float(v.value), float(v.stderr),
                     rho_m * (1 - r_aw) * (1 - r_wa) / (1 - rho_m * r_wa), th))
    ctx.compare("water->air R_wa(theta_w) = 1 - Eu_wl(0+)/Eu(0-), beam from a mirror bottom",
                ratio_v, ratio_e, ratio_r, labels=labels, rel_cap=ctx.pick(0.02, 0.06))
    ctx.compare("mirror bottom: water-leaving = rho (1-R_aw)(1-R_wa)/(1 - rho R_wa)",
                [s[0] for s in spec], [s[1] for s in spec], [s[2] for s in spec],
                labels=labels, rel_cap=ctx.pick(0.005, 0.015))

    # water -> air reflectance as a function of angle, from uniform upwelling radiance
    step = 2.5
    down = list(np.arange(0.0, 90.0 + 1e-9, step))
    edges_cfg = down + [180.0 - d for d in reversed(down[:-1])]
    r = ctx.simulate(scene("sun at zenith, Lambertian bottom rho = 1 (water->air R)",
                           ctx.pick(8_000_000, 400_000), sun=0.0, layers=[clear_layer()],
                           bottom={"model": "lambertian", "reflectance": 1.0},
                           theta_edges=edges_cfg, phi_bands=1))
    edges = edges_of(r)
    n_t = len(edges) - 1
    rad = JK.of(r, "radiance")[0][:, 0]
    theta_c = ref.critical_angle_deg(n)
    partial = np.array([i for i in range(1, n_t // 2) if edges[i] < theta_c])
    beyond = np.array([i for i in range(1, n_t // 2) if edges[i] >= theta_c])
    ratio = rad[partial] / rad[n_t - 1 - partial]
    rwa = band_refs(edges, partial, lambda mu: float(ref.fresnel(n, 1.0, mu)),
                    points=[math.cos(math.radians(theta_c))])
    ctx.compare_jk("water->air R: L_down(0-)/L_up(0-) per band vs band-averaged R_wa", ratio, rwa,
                   labels=band_labels(edges, partial), rel_cap=ctx.pick(0.015, 0.06))
    ctx.exact("water->air beyond the critical angle: L_down/L_up == 1 (TIR)",
              rad.value[beyond] / rad.value[n_t - 1 - beyond], 1.0, rtol=1e-12)

    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    t = np.linspace(0, 89.9, 500)
    ax.plot(t, ref.fresnel(1.0, n, np.cos(np.radians(t))), "C0-", lw=1,
            label="air->water, exact")
    ax.plot(t, ref.schlick(1.0, n, np.cos(np.radians(t))), "C0:", lw=1,
            label="air->water, Schlick (not used)")
    ax.plot(t, ref.fresnel(n, 1.0, np.cos(np.radians(t))), "C1-", lw=1,
            label="water->air, exact")
    ax.errorbar(angles, vals, yerr=errs, fmt="o", color="C0", ms=4,
                label="MC: sun over black water")
    centre = 0.5 * (edges[1:n_t // 2] + edges[2:n_t // 2 + 1])
    allb = np.arange(1, n_t // 2)
    rr = rad[allb] / rad[n_t - 1 - allb]
    ax.errorbar(centre, rr.value, yerr=rr.stderr, fmt="s", color="C1", ms=3,
                label="MC: L_down/L_up under uniform upwelling (band averages)")
    ax.axvline(theta_c, color="grey", ls="--", lw=0.8)
    ax.set_xlabel("angle of incidence (deg)")
    ax.set_ylabel("reflectance")
    ax.set_yscale("log")
    ax.legend(fontsize=7)
    ctx.figure(fig, "fresnel", "Fresnel reflectance of the flat surface from both sides: MC "
               "against the exact unpolarized formula (Schlick's approximation dotted for "
               "scale). Water-side points are band averages over 2.5 deg bands.")
    ctx.note("Air -> water: a sun at theta_s over a clear 1 m layer and a black bottom; "
             "budget/surface_reflection is R(theta_s) (analog mode: a Bernoulli draw per "
             "photon, so a binomial error; implicit mode: exactly R, checked to 1e-9). "
             "Water -> air: a mirror bottom (reflectance 0.5) sends the refracted beam back up at "
             "theta_w, where 1 - Eu_wl(0+)/Eu(0-) is R_wa(theta_w) (computed with the water-side "
             "indices; it equals R_aw(theta_s) by reciprocity) and the water-leaving fraction is "
             "rho (1 - R_aw)(1 - R_wa)/(1 - rho R_wa); and "
             "under uniform upwelling radiance (Lambertian bottom, rho = 1) the ratio of "
             "downward to upward radiance just below the surface, band by band, is the "
             "band-averaged R_wa(theta), exactly 1 beyond the critical angle.")


CASE = Case("fresnel", "Fresnel reflectance from both sides of the surface", case_fresnel,
            "budget/surface_reflection vs R(theta); water->air R by scenes")
