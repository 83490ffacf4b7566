"""The validation cases. Each is a function of a Ctx: it runs its scenes, records checks against
analytic or independent references, draws its figures and writes its notes for the report."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from . import references as ref
from .context import Ctx
from .stats import JK

N_WATER = 1.34
MU_CUT = 0.01   # the tallies' default grazing_mu_cut (config.Tallies)


@dataclass(frozen=True)
class Case:
    name: str
    title: str
    run: Callable[[Ctx], None]
    summary: str


# --- scene and grid helpers ---------------------------------------------------------------------


def clear_layer(thickness: float = 1.0) -> dict:
    return {"thickness_m": thickness, "a": 0.0, "b": 0.0}


def scene(name: str, photons: int, *, layers: list, bottom: dict, sun: float = 30.0,
          diffuse: float = 0.0, sky: str = "uniform", surface: str = "flat",
          depths=(0.0,), theta_edges="hydrolight", phi_bands: int = 24, mode: str = "implicit",
          batches: int | None = None) -> dict:
    cfg = {
        "name": name, "photons": int(photons),
        "illumination": {"Ed0": 1.0, "sun_zenith_deg": float(sun),
                         "diffuse_fraction": float(diffuse), "sky": sky},
        "surface": {"model": surface, "n_water": N_WATER, "fresnel": "exact"},
        "water": {"layers": layers},
        "bottom": bottom,
        "tallies": {"depths_m": [float(d) for d in depths],
                    "theta_edges_deg": theta_edges if isinstance(theta_edges, str)
                    else [float(t) for t in theta_edges],
                    "phi_bands": int(phi_bands)},
        "estimator": {"mode": mode},
    }
    if batches is not None:
        cfg["batches"] = batches
    return cfg


def edges_of(result) -> np.ndarray:
    return np.asarray(result.coords["theta_edges"], dtype=np.float64)


def hemisphere_bands(edges: np.ndarray, up: bool) -> np.ndarray:
    centres = 0.5 * (edges[1:] + edges[:-1])
    return np.nonzero(centres > 90.0 if up else centres < 90.0)[0]


def band_refs(edges: np.ndarray, bands, f, points=None) -> np.ndarray:
    """Expected quad (band) averages of an azimuthally symmetric radiance f(|mu|)."""
    out = []
    for i in bands:
        lo, hi = ref.band_mu(edges[i], edges[i + 1])
        out.append(ref.band_average(f, lo, hi, MU_CUT, points))
    return np.array(out)


def quads(rad: JK, edges: np.ndarray, bands, phi_centres):
    """The distinct quads of the given theta bands (a polar cap counted once): estimates, their
    theta band index and labels."""
    n_t = len(edges) - 1
    ti, pj, labels = [], [], []
    for i in bands:
        cap = i == 0 or i == n_t - 1
        cols = [0] if cap else range(len(phi_centres))
        for j in cols:
            ti.append(i)
            pj.append(j)
            labels.append(f"theta {edges[i]:g}-{edges[i + 1]:g}" +
                          ("" if cap else f" phi {phi_centres[j]:g}"))
    ti = np.array(ti)
    pj = np.array(pj)
    return rad[ti, pj], ti, pj, labels


def expected_counts(ref_vals, ti, edges, per_batch: float, n_phi: int | None) -> np.ndarray:
    """Rough number of photons per batch scoring in each quad (n_phi given) or whole band
    (n_phi None) whose reference radiance is ref_vals: photons x L mu Omega (weights <= 1, so
    this undercounts)."""
    ref_vals = np.asarray(ref_vals, dtype=np.float64)
    n_t = len(edges) - 1
    out = np.empty(len(ti))
    for k, i in enumerate(ti):
        lo, hi = ref.band_mu(edges[i], edges[i + 1])
        cap = i == 0 or i == n_t - 1
        omega = 2.0 * math.pi * (hi - lo) / (1 if (cap or n_phi is None) else n_phi)
        out[k] = per_batch * abs(ref_vals[k]) * 0.5 * (lo + hi) * omega
    return out


def band_labels(edges, bands) -> list[str]:
    return [f"theta {edges[i]:g}-{edges[i + 1]:g}" for i in bands]


def compare_symmetric_radiance(ctx: Ctx, r, rad: JK, edges: np.ndarray, bands, f, *,
                               band_check: str, quad_check: str, quad_cap: tuple[float, float],
                               points=None, band_counts: bool = False) -> np.ndarray:
    """The band averages and every distinct quad of the given theta bands against an
    azimuthally symmetric radiance f(|mu|) (a quad's reference is its band's average); the
    quads' power caps count the photons per quad, the bands' only with band_counts. Returns the
    band references."""
    band_ref = band_refs(edges, bands, f, points)
    per_batch = r.attrs["photons_per_batch"]
    ctx.compare_jk(band_check, rad.mean(axis=-1)[bands], band_ref,
                   labels=band_labels(edges, bands), rel_cap=ctx.pick(0.01, 0.03),
                   counts=expected_counts(band_ref, bands, edges, per_batch, None)
                   if band_counts else None)
    q, ti, _, labels = quads(rad, edges, bands, r.coords["phi"])
    qref = band_ref[np.searchsorted(bands, ti)]
    ctx.compare_jk(quad_check, q, qref, labels=labels, rel_cap=ctx.pick(*quad_cap),
                   counts=expected_counts(qref, ti, edges, per_batch, len(r.coords["phi"])))
    return band_ref


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


# --- 1. BRDF bottoms ----------------------------------------------------------------------------


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
        ax.set_theta_zero_location("N")
        ax.set_theta_direction(-1)
        ax.set_thetamin(-90)
        ax.set_thetamax(90)
        ax.yaxis.set_major_locator(MaxNLocator(3))
        ax.tick_params(labelsize=7)
        ax.set_title(f"{label_m}, theta_i = 30 deg", fontsize=9)
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


# --- 2. optical manhole --------------------------------------------------------------------------


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
    from matplotlib.colors import LogNorm
    fig, axes = plt.subplots(1, 2, subplot_kw={"projection": "polar"}, figsize=(10, 4.6))
    for ax, (title, (rr, ee, rd)) in zip(axes, (
            ("uniform sky, clear water, black bottom", (sky_runs["uniform"][0],
                                                        sky_runs["uniform"][1],
                                                        JK.of(sky_runs["uniform"][0],
                                                              "radiance")[0])),
            ("sun at zenith, Lambertian bottom (rho = 1)", tir_run))):
        dn = hemisphere_bands(ee, up=False)
        phi_e = np.radians(np.asarray(rr.coords["phi_edges"]))
        t_e = np.append(ee[dn], ee[dn[-1] + 1])
        vals = rd.value[dn, :].copy()
        vals = np.where(vals > 0, vals, np.nan)
        finite = vals[np.isfinite(vals)]
        norm = LogNorm(vmin=max(finite.min(), finite.max() * 1e-3), vmax=finite.max())
        if ee[dn[0] + 1] <= 5.0 and "sun" in title:
            vals[0, :] = np.nan    # the transmitted sun's cap: off the scale
            finite = vals[np.isfinite(vals)]
            norm = LogNorm(vmin=finite.min(), vmax=finite.max())
        mesh = ax.pcolormesh(phi_e, t_e, vals, norm=norm, cmap="viridis", shading="flat")
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


# --- 3. Fresnel ----------------------------------------------------------------------------------


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


# --- 4. Beer-Lambert -----------------------------------------------------------------------------


def case_beer_lambert(ctx: Ctx) -> None:
    n = N_WATER
    a = 0.1
    depths = [0.0, 1.0, 2.0, 5.0, 10.0, 20.0]
    photons = ctx.pick(2_000_000, 100_000)
    plot = {}
    for th in (0.0, 30.0, 60.0, 80.0):
        mu = math.cos(math.radians(th))
        t = 1.0 - float(ref.fresnel(1.0, n, mu))
        mu_w = float(ref.refracted_cos(1.0, n, mu))
        z = np.array(depths)
        ed_ref = t * np.exp(-a * z / mu_w)
        layers = [{"thickness_m": 20.0, "a": a, "b": 0.0}]
        r = ctx.simulate(scene(f"pure absorber a = {a}, sun {th:g} (analog)", photons, sun=th,
                               layers=layers, bottom={"model": "black"}, depths=depths,
                               mode="analog", phi_bands=1))
        ed = JK.of(r, "Ed")
        labels = [f"z {d:g} m" for d in depths]
        ctx.compare_jk(f"sun {th:g}: Ed(z) = (1-R) exp(-a z / mu_w)", ed, ed_ref,
                       labels=labels, rel_cap=ctx.pick(0.005, 0.015))
        ctx.compare_jk(f"sun {th:g}: attenuation Ed(z)/Ed(0-) = exp(-a z / mu_w)",
                       ed[1:] / ed[0], ed_ref[1:] / ed_ref[0], labels=labels[1:],
                       rel_cap=ctx.pick(0.005, 0.015))
        eod = JK.of(r, "Eod")
        ctx.compare_jk(f"sun {th:g}: Eod(z) = Ed(z) / mu_w", eod, ed_ref / mu_w,
                       labels=labels, rel_cap=ctx.pick(0.005, 0.015))
        ctx.exact(f"sun {th:g}: Eu(z) == 0", r["Eu"], 0.0)
        ri = ctx.simulate(scene(f"pure absorber, sun {th:g} (implicit)", 200, sun=th,
                                layers=layers, bottom={"model": "black"}, depths=depths,
                                batches=2, phi_bands=1))
        ctx.exact(f"sun {th:g}: implicit Ed(z) == (1-R) exp(-a z / mu_w)", ri["Ed"], ed_ref,
                  rtol=1e-9)
        plot[th] = (ed, ed_ref, mu_w, t)
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    zz = np.linspace(0, 20, 100)
    for c, (th, (ed, ed_ref, mu_w, t)) in enumerate(plot.items()):
        ax.plot(zz, t * np.exp(-a * zz / mu_w), color=f"C{c}", lw=1)
        ax.errorbar(depths, ed.value, yerr=ed.stderr, fmt="o", color=f"C{c}", ms=4,
                    label=f"sun {th:g} deg")
    ax.set_yscale("log")
    ax.set_xlabel("depth z (m)")
    ax.set_ylabel("Ed(z) / Ed(0+)")
    ax.legend(fontsize=8)
    ctx.figure(fig, "ed", "Pure absorber (a = 0.1 /m) under a flat surface: MC Ed(z) (analog, "
               "points) against Ed(0+) (1 - R) exp(-a z / cos theta_w) (lines).")
    ctx.note("A 20 m layer with a = 0.1 /m, b = 0, black bottom, sun only. Analog mode decides "
             "reflection and absorption by draws, giving binomial errors; implicit mode "
             "attenuates the weight exactly (checked deterministically). Eod = Ed / cos theta_w "
             "for a collimated beam; nothing travels up.")


# --- 5. Chandrasekhar ----------------------------------------------------------------------------


CHANDRA_LOCAL = ((180.0, 0.0), (150.0, 0.0), (120.0, 90.0), (100.0, 180.0))


def case_chandrasekhar(ctx: Ctx) -> None:
    ctx.exact("reference: A(w0 = 0.8, mu0 = 0.5) vs 0.36797", ref.chandrasekhar_albedo(0.8, 0.5),
              0.36797, atol=5e-6)
    ctx.exact("reference: L(nadir)/Ed (w0 = 0.8, mu0 = 0.5) vs 0.09586",
              ref.chandrasekhar_radiance(0.8, 0.5, 1.0), 0.09586, atol=5e-6)
    for w0 in (0.5, 0.8, 0.95):
        mus = [0.1, 0.25, 0.5, 1.0]
        ctx.exact(f"reference: H(mu; w0 = {w0}) closed form vs iterated integral equation",
                  [ref.chandrasekhar_h(m, w0) for m in mus],
                  [ref.chandrasekhar_h_iterative(m, w0) for m in mus], rtol=1e-7)

    photons = ctx.pick(3_000_000, 150_000)
    w0s = (0.5, 0.8, 0.95)
    ctx.note("Exact directions (theta, phi of travel) for the local estimate: " +
             ", ".join(f"({t:g}, {p:g})" for t, p in CHANDRA_LOCAL) + "; at w0 = 0.8, "
             "mu0 = 0.5 the nadir value is the DESIGN's 0.09586.")
    mu0s = (1.0, 0.5, 0.25)
    albedo = {}
    curves = {}
    for w0 in w0s:
        for mu0 in mu0s:
            th = math.degrees(math.acos(mu0))
            cfg = scene(f"semi-infinite isotropic, w0 = {w0}, mu0 = {mu0}", photons,
                        sun=th, surface="none",
                        layers=[{"thickness_m": math.inf, "a": 1.0 - w0, "b": w0,
                                 "phase": {"model": "isotropic"}}],
                        bottom={"model": "none"})
            cfg["tallies"]["local_directions_deg"] = [list(d) for d in CHANDRA_LOCAL]
            r = ctx.simulate(cfg)
            tag = f"w0 {w0}, mu0 {mu0}"
            a_ref = ref.chandrasekhar_albedo(w0, mu0)
            wl = JK.of(r, "budget/water_leaving")
            ctx.compare(f"{tag}: plane albedo A = 1 - H(mu0) sqrt(1 - w0)", wl.value, wl.stderr,
                        a_ref, rel_cap=ctx.pick(0.005, 0.015))
            albedo[(w0, mu0)] = (float(wl.value), float(wl.stderr), a_ref)
            edges = edges_of(r)
            up = hemisphere_bands(edges, up=True)
            rad = JK.of(r, "radiance")[0]
            f = (lambda mu, w0=w0, mu0=mu0: float(ref.chandrasekhar_radiance(w0, mu0, mu)))
            band_ref = compare_symmetric_radiance(
                ctx, r, rad, edges, up, f, quad_cap=(0.04, 0.12),
                band_check=f"{tag}: band-averaged reflected radiance L(mu)/Ed",
                quad_check=f"{tag}: quad reflected radiance")
            if mu0 == 0.5:
                curves[w0] = (edges, up, rad.mean(axis=-1), band_ref)
            # exact directions, local (next-event) estimate
            mus = np.array([-math.cos(math.radians(t)) for t, _ in CHANDRA_LOCAL])
            loc = JK.of(r, "local_radiance")[0]
            ctx.compare_jk(f"{tag}: L(mu)/Ed in exact directions (local estimate)", loc,
                           ref.chandrasekhar_radiance(w0, mu0, mus),
                           labels=[f"theta {t:g} phi {p:g}" for t, p in CHANDRA_LOCAL],
                           rel_cap=ctx.pick(0.01, 0.03))
            lo, hi = ref.band_mu(edges[-2], edges[-1])
            cap_ref = ref.band_average(f, lo, hi, MU_CUT)
            method = str(r.attrs.get("Lu_method", ""))
            for name in ("Lu", "Lu_crossing", "Lu_quad"):
                if name not in r:
                    continue
                exact = name == "Lu" and method.startswith("exact nadir")
                lu = JK.of(r, name)[0]
                what = ("exact nadir value L(1)" if exact else
                        f"cap average of L(mu) over {edges[-2]:g}-180 deg")
                ctx.compare(f"{tag}: {name} vs the {what}", lu.value, lu.stderr,
                            float(ref.chandrasekhar_radiance(w0, mu0, 1.0)) if exact else cap_ref,
                            rel_cap=ctx.pick(0.02, 0.06),
                            note=method if name == "Lu" else "crossing estimator")

    plt = _plt()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    mm = np.linspace(0.02, 1, 100)
    for c, w0 in enumerate(w0s):
        ax1.plot(mm, [ref.chandrasekhar_albedo(w0, m) for m in mm], color=f"C{c}", lw=1,
                 label=f"w0 = {w0}")
        pts = [(mu0, *albedo[(w0, mu0)]) for mu0 in mu0s]
        ax1.errorbar([p[0] for p in pts], [p[1] for p in pts], yerr=[p[2] for p in pts],
                     fmt="o", color=f"C{c}", ms=4)
        edges, up, band, band_ref = curves[w0]
        view = 180.0 - 0.5 * (edges[up] + edges[up + 1])
        mu_v = np.cos(np.radians(view))
        ax2.plot(mm, ref.chandrasekhar_radiance(w0, 0.5, mm), color=f"C{c}", lw=1,
                 label=f"w0 = {w0}")
        ax2.errorbar(mu_v, band.value[up], yerr=band.stderr[up], fmt="o", color=f"C{c}", ms=3)
    ax1.set_xlabel("mu0")
    ax1.set_ylabel("plane albedo A(mu0)")
    ax1.legend(fontsize=8)
    ax2.set_xlabel("mu of the reflected ray")
    ax2.set_ylabel("L(mu) / Ed, mu0 = 0.5")
    ax2.legend(fontsize=8)
    ctx.figure(fig, "albedo_radiance", "Semi-infinite isotropic scattering without an interface: "
               "plane albedo (left) and reflected radiance for mu0 = 0.5 (right; MC azimuthal "
               "band averages at band centres, lines: Chandrasekhar's exact solution).")
    ctx.note("An infinitely deep layer with c = 1 /m, w0 = b/c, isotropic phase function, "
             "surface: none. H is computed from Chandrasekhar's closed-form integral with scipy "
             "and cross-checked against the iterated integral equation. The reflected radiance "
             "w0 H(mu) H(mu0) / (4 pi (mu + mu0)) is azimuth-independent, so it is checked on "
             "every upward quad and on azimuthal band averages (references: integrals over mu "
             "of the band, the grazing rule included).")


# --- 6. DISORT -----------------------------------------------------------------------------------

DISORT_SLABS = [
    # tau, w0, g, sun zenith, Lambertian bottom reflectance (0 = black)
    (0.5, 0.9, 0.0, 30.0, 0.0),
    (1.0, 0.99, 0.9, 60.0, 0.3),
    (2.0, 0.5, 0.5, 40.0, 0.8),
    (5.0, 0.95, 0.75, 20.0, 0.0),
    (10.0, 0.99, 0.9, 70.0, 0.5),
]


DISORT_LOCAL = ((180.0, 0.0), (160.0, 0.0), (140.0, 0.0), (140.0, 90.0), (140.0, 180.0),
                (120.0, 0.0), (120.0, 180.0), (100.0, 45.0))


def _disort_slab(ctx: Ctx, slab: tuple, photons: int, estimator: dict | None = None,
                 tag: str = "") -> tuple[str, tuple]:
    """One HG slab of DISORT_SLABS against DISORT: fluxes, every distinct quad, and the local
    estimates in exact directions; returns (name, what the principal-plane figure needs)."""
    from . import disort_ref
    tau, w0, g, sun, rho = slab
    thickness = 2.0
    c = tau / thickness
    bottom = {"model": "lambertian", "reflectance": rho} if rho > 0 else {"model": "black"}
    levels_z = [0.0, thickness / 2, thickness]
    name = f"tau {tau:g}, w0 {w0:g}, g {g:g}, sun {sun:g}, " + \
        (f"Lambertian {rho:g}" if rho > 0 else "black") + " bottom" + tag
    cfg = scene(name, photons, sun=sun, surface="none",
                layers=[{"thickness_m": thickness, "a": (1 - w0) * c, "b": w0 * c,
                         "phase": {"model": "henyey_greenstein", "g": g}}],
                bottom=bottom, depths=levels_z)
    cfg["tallies"]["local_directions_deg"] = [list(d) for d in DISORT_LOCAL]
    if estimator:
        cfg["estimator"] = dict(estimator)
    r = ctx.simulate(cfg)
    edges = edges_of(r)
    phi_edges = np.asarray(r.coords["phi_edges"])
    is_cap = np.zeros(len(edges) - 1, bool)
    is_cap[[0, -1]] = True
    taus = [tau * z / thickness for z in levels_z]
    with disort_ref.single_blas_thread():
        d1 = disort_ref.slab(tau, w0, g, sun, rho, taus, edges, phi_edges, is_cap, MU_CUT,
                             nquad=128)
        d2 = disort_ref.slab(tau, w0, g, sun, rho, taus, edges, phi_edges, is_cap, MU_CUT,
                             nquad=96, n_mu=14, n_phi=12)
    ctx.exact(f"{name}: DISORT Ed(top) = 1 (I0 = 1/mu0, direct beam included)",
              d1["Ed"][0], 1.0, rtol=1e-9)
    if rho > 0:
        ctx.exact(f"{name}: DISORT Eu(bottom) = rho Ed(bottom) (BDRF mode [rho])",
                  d1["Eu"][2], rho * d1["Ed"][2], rtol=1e-6)
    ed = JK.of(r, "Ed")
    eu = JK.of(r, "Eu")
    err_ed = np.abs(d1["Ed"] - d2["Ed"])
    err_eu = np.abs(d1["Eu"] - d2["Eu"])
    sel_ed = [1, 2]
    sel_eu = [0, 1, 2] if rho > 0 else [0, 1]
    lab = ["top", "middle", "bottom"]
    ctx.compare_jk(f"{name}: Ed", ed[sel_ed], d1["Ed"][sel_ed],
                   ref_error=err_ed[sel_ed], labels=[lab[i] for i in sel_ed],
                   rel_cap=ctx.pick(0.01, 0.03))
    ctx.compare_jk(f"{name}: Eu", eu[sel_eu], d1["Eu"][sel_eu],
                   ref_error=err_eu[sel_eu], labels=[lab[i] for i in sel_eu],
                   rel_cap=ctx.pick(0.01, 0.03))
    rad = JK.of(r, "radiance")
    rerr = np.abs(d1["radiance"] - d2["radiance"])
    up = hemisphere_bands(edges, up=True)
    down = hemisphere_bands(edges, up=False)
    groups = [(0, up, "top, upward"), (1, down, "middle, downward"),
              (1, up, "middle, upward"), (2, down, "bottom, downward")]
    if rho > 0:
        groups.append((2, up, "bottom, upward"))
    for lev, bands, where in groups:
        q, idx_t, idx_p, labels = quads(rad[lev], edges, bands, r.coords["phi"])
        qref = d1["radiance"][lev][idx_t, idx_p]
        ctx.compare(f"{name}: quad radiance, {where}", q.value, q.stderr, qref,
                    ref_error=rerr[lev][idx_t, idx_p], labels=labels, loo=q.loo,
                    n_batches=q.n, rel_cap=ctx.pick(0.04, 0.12),
                    counts=expected_counts(qref, idx_t, edges,
                                           r.attrs["photons_per_batch"], len(phi_edges) - 1))
    # exact upward directions (local estimate) against DISORT's intensity at the same points
    mus = np.array([math.cos(math.radians(t)) for t, _ in DISORT_LOCAL])  # of travel
    phis = np.radians([p for _, p in DISORT_LOCAL])
    with disort_ref.single_blas_thread():
        p1 = disort_ref.point_radiance(tau, w0, g, sun, rho, taus, mus, phis, nquad=128)
        p2 = disort_ref.point_radiance(tau, w0, g, sun, rho, taus, mus, phis, nquad=96)
    loc = JK.of(r, "local_radiance")
    lev_sel = [0, 1, 2] if rho > 0 else [0, 1]
    for lev in lev_sel:
        ctx.compare_jk(f"{name}: radiance in exact directions, {lab[lev]} (local estimate)",
                       loc[lev], p1[lev], ref_error=np.abs(p1[lev] - p2[lev]),
                       labels=[f"theta {t:g} phi {p:g}" for t, p in DISORT_LOCAL],
                       rel_cap=ctx.pick(0.02, 0.06))
    return name, (edges, np.asarray(r.coords["phi"]), rad, d1)


def case_disort(ctx: Ctx) -> None:
    from . import disort_ref
    with disort_ref.single_blas_thread():
        peak, back = disort_ref.forward_peak_azimuth_check()
    ctx.exact(f"convention: DISORT downward radiance of a thin forward-scattering slab at "
              f"phi = phi0, {peak:.4g}, exceeds that at phi0 + pi, {back:.4g}, tenfold (phi is the "
              f"travel azimuth)", float(peak / back > 10.0), 1.0)
    photons = ctx.pick(6_000_000, 200_000)
    ppp = dict(_disort_slab(ctx, slab, photons) for slab in DISORT_SLABS)

    plt = _plt()
    fig, axes = plt.subplots(len(ppp), 2, figsize=(11, 3.0 * len(ppp)), squeeze=False)
    for row, (name, (edges, phi, rad, d1)) in enumerate(ppp.items()):
        j0 = int(np.argmin(np.abs(phi - 0)))
        j180 = int(np.argmin(np.abs(phi - 180)))
        centre = 0.5 * (edges[1:] + edges[:-1])
        black = "black" in name
        for col, (lev, label) in enumerate(((0, "top (z = 0), upward"),
                                            (2, "bottom" + (", downward" if black else "")))):
            ax = axes[row][col]
            sel = centre > 90 if lev == 0 else (centre < 90 if black else centre > -1)
            for j, mk, cc in ((j0, "o", "C0"), (j180, "s", "C1")):
                ax.errorbar(centre[sel], rad.value[lev][sel, j], yerr=rad.stderr[lev][sel, j],
                            fmt=mk, ms=3, color=cc, label=f"MC, phi = {phi[j]:g}")
                ax.plot(centre[sel], d1["radiance"][lev][sel, j], "-", color=cc, lw=1,
                        label=f"DISORT, phi = {phi[j]:g}")
            ax.set_yscale("log")
            ax.axvline(90, color="grey", lw=0.6)
            ax.set_title(f"{name}: {label}", fontsize=8)
            ax.set_xlabel("theta of travel from nadir (deg; > 90 = upward)", fontsize=8)
            ax.set_ylabel("quad-average radiance / Ed(0+)", fontsize=8)
            if row == 0 and col == 0:
                ax.legend(fontsize=7)
    fig.tight_layout()
    ctx.figure(fig, "principal_plane", "Quad-average radiance in the sun's vertical plane "
               "(phi = 0 and 180 deg columns) at the top (upward quads) and the bottom of each "
               "slab: MC (points) against DISORT integrated over the same quads (lines). At the "
               "bottom the unscattered sun is in its quad for both.")
    ctx.note("Slabs without a refractive interface (surface: none), 2 m thick with "
             "a = (1 - w0) tau / 2 and b = w0 tau / 2 per m, Henyey-Greenstein phase, sun only. "
             "Levels: top (z = 0), middle, bottom. Compared: Ed (middle, bottom; Ed at the top is "
             "1 by construction), Eu (top, middle, and bottom over a Lambertian bottom), and "
             "every distinct quad of the default HydroLight grid: upward at the top, both ways "
             "in the middle, downward at the bottom (and upward over a Lambertian bottom). "
             "Each z-score includes the reference's own error, |DISORT(128 streams, 10 x 8 "
             "nodes per quad) - DISORT(96 streams, 14 x 12 nodes)|. In addition the local "
             "(next-event) estimates of the radiance in exact upward directions (theta, phi of "
             "travel) " + ", ".join(f"({t:g}, {p:g})" for t, p in DISORT_LOCAL) +
             " at each level are compared with DISORT's intensity at the same points.\n\n"
             "DISORT conventions adopted (PythonicDISORT -> oceanmc):\n\n" +
             "\n".join("- " + line.strip() for line in _disort_conventions()))


# --- 6b. Scattering biased toward straight up ------------------------------------------------------

UPWARD_FRACTION = 0.1
UPWARD_SLABS = [DISORT_SLABS[0], DISORT_SLABS[2], DISORT_SLABS[3]]


def case_upward_bias(ctx: Ctx) -> None:
    photons = ctx.pick(6_000_000, 200_000)
    for slab in UPWARD_SLABS:
        _disort_slab(ctx, slab, photons, {"upward_fraction": UPWARD_FRACTION},
                     tag=", upward-biased scattering")
    ctx.note(f"The DISORT slabs {', '.join(f'tau {s[0]:g}, w0 {s[1]:g}, g {s[2]:g}' for s in UPWARD_SLABS)} "
             f"run with `estimator.upward_fraction: {UPWARD_FRACTION:g}` (cone 15 deg): a "
             "fraction min(0.1, 1 - w0) of scattering events draws its new direction uniformly "
             "in the cone around straight up and the packet carries the defensive-mixture "
             "weight p / ((1 - f) p + f g) (kernel/upward.py). The weights change, the "
             "expectations must not: the same checks as the disort case, against the same "
             "DISORT references (fluxes, every distinct quad, exact-direction local estimates).")


def _disort_conventions() -> list[str]:
    from . import disort_ref
    doc = disort_ref.__doc__.split("Conventions, PythonicDISORT -> oceanmc")[1]
    items, cur = [], ""
    for line in doc.splitlines()[1:]:
        s = line.strip()
        if s.startswith("- "):
            if cur:
                items.append(cur)
            cur = s[2:]
        elif s:
            cur += " " + s
    if cur:
        items.append(cur)
    return items


# --- 7. white furnace ----------------------------------------------------------------------------


def case_white_furnace(ctx: Ctx) -> None:
    layers = [{"thickness_m": 5.0, "a": 0.0, "b": 1.0,
               "phase": {"model": "henyey_greenstein", "g": 0.8}}]
    bottom = {"model": "lambertian", "reflectance": 1.0}
    depths = [0.0, 2.5, 5.0]
    res = {}
    for mode, photons in (("implicit", ctx.pick(2_000_000, 100_000)),
                          ("analog", ctx.pick(600_000, 30_000))):
        r = ctx.simulate(scene(f"white furnace ({mode})", photons, sun=30.0, diffuse=0.3,
                               layers=layers, bottom=bottom, depths=depths, mode=mode))
        res[mode] = r
        out = JK.of(r, "budget/water_leaving") + JK.of(r, "budget/surface_reflection")
        ctx.exact(f"{mode}: absorbed in the water == 0", r["budget/absorbed_layer_1"], 0.0)
        ctx.exact(f"{mode}: absorbed by the bottom == 0", r["budget/absorbed_bottom"], 0.0)
        ctx.exact(f"{mode}: lost below / truncated == 0",
                  [r["budget/lost_below"], r["budget/truncated"]], 0.0)
        if mode == "analog":
            ctx.exact("analog: water_leaving + surface_reflection == 1 (every photon leaves)",
                      out.value, 1.0, rtol=1e-12)
            continue
        ctx.compare_jk("implicit: water_leaving + surface_reflection = 1", out, 1.0,
                       rel_cap=0.01)
        tot = JK.of(r, "budget/total")
        ctx.compare_jk("implicit: budget/total = 1", tot, 1.0, rel_cap=0.01)
        eu_air = JK.of(r, "air/Eu")
        ctx.compare_jk("implicit: Eu(0+) = Ed(0+) = 1", eu_air, 1.0, rel_cap=0.01)
        net = JK.of(r, "Ed") - JK.of(r, "Eu")
        ed = JK.of(r, "Ed")
        ctx.compare_jk("implicit: net flux Ed(z) - Eu(z) = 0 at every depth (relative to Ed)",
                       net / ed, 0.0, labels=[f"z {d:g} m" for d in depths], ref_error=1e-10,
                       note="ref_error 1e-10: floating-point floor (an estimator may make the "
                       "net flux vanish batch by batch, up to rounding)")
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 3.5))
    r = res["implicit"]
    names = ["surface_reflection", "water_leaving", "absorbed_layer_1", "absorbed_bottom",
             "lost_below", "truncated"]
    vals = [float(r[f"budget/{k}"]) for k in names]
    errs = [float(r.stderr(f"budget/{k}")) for k in names]
    ax.bar(names, vals, yerr=errs, color=["C0", "C1", "C2", "C3", "C4", "C5"])
    ax.set_ylabel("fraction of Ed(0+)")
    ax.set_title(f"white furnace (implicit): total = {float(r['budget/total']):.6f} "
                 f"+- {float(r.stderr('budget/total')):.1e}", fontsize=9)
    plt.setp(ax.get_xticklabels(), rotation=20, fontsize=8)
    ctx.figure(fig, "budget", "Energy budget of the white furnace: only surface reflection and "
               "water-leaving light remain, and they add up to Ed(0+).")
    ctx.note("A 5 m layer with a = 0, b = 1 /m (w0 = 1, HG g = 0.8) over a Lambertian bottom of "
             "reflectance 1, under a flat n = 1.34 surface, sun at 30 deg plus a 30 % uniform "
             "sky. Nothing can be absorbed, so everything that enters leaves to the air. In "
             "implicit mode the only noise left is Russian roulette (internal reflections "
             "shrink weights until they play it), so the z-score tests that the roulette is "
             "unbiased; in analog mode each photon leaves whole and the sum is 1 exactly. "
             "Without absorption the net flux Ed - Eu vanishes at every depth.")


# --- 8. reciprocity ------------------------------------------------------------------------------


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


from .brdf_models import case_brdf_models  # noqa: E402  (it uses the helpers above)

CASES = [
    Case("brdf_bottom", "Lambertian and Minnaert bottoms without water", case_brdf,
         "reflected flux vs rho_dh(theta_i), radiance vs (rho/pi)(cos t_i cos t_r)^k"),
    Case("brdf_models", "GGX, Hapke, Lambertian + mirror and table bottoms; the general sampler",
         case_brdf_models, "Eu/Ed vs rho_dh(theta_i) and quad radiance vs quad averages of f, "
         "both integrated numerically from the models' formulas"),
    Case("optical_manhole", "Snell's window, the n^2 law and total internal reflection",
         case_manhole, "radiance below a flat surface under sky and sun; TIR; sky reflectances"),
    Case("fresnel", "Fresnel reflectance from both sides of the surface", case_fresnel,
         "budget/surface_reflection vs R(theta); water->air R by scenes"),
    Case("beer_lambert", "Beer-Lambert attenuation under a flat surface", case_beer_lambert,
         "Ed(z) = (1 - R) exp(-a z / cos theta_w)"),
    Case("chandrasekhar", "Semi-infinite isotropic scattering (Chandrasekhar's H-function)",
         case_chandrasekhar, "plane albedo and reflected radiance"),
    Case("disort", "Slabs against DISORT (PythonicDISORT)", case_disort,
         "fluxes and quad radiances of HG slabs"),
    Case("upward_bias", "Scattering biased toward straight up, against DISORT",
         case_upward_bias, "DISORT slabs rerun with estimator.upward_fraction 0.1: fluxes, "
         "quad radiances, exact-direction local estimates"),
    Case("white_furnace", "White furnace: energy conservation", case_white_furnace,
         "water-leaving + surface reflection = 1"),
    Case("reciprocity", "Reciprocity of the reflection function", case_reciprocity,
         "L(mu; mu0) = L(mu0; mu) per unit Ed(0+), band-averaged both ways"),
]
