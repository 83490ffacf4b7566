"""Validation case chandrasekhar: semi-infinite isotropic scattering, plane albedo and reflected
radiance against Chandrasekhar's H-function solution."""
from __future__ import annotations

import math

import numpy as np

from .. import references as ref
from ..context import Ctx
from ..stats import JK
from .common import (MU_CUT, Case, _plt, compare_symmetric_radiance, edges_of,
                     hemisphere_bands, scene)


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
                # quick: the crossing cap estimate at w0 0.5 has a 6-6.5% standard error, so a
                # 6% precision cap failed at 5 of seeds 11-16 on the kernel of 29d7ba3
                what = ("exact nadir value L(1)" if exact else
                        f"cap average of L(mu) over {edges[-2]:g}-180 deg")
                ctx.compare(f"{tag}: {name} vs the {what}", lu.value, lu.stderr,
                            float(ref.chandrasekhar_radiance(w0, mu0, 1.0)) if exact else cap_ref,
                            rel_cap=ctx.pick(0.02, 0.1),
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


CASE = Case("chandrasekhar", "Semi-infinite isotropic scattering (Chandrasekhar's H-function)",
            case_chandrasekhar, "plane albedo and reflected radiance")
