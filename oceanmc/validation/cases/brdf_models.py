"""Validation case brdf_models: the bottom BRDFs beyond Lambertian and Minnaert (GGX microfacets,
Hapke with its hot spot, Lambertian + mirror, measured tables isotropic and anisotropic) and
Lambertian and Minnaert through the general tabulated sampler, on a bottom without water.

Each model's f is written here again from its paper (or, for a table, from README's definition
of the interpolation), never taken from the kernel. The references are integrals of that f over
the tally's quads, by composite Gauss-Legendre rules on panels whose edges hold every place
where f is not smooth (quad edges, the mirror and hot-spot directions, a table's nodes):
  flux      Eu/Ed at the bottom = rho_dh(theta_i) = integral of f cos over the hemisphere;
  radiance  the quad average of f(wi, wo) Ed (Ed = 1 on the bottom), with the crossing
            estimator's grazing rule below |mu| = MU_CUT, and azimuthal band averages.
"""
from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from ...plot import half_polar
from .. import references as ref
from ..context import Ctx
from ..stats import JK
from .common import (MU_CUT, Case, _plt, band_labels, clear_layer, edges_of, hemisphere_bands,
                     quads, scene)

PANEL_THETA_DEG = 1.0    # quad edges, table nodes (3 and 6 deg) and suns are whole degrees
PANEL_PHI_DEG = 2.5      # phi band edges (7.5 + 15 j) and table azimuth nodes (5, 10 deg)
GAUSS_POINTS = 8         # per panel side; the 4-point rule's difference is the error estimate


# --- the models' f, written from the papers (local frame: normal +z, wi towards the source) ---


def ggx_f(alpha: float, n_ratio: float, rho_d: float, fresnel: bool):
    """Walter, Marschner, Li & Torrance 2007 (EGSR), Eq. 20: f = F(wi.h) D(h) G2 / (4 mu_i mu_o),
    D from their Eq. 33, D = alpha^2 / (pi cos^4 t_h (alpha^2 + tan^2 t_h)^2); height-correlated
    G2 = 1 / (1 + Lambda(wi) + Lambda(wo)) (Heitz 2014, JCGT 3(2), Eq. 99) with the GGX
    Lambda(v) = (-1 + sqrt(1 + alpha^2 tan^2 t_v)) / 2 (Heitz Eq. 86); F the exact unpolarized
    Fresnel reflectance into facets of relative index n_ratio (1 when fresnel is off); plus a
    Lambertian rho_d / pi."""
    def lam(mu):
        return 0.5 * (np.sqrt(1.0 + alpha ** 2 * (1.0 - mu * mu) / (mu * mu)) - 1.0)

    def f(wi, wo):
        h = wi + wo
        h = h / np.linalg.norm(h, axis=-1, keepdims=True)
        cos_h = h[..., 2]
        tan2_h = (1.0 - cos_h ** 2) / cos_h ** 2
        d = alpha ** 2 / (math.pi * cos_h ** 4 * (alpha ** 2 + tan2_h) ** 2)
        g2 = 1.0 / (1.0 + lam(wi[2]) + lam(wo[..., 2]))
        facet = ref.fresnel(1.0, n_ratio, np.sum(wi * h, axis=-1)) if fresnel else 1.0
        return facet * d * g2 / (4.0 * wi[2] * wo[..., 2]) + rho_d / math.pi
    return f


def hapke_f(w: float, xi: float, b0: float, width: float):
    """Hapke's bidirectional reflectance r = (w / 4 pi) mu0 / (mu0 + mu) [(1 + B(g)) P(g) +
    H(mu0) H(mu) - 1] (Hapke 1981, J. Geophys. Res. 86, 3039), as a BRDF f = r / mu0; the
    shadow-hiding opposition surge B(g) = B0 / (1 + tan(g/2) / h) (Hapke 1986, Icarus 67, 264);
    Henyey-Greenstein grains P(g) = (1 - xi^2) / (1 + 2 xi cos g + xi^2)^(3/2) in the phase
    angle g (g = 0: back to the source; xi < 0 backward); H(x) = 1 / (1 - w x [r0 + (1 - 2 r0 x)
    / 2 ln((1 + x) / x)]), r0 = (1 - gamma)/(1 + gamma), gamma = sqrt(1 - w) (Hapke 2002,
    Icarus 157, 523, Eq. 13)."""
    gamma = math.sqrt(1.0 - w)
    r0 = (1.0 - gamma) / (1.0 + gamma)

    def h_fn(x):
        return 1.0 / (1.0 - w * x * (r0 + 0.5 * (1.0 - 2.0 * r0 * x) * np.log((1.0 + x) / x)))

    def f(wi, wo):
        g = np.arccos(np.clip(np.sum(wi * wo, axis=-1), -1.0, 1.0))
        p = (1.0 - xi ** 2) / (1.0 + 2.0 * xi * np.cos(g) + xi ** 2) ** 1.5
        surge = b0 / (1.0 + np.tan(0.5 * g) / width)
        mu0, mu = wi[2], wo[..., 2]
        return w / (4.0 * math.pi) / (mu0 + mu) * ((1.0 + surge) * p + h_fn(mu0) * h_fn(mu) - 1.0)
    return f


def minnaert_f(rho: float, k: float):
    """(rho / pi)(mu_i mu_o)^k (Minnaert 1941); k = 0 is Lambertian."""
    def f(wi, wo):
        return ref.minnaert_radiance(rho, k, wi[2], wo[..., 2])
    return f


def skewed_f(rho: float, amplitude: float, phi0_deg: float):
    """An anisotropic, reciprocal test BRDF: (rho/pi)[1 + A sin t_i sin t_o cos(phi_i + phi_o -
    2 phi0)]; symmetric in wi and wo, >= 0 for A <= 1, rho_dh = rho (the cosine averages out
    over phi_o). Lit from phi_i = 180 deg, its lobe leans to dphi = 2 phi0 (out of the plane
    of incidence), which shows whether the table's azimuths are read the right way round."""
    def f(wi, wo):
        s = np.hypot(wi[0], wi[1]) * np.hypot(wo[..., 0], wo[..., 1])
        phi = math.atan2(wi[1], wi[0]) + np.arctan2(wo[..., 1], wo[..., 0])
        return rho / math.pi * (1.0 + amplitude * s * np.cos(phi - 2.0 * math.radians(phi0_deg)))
    return f


def write_table(path: Path, f, theta_step: float, dphi_step: float, theta_max: float,
                phi_i_step: float | None = None) -> Callable:
    """Tabulates f on a grid (isotropic: a CSV of theta_i, theta_r, phi, f rows; anisotropic:
    an .npz with phi_i_deg) as README describes, and returns the table's own BRDF: f multilinear
    in (theta_i, [phi_i], theta_r, dphi) between the nodes, constant beyond the last theta node,
    dphi folded about 180 deg (symmetric tables) or wrapped at 360 deg, phi_i wrapped at 360."""
    theta = np.arange(0.0, theta_max + 1e-9, theta_step)
    dphi = np.arange(0.0, (180.0 if phi_i_step is None else 360.0 - dphi_step) + 1e-9, dphi_step)
    phi_i = None if phi_i_step is None else np.arange(0.0, 360.0 - phi_i_step + 1e-9, phi_i_step)
    ti, pi_, tr, dp = np.meshgrid(np.radians(theta), np.radians([180.0] if phi_i is None
                                                               else phi_i),
                                  np.radians(theta), np.radians(dphi), indexing="ij")
    wi = np.stack([np.sin(ti) * np.cos(pi_), np.sin(ti) * np.sin(pi_), np.cos(ti)], axis=-1)
    po = pi_ + dp
    wo = np.stack([np.sin(tr) * np.cos(po), np.sin(tr) * np.sin(po), np.cos(tr)], axis=-1)
    values = np.empty(ti.shape)
    for idx in np.ndindex(ti.shape[:2]):   # f takes one incidence at a time
        values[idx] = f(wi[idx][0, 0], wo[idx])
    if phi_i is None:
        values = values[:, 0]
        grid = np.meshgrid(theta, theta, dphi, indexing="ij")
        np.savetxt(path, np.column_stack([g.ravel() for g in grid] + [values.ravel()]),
                   delimiter=",", fmt="%.17g", header="theta_i,theta_r,phi,brdf")
        interp = RegularGridInterpolator((theta, theta, dphi), values)
    else:
        np.savez(path, theta_i_deg=theta, phi_i_deg=phi_i, theta_r_deg=theta, phi_deg=dphi,
                 brdf=values)
        wrapped = np.concatenate([values, values[:, :1]], axis=1)
        wrapped = np.concatenate([wrapped, wrapped[..., :1]], axis=3)
        interp = RegularGridInterpolator((theta, np.append(phi_i, 360.0), theta,
                                          np.append(dphi, 360.0)), wrapped)

    def table_f(wi_, wo_):
        t_i = np.full(wo_.shape[:-1], min(math.degrees(math.acos(wi_[2])), theta_max))
        t_r = np.minimum(np.degrees(np.arccos(np.clip(wo_[..., 2], -1.0, 1.0))), theta_max)
        az_i = math.degrees(math.atan2(wi_[1], wi_[0])) % 360.0
        d = (np.degrees(np.arctan2(wo_[..., 1], wo_[..., 0])) - az_i) % 360.0
        if phi_i is None:
            return interp(np.stack([t_i, t_r, np.where(d > 180.0, 360.0 - d, d)], axis=-1))
        return interp(np.stack([t_i, np.full(t_i.shape, az_i), t_r, d], axis=-1))
    return table_f


# --- the models ----------------------------------------------------------------------------


@dataclass(frozen=True)
class Model:
    name: str
    label: str
    bottom: dict
    f: Callable                     # f(wi, wo) in 1/sr: the finite part
    suns: tuple                     # sun zenith angles (deg), full mode
    quick_sun: float
    mirror: float = 0.0             # reflectance of a mirror (delta-function) part
    mode: str = "implicit"
    constant_weight: bool = False   # the sampler's weight is exactly rho_dh: a deterministic flux
    closed_form: Callable | None = None   # rho_dh(mu_i) in closed form: checks the integration
    source: Callable | None = None  # a table's source model (figure only)
    photons_factor: float = 1.0     # more photons where they are cheap or few come back diffusely


HAPKE = dict(albedo=0.7, asymmetry=-0.3, opposition_amplitude=0.8, opposition_width=0.06)


def models(table_dir: Path) -> list[Model]:
    hapke = hapke_f(HAPKE["albedo"], HAPKE["asymmetry"], HAPKE["opposition_amplitude"],
                    HAPKE["opposition_width"])
    skewed = skewed_f(0.4, 0.6, 30.0)
    # Hapke's f ~ 1/(mu0 + mu) is infinite at (90, 90) deg: its table stops at 87 deg
    iso_file, aniso_file = table_dir / "hapke_table.csv", table_dir / "skewed_table.npz"
    iso = write_table(iso_file, hapke, 3.0, 5.0, 87.0)
    aniso = write_table(aniso_file, skewed, 6.0, 10.0, 90.0, phi_i_step=15.0)
    return [
        Model("ggx_rough", "GGX alpha 0.5, F = 1",
              {"model": "ggx", "roughness": 0.5, "fresnel": False}, ggx_f(0.5, 1.0, 0.0, False),
              (0.0, 40.0, 70.0), 40.0),
        Model("ggx_glossy", "GGX alpha 0.1, n 1.5, + Lambertian 0.2",
              {"model": "ggx", "roughness": 0.1, "n_ratio": 1.5, "diffuse_reflectance": 0.2},
              ggx_f(0.1, 1.5, 0.2, True), (0.0, 30.0, 60.0), 30.0),
        Model("hapke", "Hapke w 0.7, xi -0.3, B0 0.8, h 0.06", dict(model="hapke", **HAPKE),
              hapke, (0.0, 30.0, 60.0), 30.0),
        Model("lambertian_specular", "Lambertian 0.3 + mirror 0.4",
              {"model": "lambertian_specular", "diffuse_reflectance": 0.3,
               "specular_reflectance": 0.4}, minnaert_f(0.3, 0.0), (0.0, 40.0, 70.0), 40.0,
              mirror=0.4, mode="analog", photons_factor=5.0),
        Model("table", "table from Hapke (CSV, 3 x 5 deg)",
              {"model": "table", "file": str(iso_file)}, iso, (0.0, 50.0, 70.0), 50.0,
              source=hapke),
        Model("table_anisotropic", "anisotropic table (npz, 6 x 15 x 10 deg)",
              {"model": "table", "file": str(aniso_file)}, aniso, (40.0, 70.0), 40.0,
              source=skewed),
        Model("lambertian_tabulated", "Lambertian 0.5, general sampler",
              {"model": "lambertian", "reflectance": 0.5, "sampling": "tabulated"},
              minnaert_f(0.5, 0.0), (0.0, 60.0), 60.0, constant_weight=True,
              closed_form=lambda mu: ref.minnaert_rho_dh(0.5, 0.0, mu)),
        Model("minnaert_tabulated", "Minnaert 0.8, k 1.5, general sampler",
              {"model": "minnaert", "reflectance": 0.8, "k": 1.5, "sampling": "tabulated"},
              minnaert_f(0.8, 1.5), (30.0, 60.0), 30.0,
              closed_form=lambda mu: ref.minnaert_rho_dh(0.8, 1.5, mu)),
    ]


# --- quad integrals --------------------------------------------------------------------------


def gauss_nodes(edges: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
    """Composite m-point Gauss-Legendre nodes and weights over consecutive panels."""
    x, w = np.polynomial.legendre.leggauss(m)
    lo, hi = edges[:-1, None], edges[1:, None]
    return (0.5 * (hi - lo) * x + 0.5 * (hi + lo)).ravel(), (0.5 * (hi - lo) * w).ravel()


def panels(lo: float, hi: float, step: float, extra=()) -> np.ndarray:
    n = max(1, round((hi - lo) / step))
    cuts = [e for e in extra if lo < e < hi]
    return np.union1d(np.linspace(lo, hi, n + 1), cuts)


def local_view(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Local-frame unit vectors (x, -y, -z of oceanmc's frame) of upward travel directions at
    theta (> 90 deg from nadir), phi (rad); shape (theta, phi, 3)."""
    t, p = np.meshgrid(theta, phi, indexing="ij")
    return np.stack([np.sin(t) * np.cos(p), -np.sin(t) * np.sin(p), -np.cos(t)], axis=-1)


def quad_integrals(model: Model, sun: float, theta_edges: np.ndarray, phi_edges: np.ndarray,
                   m: int) -> tuple[np.ndarray, np.ndarray]:
    """For every upward theta band x phi band: the expected crossing estimate of the quad's
    radiance (integral of f Ed g(mu) dOmega / Omega_q, g = 1 above MU_CUT and 2 mu / MU_CUT
    below it, the tally's grazing rule) and the flux through it (integral of f mu dOmega).
    A polar cap is one quad: its average fills every column, its flux sits in column 0. The
    mirror part adds rho_s to the flux of its quad and rho_s / (mu_s Omega_q) to its average."""
    s = math.radians(sun)
    wi = np.array([-math.sin(s), 0.0, math.cos(s)])   # towards the sun (phi_i = 180 deg)
    n_phi = len(phi_edges) - 1
    grazing_deg = 90.0 + math.degrees(math.asin(MU_CUT))
    phi_panels = np.concatenate([panels(phi_edges[j], phi_edges[j + 1], PANEL_PHI_DEG)[:-1]
                                 for j in range(n_phi)] + [phi_edges[-1:]])
    phi_x, phi_w = gauss_nodes(np.radians(phi_panels), m)
    column = np.repeat(np.arange(n_phi), len(phi_x) // n_phi)
    up = hemisphere_bands(theta_edges, up=True)
    avg = np.zeros((len(up), n_phi))
    flux = np.zeros((len(up), n_phi))
    for k, i in enumerate(up):
        lo, hi = theta_edges[i], theta_edges[i + 1]
        th_x, th_w = gauss_nodes(np.radians(panels(lo, hi, PANEL_THETA_DEG, [grazing_deg])), m)
        mu = -np.cos(th_x)
        d_omega = (th_w * np.sin(th_x))[:, None] * phi_w[None, :]
        f = model.f(wi, local_view(th_x, phi_x))
        g = np.where(mu < MU_CUT, 2.0 * mu / MU_CUT, 1.0)[:, None]
        radiance = np.bincount(column, weights=np.sum(f * g * d_omega, axis=0), minlength=n_phi)
        out = np.bincount(column, weights=np.sum(f * mu[:, None] * d_omega, axis=0),
                          minlength=n_phi)
        mu_lo, mu_hi = ref.band_mu(lo, hi)
        cap = i == len(theta_edges) - 2
        omega = (mu_hi - mu_lo) * np.radians(np.diff(phi_edges))
        if model.mirror and lo < 180.0 - sun <= hi:   # the mirror beam at phi = 0 (column 0)
            j = 0 if cap else int(np.searchsorted(phi_edges, 0.0) - 1)
            radiance[j] += model.mirror / math.cos(s)
            out[j] += model.mirror
        if cap:
            avg[k] = radiance.sum() / omega.sum()
            flux[k, 0] = out.sum()
        else:
            avg[k] = radiance / omega
            flux[k] = out
    return avg, flux


def references(model: Model, sun: float, theta_edges, phi_edges):
    """(quad averages, flux per quad, their error estimates): the GAUSS_POINTS rule, and its
    difference from the rule with half the points on the same panels."""
    avg, flux = quad_integrals(model, sun, theta_edges, phi_edges, GAUSS_POINTS)
    avg_c, flux_c = quad_integrals(model, sun, theta_edges, phi_edges, GAUSS_POINTS // 2)
    return avg, flux, np.abs(avg - avg_c), abs(flux.sum() - flux_c.sum())


# --- the case --------------------------------------------------------------------------------


def case_brdf_models(ctx: Ctx) -> None:
    with tempfile.TemporaryDirectory(prefix="oceanmc_brdf_tables_") as tmp:
        specs = models(Path(tmp))
        photons = ctx.pick(1_000_000, 100_000)
        shown = {}
        worst_ref = 0.0
        for model in specs:
            for sun in (model.suns if not ctx.quick else (model.quick_sun,)):
                r, rad, avg, rel = run_scene(ctx, model, sun,
                                             int(photons * model.photons_factor))
                worst_ref = max(worst_ref, rel)
                if sun > 0.0 and model.name not in shown:   # the first oblique sun
                    shown[model.name] = (model, sun, r, rad, avg)
    figure_f_cos(ctx, specs)
    figure_principal_plane(ctx, shown)
    ctx.note(
        "Scenes: a 1 m layer with a = b = 0 over the bottom, no refractive interface (surface: "
        "none), sun only, unit horizontal irradiance Ed on the bottom; tallies at z = 0, where "
        "the reflected light leaves unchanged. Flux: Eu/Ed against rho_dh(theta_i), the "
        "integral of f cos over the hemisphere. Radiance: every upward quad (and the azimuthal "
        "band averages) against the quad average of f(wi, wo) Ed, including the tally's "
        "grazing rule below |mu| = 0.01. The models' f are written in brdf_models.py from the "
        "papers (GGX: Walter et al. 2007 with Heitz's 2014 height-correlated G2 and exact "
        "Fresnel; Hapke 1981 with the 1986 opposition surge and the 2002 H function), not "
        "taken from the kernel; a table's reference is its own multilinear interpolant (README), "
        "computed with scipy's RegularGridInterpolator from the values written to the file, "
        "CSV for the isotropic table made from the Hapke model above, npz for an anisotropic, "
        "reciprocal one, (rho/pi)[1 + 0.6 sin t_i sin t_o cos(phi_i + phi_o - 60 deg)], "
        "whose lobe leans out of the plane of incidence (read with its azimuths mirrored, its "
        "quads would be off by up to 100%). Hapke and tables are always drawn by "
        "the general tabulated sampler; Lambertian and Minnaert are forced through it with "
        "sampling: tabulated; GGX uses its visible-normal sampler, Lambertian + mirror runs in "
        "analog mode (binomial errors). Implicit-mode weights f cos/pdf vary about rho_dh, "
        "so Eu has a batch error; through the general sampler a Lambertian weight is exactly "
        "rho (checked deterministically).")
    ctx.note(
        f"Integration: composite {GAUSS_POINTS}-point Gauss-Legendre rules in theta and phi on "
        f"panels of {PANEL_THETA_DEG:g} x {PANEL_PHI_DEG:g} deg whose edges include every quad "
        "edge, the grazing cut, the table nodes, the mirror and hot-spot directions (the suns "
        "sit at band centres); the difference from the "
        f"{GAUSS_POINTS // 2}-point rule on the same panels is carried as the references' own "
        f"error (largest relative difference over all quads and fluxes: {worst_ref:.1e}). The "
        "same rules reproduce the closed-form rho_dh of the Lambertian and Minnaert models "
        "(checks named 'reference:'). A mirror part (rho_s) is added exactly: rho_s to the "
        "flux and rho_s / (mu_s Omega_q) to the quad holding the mirror direction.")


def run_scene(ctx: Ctx, model: Model, sun: float, photons: int):
    tag = f"{model.label}, theta_i {sun:g}"
    r = ctx.simulate(scene(f"{model.label}, sun {sun:g}", photons, sun=sun, surface="none",
                           layers=[clear_layer()], bottom=model.bottom, mode=model.mode))
    edges = edges_of(r)
    phi_edges = np.asarray(r.coords["phi_edges"], dtype=np.float64)
    avg, flux, avg_err, rho_err = references(model, sun, edges, phi_edges)
    rho_dh = float(flux.sum())
    if model.closed_form is not None:
        ctx.exact(f"reference: {tag}: integrated rho_dh vs closed form", rho_dh,
                  float(model.closed_form(math.cos(math.radians(sun)))), rtol=1e-9)
    eu = JK.of(r, "Eu")[0] / JK.of(r, "Ed")[0]
    if model.constant_weight:
        ctx.exact(f"{tag}: Eu/Ed == rho_dh (every weight is rho_dh)", eu.value, rho_dh,
                  rtol=1e-9)
    else:
        ctx.compare_jk(f"{tag}: Eu/Ed vs rho_dh", eu, rho_dh, ref_error=rho_err,
                       rel_cap=ctx.pick(0.01, 0.03))
    up = hemisphere_bands(edges, up=True)
    rad = JK.of(r, "radiance")[0]
    # photons per batch through each quad: its share of the reflected flux over the mean weight
    per_photon = r.attrs["photons_per_batch"] / (1.0 if model.mode == "analog" else rho_dh)
    ctx.compare_jk(f"{tag}: band-averaged reflected radiance", rad.mean(axis=-1)[up],
                   avg.mean(axis=1), ref_error=avg_err.mean(axis=1),
                   labels=band_labels(edges, up), rel_cap=ctx.pick(0.01, 0.03),
                   counts=per_photon * flux.sum(axis=1))
    q, ti, pj, labels = quads(rad, edges, up, r.coords["phi"])
    k = np.searchsorted(up, ti)
    ctx.compare_jk(f"{tag}: quad radiance", q, avg[k, pj], ref_error=avg_err[k, pj],
                   labels=labels, rel_cap=ctx.pick(0.04, 0.12),
                   counts=per_photon * flux[k, pj])
    rel = max(rho_err / rho_dh, float(np.max(avg_err / avg)))
    return r, rad, avg, rel


# --- figures ---------------------------------------------------------------------------------

FIGURE_SUNS = (0.0, 30.0, 60.0, 75.0)


def plane_of_incidence(sun: float, theta_r: np.ndarray):
    """wi and the outgoing directions in the plane of incidence: theta_r > 0 forward (the mirror
    side, phi = 0 in oceanmc), < 0 back towards the source (phi = 180 deg)."""
    s = math.radians(sun)
    wi = np.array([-math.sin(s), 0.0, math.cos(s)])
    t = np.radians(theta_r)
    return wi, np.stack([np.sin(t), np.zeros_like(t), np.cos(t)], axis=-1)


def figure_f_cos(ctx: Ctx, specs: list[Model]) -> None:
    plt = _plt()
    from matplotlib.ticker import MaxNLocator
    cols = 4
    rows = -(-len(specs) // cols)
    fig, axes = plt.subplots(rows, cols, subplot_kw={"projection": "polar"},
                             figsize=(4.2 * cols, 3.9 * rows))
    theta_r = np.linspace(-89.9, 89.9, 721)
    for ax, model in zip(axes.ravel(), specs):
        peaks = []
        for c, sun in enumerate(FIGURE_SUNS):
            wi, wo = plane_of_incidence(sun, theta_r)
            y = model.f(wi, wo) * wo[:, 2]
            ax.plot(np.radians(theta_r), y, color=f"C{c}", lw=1.2,
                    label=f"theta_i = {sun:g} deg")
            if model.source is not None:
                ax.plot(np.radians(theta_r), model.source(wi, wo) * wo[:, 2], color=f"C{c}",
                        lw=0.8, ls=":")
            peaks.append(float(np.max(y)))
        top = max(peaks)
        log_radius = top > 10.0 * min(peaks)   # a glossy lobe would flatten the other curves
        if model.mirror:
            for c, sun in enumerate(FIGURE_SUNS):
                ax.annotate("", xy=(math.radians(sun), top), xytext=(0.0, 0.0),
                            arrowprops={"arrowstyle": "->", "color": f"C{c}", "lw": 0.8})
        if log_radius:
            ax.set_rscale("log")
            ax.set_ylim(1e-3 * top, 1.5 * top)
        else:
            ax.set_ylim(0.0, 1.1 * top)
            ax.yaxis.set_major_locator(MaxNLocator(3))
        half_polar(ax, model.label + (" (log radius)" if log_radius else "")
                   + (" (arrows: the mirror)" if model.mirror else ""))
    for ax in axes.ravel()[len(specs):]:
        ax.set_visible(False)
    fig.legend(*axes.ravel()[0].get_legend_handles_labels(), loc="lower center", ncol=4,
               fontsize=8)
    ctx.figure(fig, "f_cos", "f(theta_i, theta_r) cos(theta_r) (1/sr) in the plane of incidence "
               "at incidence 0, 30, 60 and 75 deg, from the formulas in brdf_models.py (angle: "
               "theta_r; forward, the mirror side, to the right; back towards the source to the "
               "left). Tables: their multilinear interpolant (solid) and the model they were "
               "made from (dotted); the anisotropic table is lit from phi_i = 180 deg, as a sun "
               "in oceanmc. Arrows: the mirror part of Lambertian + mirror.")


def figure_principal_plane(ctx: Ctx, shown: dict) -> None:
    plt = _plt()
    cols = 4
    rows = -(-len(shown) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.2 * rows))
    for ax, (model, sun, r, rad, avg) in zip(axes.ravel(), shown.values()):
        edges = edges_of(r)
        up = hemisphere_bands(edges, up=True)
        view = 180.0 - 0.5 * (edges[up] + edges[up + 1])   # zenith angle of the reflected ray
        phi = np.asarray(r.coords["phi"])
        columns = [int(np.argmin(np.abs(phi - target))) for target in (0.0, 180.0)]
        for sign, j, colour in zip((1.0, -1.0), columns, ("C0", "C1")):
            ax.errorbar(sign * view, rad.value[up, j], yerr=rad.stderr[up, j], fmt="o", ms=3,
                        color=colour, label=f"MC quads, phi = {phi[j]:g}")
            ax.plot(sign * view, avg[:, j], "kx", ms=5)
        wi, wo = plane_of_incidence(sun, np.linspace(-89.9, 89.9, 721))
        ax.plot(np.degrees(np.arctan2(wo[:, 0], wo[:, 2])), model.f(wi, wo), "k-", lw=0.7)
        ax.set_yscale("log")   # f near the horizon and the mirror quad span decades
        ax.set_ylim(0.5 * avg[:, columns].min(), 2.0 * avg[:, columns].max())
        ax.set_xlim(-90, 90)
        ax.tick_params(labelsize=7)
        ax.set_title(f"{model.label}, sun {sun:g} deg", fontsize=8)
    for ax in axes.ravel()[len(shown):]:
        ax.set_visible(False)
    axes.ravel()[0].legend(fontsize=7)
    ctx.figure(fig, "principal_plane", "Reflected radiance per unit Ed on the bottom in the "
               "principal plane (x: zenith angle of the reflected ray, forward/phi = 0 to the "
               "right, back/phi = 180 to the left): MC quad averages (points, 1 sigma) against "
               "the integrated reference quad averages (crosses) and f itself at the exact "
               "directions (line; the Lambertian + mirror quad holding the mirror beam is the "
               "cross far above it).")


CASE = Case("brdf_models", "GGX, Hapke, Lambertian + mirror and table bottoms; the general sampler",
            case_brdf_models, "Eu/Ed vs rho_dh(theta_i) and quad radiance vs quad averages of f, "
            "both integrated numerically from the models' formulas")
