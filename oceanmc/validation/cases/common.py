"""What the validation cases share: the Case record, scene and grid helpers, the comparison of an
azimuthally symmetric radiance, and the DISORT slab run by both the disort and the upward_bias
cases."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ...plot import pyplot as _plt  # noqa: F401 (the cases draw their figures through it)
from .. import references as ref
from ..context import Ctx
from ..stats import JK

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


# --- DISORT slabs (the disort and upward_bias cases) --------------------------------------------

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
    from .. import disort_ref
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
