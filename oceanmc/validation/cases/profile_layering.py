"""Validation case profile_layering: a scattering water with a deep chlorophyll maximum (a
gaussian profile, resolved by oceanmc.optics into sublayers within its optical-depth bound)
against the same water as 0.25 m homogeneous layers whose IOPs are computed here from the
published formulas at the layers' exact mean chlorophyll, run independently."""
from __future__ import annotations

import math

import numpy as np

from ..context import Ctx
from ..stats import JK
from .common import Case, _plt, scene

WL = 490.0
PEAK, WIDTH, TOTAL, BACKGROUND = 20.0, 5.0, 30.0, 0.1
THICKNESS = 40.0
STEP = 0.25
# printed 490 nm values: Pope & Fry (1997) a_w; Bricaud et al. (1998) A_phi, E_phi
A_W, A_PHI, E_PHI = 0.0150, 0.0253719, 0.607395


def mean_chl(top: float, bottom: float) -> float:
    s = WIDTH * math.sqrt(2.0)
    mass = 0.5 * TOTAL * (math.erf((bottom - PEAK) / s) - math.erf((top - PEAK) / s))
    return BACKGROUND + mass / (bottom - top)


def fine_layer(top: float) -> dict:
    """One 0.25 m layer: pure water (Pope & Fry 1997; Morel 1974 b_w) plus Case-1 chlorophyll
    (Bricaud et al. 1998 a_ph; Morel & Maritorena 2001 b_p; Morel et al. 2002 bb/b), with the
    phase functions as a b-weighted mixture."""
    chl = mean_chl(top, top + STEP)
    b_w = 0.00288 * (WL / 500.0) ** -4.32
    b_p = 0.416 * chl ** 0.766 * 550.0 / WL
    nu = 0.5 * (math.log10(chl) - 0.3) if chl < 2.0 else 0.0
    ratio = 0.002 + 0.01 * (0.5 - 0.25 * math.log10(chl)) * (WL / 550.0) ** nu
    ratio = float(f"{ratio:.4g}")   # as oceanmc tabulates it
    return {"thickness_m": STEP, "a": A_W + A_PHI * chl ** E_PHI,
            "phase": {"model": "mixture", "components": [
                {"b": b_w, "phase": {"model": "pure_water"}},
                {"b": b_p, "phase": {"model": "fournier_forand", "bb_ratio": ratio}}]}}


def case_profile_layering(ctx: Ctx) -> None:
    photons = ctx.pick(2_000_000, 200_000)
    depths = [0.0, 10.0, 20.0, 30.0]
    common = dict(sun=30.0, surface="flat", bottom={"model": "lambertian", "reflectance": 0.2},
                  depths=depths, phi_bands=1)
    profiled = scene("DCM as a gaussian profile", photons, layers=[{
        "thickness_m": THICKNESS, "components": [
            {"model": "pure_water"},
            {"model": "chlorophyll", "chl_mg_m3": {
                "profile": "gaussian", "background": BACKGROUND, "peak_depth_m": PEAK,
                "width_m": WIDTH, "total_mg_m2": TOTAL}}]}], **common)
    profiled["wavelengths_nm"] = [WL]
    profiled["tallies"]["radiance"] = False
    layered = scene("DCM as 160 layers of 0.25 m", photons,
                    layers=[fine_layer(STEP * k) for k in range(int(THICKNESS / STEP))],
                    **common)
    layered["tallies"]["radiance"] = False
    a, b = ctx.simulate(profiled), ctx.simulate(layered)
    n_sub = len(a.iops["layer_top"])
    labels = [f"z {d:g} m" for d in depths]
    for name in ("Ed", "Eu"):
        ja, jb = JK.of(a, name), JK.of(b, name)
        ctx.compare(f"{name}: profile ({n_sub} sublayers) - fine layering = 0",
                    ja.value - jb.value, np.hypot(ja.stderr, jb.stderr), 0.0, labels=labels,
                    rel_cap=None)
        ctx.exact(f"{name}: relative standard error of the profile run below 3%",
                  float(np.max(ja.stderr / ja.value) < 0.03), 1.0)
    plt = _plt()
    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.6))
    tops = a.iops["layer_top"][:-1] if math.isinf(a.iops["layer_thickness"][-1]) \
        else a.iops["layer_top"]
    left.step(a.iops["c"][:len(tops), 0], tops, where="post", label="sublayers (c, 1/m)")
    fine_c = [fine_layer(STEP * k) for k in range(int(THICKNESS / STEP))]
    left.step([f["a"] + sum(m["b"] for m in f["phase"]["components"]) for f in fine_c],
              STEP * np.arange(len(fine_c)), where="post", lw=0.7, label="0.25 m layers")
    left.invert_yaxis()
    left.set_xlabel("c (1/m)", fontsize=8)
    left.set_ylabel("depth (m)", fontsize=8)
    left.legend(fontsize=7)
    for name, marker in (("Ed", "o"), ("Eu", "s")):
        right.errorbar(depths, a[name], yerr=a.stderr(name), fmt=marker, label=f"{name} profile")
        right.plot(depths, b[name], "-", lw=1, label=f"{name} 0.25 m layers")
    right.set_yscale("log")
    right.set_xlabel("depth (m)", fontsize=8)
    right.legend(fontsize=7)
    fig.tight_layout()
    ctx.figure(fig, "profile", "Left: the attenuation of the resolved sublayers and of the "
               "0.25 m reference layers. Right: Ed and Eu of both runs.")
    ctx.note(f"One 40 m layer of pure water and chlorophyll with a deep maximum (gaussian: "
             f"background {BACKGROUND} mg/m3, peak at {PEAK} m, width {WIDTH} m, "
             f"{TOTAL} mg/m2) over a Lambertian bottom of reflectance 0.2, at {WL:g} nm. "
             f"oceanmc resolved it into {n_sub} sublayers (optical-depth bound "
             "OPTICAL_DEPTH_TOLERANCE per sublayer, optics/column.py); the reference is the "
             "same water as 160 homogeneous 0.25 m layers whose IOPs are computed in this case "
             "from the published formulas at each layer's exact mean chlorophyll, run as an "
             "independent scene. The z-scores compare the two runs (both errors combined).")


CASE = Case("profile_layering", "A depth profile against a fine layering", case_profile_layering,
            "Ed and Eu through a deep chlorophyll maximum resolved into sublayers against the "
            "same water as 0.25 m layers computed from the published formulas")
