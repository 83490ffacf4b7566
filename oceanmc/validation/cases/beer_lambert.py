"""Validation case beer_lambert: Ed(z) = Ed(0+) (1 - R) exp(-a z / cos theta_w) for a pure absorber
under a flat surface."""
from __future__ import annotations

import math

import numpy as np

from .. import references as ref
from ..context import Ctx
from ..stats import JK
from .common import N_WATER, Case, _plt, scene


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


CASE = Case("beer_lambert", "Beer-Lambert attenuation under a flat surface", case_beer_lambert,
            "Ed(z) = (1 - R) exp(-a z / cos theta_w)")
