"""Validation case disort: Henyey-Greenstein slabs against PythonicDISORT (fluxes, every
distinct quad, exact-direction local estimates); the conventions that map DISORT onto oceanmc
go into the report."""
from __future__ import annotations

import numpy as np

from ..context import Ctx
from .common import DISORT_LOCAL, DISORT_SLABS, Case, _disort_slab, _plt


def case_disort(ctx: Ctx) -> None:
    from .. import disort_ref
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


def _disort_conventions() -> list[str]:
    from .. import disort_ref
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


CASE = Case("disort", "Slabs against DISORT (PythonicDISORT)", case_disort,
            "fluxes and quad radiances of HG slabs")
