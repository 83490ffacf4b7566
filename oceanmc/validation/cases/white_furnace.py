"""Validation case white_furnace: no absorption anywhere, so everything that enters leaves."""
from __future__ import annotations

from ..context import Ctx
from ..stats import JK
from .common import Case, _plt, scene


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


CASE = Case("white_furnace", "White furnace: energy conservation", case_white_furnace,
            "water-leaving + surface reflection = 1")
