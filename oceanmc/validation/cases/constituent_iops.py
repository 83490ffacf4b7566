"""Validation case constituent_iops: the IOPs oceanmc makes of each constituent against the
published formulas and printed values, recomputed here from the papers' equations."""
from __future__ import annotations

import math

import numpy as np

from ..context import Ctx
from .common import Case, _plt

WL = np.array([412.0, 443.0, 490.0, 555.0, 670.0])
# pure-water a_w (1/m) as printed: Pope & Fry (1997) at 490 and 670 nm (OMLC table, 1/cm x 100);
# at 412 nm, below the 420 nm where the IOCCG Protocols (2018)'s spectrum takes Pope & Fry up,
# Morel et al. (2007) Table 2a, 0.0046 at both 410 and 415 nm
PURE_WATER_A = {412.0: (0.0046, "Morel et al. 2007"), 490.0: (0.0150, "Pope & Fry 1997"),
                670.0: (0.439, "Pope & Fry 1997")}


def _config(components):
    import oceanmc
    return oceanmc.load_config({"wavelengths_nm": WL.tolist(), "water": {"layers": [
        {"thickness_m": math.inf, "components": components}]}, "bottom": {"model": "none"}})


def case_constituent_iops(ctx: Ctx) -> None:
    from ... import optics
    (water,) = optics.column_iops(_config([{"model": "pure_water"}]))
    for wl, (a, source) in PURE_WATER_A.items():
        k = int(np.nonzero(WL == wl)[0][0])
        ctx.exact(f"pure water: a_w({wl:g} nm) = {a} 1/m ({source})", water.a[k], a, rtol=1e-9)
    ctx.exact("pure water: b_w = 0.00288 (lambda/500)^-4.32 (Morel 1974)", water.b,
              0.00288 * (WL / 500.0) ** -4.32, rtol=1e-12)
    ctx.exact("pure water: bb_w / b_w = 1/2", water.bb / water.b, 0.5, rtol=1e-12)

    for chl in (0.03, 0.3, 3.0):
        (ph,) = optics.column_iops(_config([{"model": "chlorophyll", "chl_mg_m3": chl}]))
        k = int(np.nonzero(WL == 490.0)[0][0])
        # Bricaud et al. (1998) 490 nm row: A_phi = 0.0253719, E_phi = 0.607395 (printed)
        ctx.exact(f"chlorophyll {chl:g}: a_ph(490) = 0.0253719 Chl^0.607395 (Bricaud 1998)",
                  ph.a[k], 0.0253719 * chl ** 0.607395, rtol=1e-6)
        ctx.exact(f"chlorophyll {chl:g}: b_p = 0.416 Chl^0.766 (550/lambda) (Morel & "
                  "Maritorena 2001)", ph.b, 0.416 * chl ** 0.766 * 550.0 / WL, rtol=1e-12)
        nu = 0.5 * (math.log10(chl) - 0.3) if chl < 2.0 else 0.0
        ratio = 0.002 + 0.01 * (0.5 - 0.25 * math.log10(chl)) * (WL / 550.0) ** nu
        ctx.exact(f"chlorophyll {chl:g}: bb_p/b_p (Morel et al. 2002), carried to 4 digits",
                  ph.bb / ph.b, ratio, rtol=5e-4)

    (g,) = optics.column_iops(_config([{"model": "cdom", "a440": 0.1, "slope": 0.017}]))
    ctx.exact("cdom: a_g = a440 exp(-S (lambda - 440))", g.a,
              0.1 * np.exp(-0.017 * (WL - 440.0)), rtol=1e-12)
    ctx.exact("cdom: no scattering", g.b, 0.0, atol=0.0)
    (p,) = optics.column_iops(_config([{"model": "particles", "b550": 1.2, "exponent": 0.5,
                                        "bb_ratio": 0.019, "a443": 0.05, "slope": 0.0123}]))
    ctx.exact("particles: a = a443 exp(-S (lambda - 443))", p.a,
              0.05 * np.exp(-0.0123 * (WL - 443.0)), rtol=1e-12)
    ctx.exact("particles: b = b550 (550/lambda)^n", p.b, 1.2 * (550.0 / WL) ** 0.5, rtol=1e-12)
    ctx.exact("particles: bb = bb_ratio b", p.bb, 0.019 * p.b, rtol=1e-12)
    wl = np.arange(400.0, 701.0, 5.0)
    plt = _plt()
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6))
    import oceanmc
    for label, comps in (("pure water", [{"model": "pure_water"}]),
                         ("Chl 0.1", [{"model": "chlorophyll", "chl_mg_m3": 0.1}]),
                         ("Chl 1", [{"model": "chlorophyll", "chl_mg_m3": 1.0}]),
                         ("Chl 10", [{"model": "chlorophyll", "chl_mg_m3": 10.0}]),
                         ("CDOM a440 0.1", [{"model": "cdom", "a440": 0.1}])):
        (iop,) = optics.column_iops(oceanmc.load_config({
            "wavelengths_nm": wl.tolist(), "water": {"layers": [
                {"thickness_m": math.inf, "components": [{"model": "pure_water"}] + comps
                 if label != "pure water" else comps}]}, "bottom": {"model": "none"}}))
        left.semilogy(wl, iop.a, label=label)
        right.semilogy(wl, iop.bb, label=label)
    left.set_title("absorption a (1/m), pure water included", fontsize=9)
    right.set_title("backscattering bb (1/m)", fontsize=9)
    for ax in (left, right):
        ax.set_xlabel("wavelength (nm)", fontsize=8)
        ax.legend(fontsize=7)
    fig.tight_layout()
    ctx.figure(fig, "spectra", "Absorption and backscattering of pure water and of pure water "
               "with Case-1 chlorophyll (0.1, 1, 10 mg/m3) or CDOM, as oceanmc.optics makes them.")
    ctx.note("Each constituent model evaluated by oceanmc.optics at 412, 443, 490, 555 and "
             "670 nm against its published formula, recomputed here, and the printed table "
             "values (Pope & Fry 1997 and Morel et al. 2007 a_w; Bricaud et al. 1998 A_phi, "
             "E_phi at 490 nm). The chlorophyll model's backscatter fraction is carried by "
             "Fournier-Forand phase functions tabulated at 4 significant digits of bb/b.")


CASE = Case("constituent_iops", "IOPs of each constituent model against the published formulas",
            case_constituent_iops,
            "pure water (Pope & Fry 1997, Morel et al. 2007, Morel 1974), chlorophyll "
            "(Bricaud et al. 1998, Morel & Maritorena 2001, Morel et al. 2002), CDOM and "
            "particles at five wavelengths")
