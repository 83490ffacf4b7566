"""Validation case realistic_phase: slabs of Petzold, Fournier-Forand and pure-water scatterers
against PythonicDISORT, the phase functions given to DISORT as their Legendre moments (600, from
the tables the kernel samples), with delta-M truncation; no refractive surface."""
from __future__ import annotations

import math

import numpy as np

from ...scene import phase_tables
from ..context import Ctx
from ..stats import JK
from .common import MU_CUT, Case, _plt, scene

N_MOMENTS = 600


def legendre_moments(psi: np.ndarray, q: np.ndarray, count: int = N_MOMENTS) -> np.ndarray:
    """chi_l = integral of q(psi) P_l(cos psi) dpsi for a density q per unit scattering angle
    that is piecewise linear between the nodes psi (phase_tables' convention), on the nodes plus
    a uniform grid fine enough for P_l up to l = count (trapezoidal rule)."""
    fine = np.union1d(psi, np.linspace(0.0, math.pi, 40 * count + 1))
    dens = np.interp(fine, psi, q)
    x = np.cos(fine)
    weights = np.concatenate([[0.0], np.diff(fine)])
    weights = 0.5 * (weights + np.concatenate([np.diff(fine), [0.0]]))
    out = np.empty(count)
    p_prev, p_cur = np.ones_like(x), x.copy()
    out[0] = np.sum(weights * dens)
    out[1] = np.sum(weights * dens * p_cur)
    for n in range(1, count - 1):   # Bonnet's recursion
        p_prev, p_cur = p_cur, ((2 * n + 1) * x * p_cur - n * p_prev) / (n + 1)
        out[n + 1] = np.sum(weights * dens * p_cur)
    return out / out[0]


def pure_water_table(beta: float = 0.835) -> tuple[np.ndarray, np.ndarray]:
    """Pure sea water, p ~ 1 + 0.835 cos^2 (Morel 1974), as a density per unit angle."""
    psi = np.linspace(0.0, math.pi, 4001)
    q = (1.0 + beta * np.cos(psi) ** 2) * np.sin(psi)
    return psi, q / np.trapezoid(q, psi)


SLABS = [
    # name, phase config, (psi, q) of what the kernel samples, tau, w0, sun zenith
    ("Petzold", {"model": "petzold"}, lambda: phase_tables.petzold_table()[:2], 3.0, 0.85, 30.0),
    ("Fournier-Forand bb/b 0.01", {"model": "fournier_forand", "bb_ratio": 0.01},
     lambda: phase_tables.fournier_forand_table(0.01)[:2], 3.0, 0.9, 50.0),
    ("pure water 440 nm (a 0.00635, b 0.00498 1/m)", {"model": "pure_water"}, pure_water_table,
     40.0, 0.00498 / (0.00498 + 0.00635), 20.0),
]


def case_realistic_phase(ctx: Ctx) -> None:
    from .. import disort_ref
    photons = ctx.pick(4_000_000, 200_000)
    plt = _plt()
    fig, axes = plt.subplots(1, len(SLABS), figsize=(4.0 * len(SLABS), 3.4))
    for ax, (name, phase, table, tau, w0, sun) in zip(axes, SLABS):
        thickness = 2.0
        c = tau / thickness
        levels = [0.0, thickness / 2, thickness]
        moments = legendre_moments(*table())
        g_kernel, bb_kernel = phase_tables.moments(*table())
        ctx.exact(f"{name}: Legendre moment chi_1 = g of the sampled table", moments[1],
                  g_kernel, rtol=1e-4, atol=1e-6)
        cfg = scene(f"{name}: tau {tau:g}, w0 {w0:.3g}, sun {sun:g}", photons, sun=sun,
                    surface="none", layers=[{"thickness_m": thickness, "a": (1 - w0) * c,
                                             "b": w0 * c, "phase": phase}],
                    bottom={"model": "black"}, depths=levels, phi_bands=1)
        cfg["tallies"]["radiance"] = False
        r = ctx.simulate(cfg)
        taus = [tau * z / thickness for z in levels]
        edges = np.array([0.0, 90.0, 180.0])
        with disort_ref.single_blas_thread():
            d1 = disort_ref.slab(tau, w0, moments, sun, 0.0, taus, edges, [0.0, 360.0],
                                 np.array([True, True]), MU_CUT, nquad=128, n_mu=2, n_phi=1)
            d2 = disort_ref.slab(tau, w0, moments, sun, 0.0, taus, edges, [0.0, 360.0],
                                 np.array([True, True]), MU_CUT, nquad=96, n_mu=2, n_phi=1)
        labels = ["top", "middle", "bottom"]
        # the deep pure water (tau 40): only the light reflected at the top is measurable
        ed_at, eu_at = ([], [0]) if tau > 10.0 else ([1, 2], [0, 1])
        if ed_at:
            ctx.compare_jk(f"{name}: Ed", JK.of(r, "Ed")[ed_at], d1["Ed"][ed_at],
                           ref_error=np.abs(d1["Ed"] - d2["Ed"])[ed_at],
                           labels=[labels[i] for i in ed_at], rel_cap=ctx.pick(0.01, 0.03))
        ctx.compare_jk(f"{name}: Eu", JK.of(r, "Eu")[eu_at], d1["Eu"][eu_at],
                       ref_error=np.abs(d1["Eu"] - d2["Eu"])[eu_at],
                       labels=[labels[i] for i in eu_at], rel_cap=ctx.pick(0.01, 0.05))
        for key, marker in (("Ed", "o"), ("Eu", "s")):
            ax.errorbar(levels, r[key], yerr=r.stderr(key), fmt=marker, ms=4,
                        label=f"MC {key}")
            ax.plot(levels, d1[key], "-", lw=1, label=f"DISORT {key}")
        ax.set_yscale("log")
        ax.set_title(name, fontsize=8)
        ax.set_xlabel("depth (m)", fontsize=8)
        ax.legend(fontsize=7)
    fig.tight_layout()
    ctx.figure(fig, "fluxes", "Ed and Eu against depth in each slab: MC (points, with standard "
               "errors) and DISORT with the phase function's Legendre moments (lines).")
    ctx.note("Slabs 2 m thick without a refractive interface (surface: none) over a black "
             "bottom, sun only, with the phase functions users run: Petzold's average particle "
             "(the kernel's table), Fournier-Forand (bb/b = 0.01, the kernel's table) and pure "
             "sea water (Morel 1974, 1 + 0.835 cos^2; tau 40 stands for the clearest deep "
             "water: Eu at the top is its irradiance reflectance). DISORT (PythonicDISORT) gets "
             "each phase function as 600 Legendre moments integrated from the same table, with "
             "delta-M truncation at 128 streams and Nakajima-Tanaka corrections; the "
             "reference's own error is |DISORT(128) - DISORT(96)|. Compared: Ed (middle, "
             "bottom) and Eu (top, middle); for the pure water Eu at the top only (below it "
             "the sun's light is exp(-40) of what entered).")


CASE = Case("realistic_phase", "Petzold, Fournier-Forand and pure-water slabs against DISORT",
            case_realistic_phase,
            "Ed and Eu of slabs with the phase functions of real water (Petzold, "
            "Fournier-Forand, pure water) against DISORT with 600 Legendre moments and delta-M")
