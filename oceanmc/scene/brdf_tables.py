"""Bottom BRDFs for the kernel: the packed parameter array, measured tables read from files, the
general sampler's tables, and the physical checks, all once per scene (never per ray).

The parameter array (kernel/models.py): model scalars in slots 0..7, a header (slot 8: 1 when
the general tabulated sampler is used; 9: offset of its tables; 10: offset of a measured table),
then the tables themselves, flattened float64.

General tabulated sampler (kernel/brdf/general.py). For every node of a grid of incident angles
(theta_i every 2 deg, 0..90; anisotropic BRDFs: every 5 deg times phi_i every 15 deg) the
integral of f cos over every outgoing cell (theta_o bands of 2 deg times dphi bands of 5 deg;
anisotropic 3 x 7.5 deg) is computed with an m x m Gauss rule per cell (m = 4; GGX 8 to 12);
their sum is rho_dh at the node. Their normalised values, mixed with 1% of the
cosine-weighted density, are the sampler's cell probabilities; within a cell it samples the
density proportional to cos(theta_o). An incidence between nodes draws from one of the two
neighbouring nodes with the linear-interpolation weights, and the packet's weight is
f cos / pdf with the exact mixture pdf. The expectation of the weight is therefore rho_dh(wi)
exactly, whatever the grid; the grid sets only how constant the weight is. Measured by
tests/test_brdf_models.py (200,000 samples at 0, 45 and 76 deg): Lambertian through this path
gives weight == rho to 1e-12; the weight's spread (standard deviation / mean) is 2% for Minnaert
k = 1.5, 0.5-1.7% for Hapke and tables, 5-11% for GGX (alpha = 0.15) up to 45 deg and 43% at
76 deg (its lobe narrows towards the horizon); the mean weight matched rho_dh from independent
quadratures within |z| < 3 everywhere. The tabulated rho_dh at the nodes agrees with the closed
forms to 1e-6 (Minnaert) and 1e-5 (GGX up to 70 deg, 1e-3 at grazing incidence).

Physical checks (unless bottom.allow_unphysical): f >= 0 at every quadrature point, reciprocity
f(i, o) = f(o, i) on a grid of direction pairs (relative tolerance 1e-6 for analytic models; for
measured tables reciprocity_tolerance, at the table's own nodes), and rho_dh <= 1 + 1e-3 at every
incident node. Lambertian and Minnaert with their own samplers are physical by their formulas
and the schema's ranges (rho <= 1, k >= 0: rho_dh = 2 rho cos^k / (k + 2) <= 1), so they skip
the numerical check.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import config as cfg
from .. import registry
from ..config import ConfigError
from ..kernel import models
from ..kernel.brdf import tables as ktables
from ..config.loading import file_problem
from .phase_tables import (ARRAY_FILE_ERRORS, TableError, hdf5_arrays, is_real, npz_arrays,
                           numeric_rows)

ENERGY_TOLERANCE = 1e-3
ANALYTIC_RECIPROCITY = 1e-6
DEFENSIVE = 0.01          # share of the cosine-weighted density mixed into the sampler's cells
# the largest value of a measured table: a glossy lobe of a milliradian reaches ~1e5 1/sr; with
# bottom.allow_unphysical, values of 1e100 carried weights past 1e308 (NaN results)
MAX_TABLE_BRDF = 1e6

# (n_ti, n_pi, n_t, n_p) of the sampler grid
ISOTROPIC_GRID = (46, 1, 45, 72)
ANISOTROPIC_GRID = (19, 24, 30, 48)
LAST_NODE_DEG = 89.5      # the grazing node's table is computed just inside the horizon


# --- measured tables --------------------------------------------------------------------------

def _fail(path, problem: str):
    raise TableError(f"BRDF table {path}: {problem}")


def _load_arrays(path: Path) -> dict[str, np.ndarray]:
    suffix = path.suffix.lower()
    if suffix == ".npz":
        try:
            return npz_arrays(path)
        except ARRAY_FILE_ERRORS as exc:
            _fail(path, f"cannot read it as .npz ({exc})")
    if suffix in (".h5", ".hdf5", ".he5"):
        try:
            return hdf5_arrays(path)
        except ARRAY_FILE_ERRORS as exc:
            _fail(path, f"cannot read it as HDF5 ({exc})")
    if suffix in (".csv", ".txt", ".dat"):
        return _text_table(path)
    _fail(path, f"unknown file type {suffix!r}; use .npz, .h5/.hdf5 or .csv/.txt")


def _text_table(path: Path) -> dict[str, np.ndarray]:
    """Rows of (theta_i, theta_r, dphi, f) or (theta_i, phi_i, theta_r, dphi, f), degrees, on a
    complete grid; '#' comments and one header line are skipped."""
    rows = []
    for lineno, values in numeric_rows(path, "BRDF table"):
        if len(values) not in (4, 5) or (rows and len(values) != len(rows[0])):
            _fail(path, f"line {lineno}: expected 4 columns (theta_i, theta_r, dphi, f) or 5 "
                        f"(theta_i, phi_i, theta_r, dphi, f), got {len(values)}")
        rows.append(values)
    if not rows:
        _fail(path, "is empty (no data rows)")
    table = np.array(rows)
    if not np.all(np.isfinite(table)):
        _fail(path, "contains NaN or inf")
    names = ["theta_i_deg", "theta_r_deg", "phi_deg"] if table.shape[1] == 4 else \
        ["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_deg"]
    axes = [np.unique(table[:, k]) for k in range(len(names))]
    shape = tuple(len(a) for a in axes)
    if int(np.prod(shape)) != len(table):
        _fail(path, f"the rows do not form a complete grid: {len(table)} rows for "
                    f"{' x '.join(str(n) for n in shape)} distinct angles")
    idx = tuple(np.searchsorted(a, table[:, k]) for k, a in enumerate(axes))
    values = np.full(shape, np.nan)
    values[idx] = table[:, -1]
    if np.isnan(values).any():
        _fail(path, "the rows do not form a complete grid (an angle combination repeats)")
    out = dict(zip(names, axes))
    out["brdf"] = values
    return out


def _axis(path, data: dict, name: str, lo: float, hi: float, minimum: int) -> np.ndarray:
    if name not in data:
        _fail(path, f"no array {name!r} (needed: theta_i_deg, theta_r_deg, phi_deg, brdf; "
                    "phi_i_deg for an anisotropic table)")
    a = np.asarray(data[name])
    if not is_real(a):
        _fail(path, f"{name} is not real numbers ({a.dtype})")
    a = a.astype(np.float64)
    if a.ndim != 1:
        _fail(path, f"{name} must be one-dimensional, got shape {a.shape}")
    if a.size < minimum:
        _fail(path, f"{name} needs at least {minimum} value(s), got {a.size}")
    if not np.all(np.isfinite(a)):
        _fail(path, f"{name} contains NaN or inf")
    if a[0] < lo or a[-1] > hi:
        _fail(path, f"{name} must lie in {lo:g}..{hi:g} deg, got {a.min():g}..{a.max():g}")
    if np.any(np.diff(a) <= 0.0):
        bad = int(np.argmin(np.diff(a) > 0.0)) + 1
        _fail(path, f"{name} must increase strictly ({a[bad]:g} after {a[bad - 1]:g} at index "
                    f"{bad})")
    return a


def read_brdf_table(path) -> dict:
    """The measured BRDF in a file: a dict with theta_i, phi_i (None when isotropic), theta_r,
    phi (deg) and f, checked; every problem is a TableError naming the file."""
    path = Path(str(path))
    problem = file_problem(path)
    if problem:
        _fail(path, problem)
    if path.stat().st_size == 0:
        _fail(path, "is empty")
    data = _load_arrays(path)
    if "brdf" not in data:
        _fail(path, "no array 'brdf' (needed: theta_i_deg, theta_r_deg, phi_deg, brdf; "
                    "phi_i_deg for an anisotropic table)")
    f = np.asarray(data["brdf"])
    if f.size == 0:
        _fail(path, "the array 'brdf' is empty")
    if not is_real(f):
        _fail(path, f"the array 'brdf' is not real numbers ({f.dtype})")
    f = f.astype(np.float64)
    theta_i = _axis(path, data, "theta_i_deg", 0.0, 90.0, 2)
    theta_r = _axis(path, data, "theta_r_deg", 0.0, 90.0, 2)
    phi = _axis(path, data, "phi_deg", 0.0, 360.0, 1)
    phi_i = _axis(path, data, "phi_i_deg", 0.0, 360.0, 2) if "phi_i_deg" in data else None
    shape = (len(theta_i),) + ((len(phi_i),) if phi_i is not None else ()) \
        + (len(theta_r), len(phi))
    names = "(theta_i, phi_i, theta_r, phi)" if phi_i is not None else "(theta_i, theta_r, phi)"
    if f.shape != shape:
        _fail(path, f"brdf has shape {f.shape}, expected {shape} = {names} from the angle "
                    "arrays")
    if not np.all(np.isfinite(f)):
        k = np.argwhere(~np.isfinite(f))[0]
        _fail(path, f"brdf contains NaN or inf (at index {tuple(int(i) for i in k)})")
    if np.any(f < 0.0):
        k = np.argwhere(f < 0.0)[0]
        _fail(path, f"brdf has negative values ({f[tuple(k)]:g} at index "
                    f"{tuple(int(i) for i in k)}); a BRDF is non-negative")
    if np.any(f > MAX_TABLE_BRDF):
        k = np.argwhere(f > MAX_TABLE_BRDF)[0]
        _fail(path, f"brdf = {f[tuple(k)]:g} at index {tuple(int(i) for i in k)}; allowed: "
                    f"0 .. {MAX_TABLE_BRDF:g} (1/sr, or as a reflectance factor)")
    if not np.any(f > 0.0):
        _fail(path, "brdf is zero everywhere (use bottom.model: black)")
    if phi[0] != 0.0:
        _fail(path, f"phi_deg (reflected azimuth relative to the incident one) must start at 0, "
                    f"got {phi[0]:g}")
    if len(phi) > 1 and phi[-1] < 180.0:
        _fail(path, f"phi_deg must end at 180 (a table symmetric about the plane of incidence) "
                    f"or extend beyond it towards 360, got {phi[-1]:g}")
    if phi_i is not None and phi_i[0] != 0.0:
        _fail(path, f"phi_i_deg must start at 0, got {phi_i[0]:g}")
    if phi_i is None:
        f = f[:, None, :, :]
    return {"theta_i": theta_i, "phi_i": phi_i, "theta_r": theta_r, "phi": phi, "f": f}


def pack_table(table: dict, reflectance_factor: bool) -> np.ndarray:
    """The kernel's block for brdf/table.py (see there for the layout)."""
    f = table["f"] / math.pi if reflectance_factor else table["f"].copy()
    phi = table["phi"]
    symmetric = len(phi) == 1 or phi[-1] == 180.0
    if not symmetric and phi[-1] < 360.0:
        phi = np.append(phi, 360.0)
        f = np.concatenate([f, f[..., :1]], axis=3)
    if table["phi_i"] is None:
        phi_i = np.zeros(1)
    else:
        phi_i = table["phi_i"]
        if phi_i[-1] < 360.0:
            phi_i = np.append(phi_i, 360.0)
            f = np.concatenate([f, f[:, :1]], axis=1)
    head = [len(table["theta_i"]), len(phi_i), len(table["theta_r"]), len(phi),
            1.0 if symmetric else 0.0, 0.0, 0.0, 0.0]
    return np.concatenate([np.array(head, dtype=np.float64), np.radians(table["theta_i"]),
                           np.radians(phi_i), np.radians(table["theta_r"]), np.radians(phi),
                           f.ravel()])


# --- the packed parameter array ---------------------------------------------------------------



def scalars(bottom) -> list[float]:
    """The model's scalar parameters, in the order of its kernel module."""
    m = bottom.model
    if m in ("lambertian", "specular"):
        return [bottom.reflectance]
    if m == "minnaert":
        return [bottom.reflectance, bottom.k]
    if m == "lambertian_specular":
        return [bottom.diffuse_reflectance, bottom.specular_reflectance]
    if m == "ggx":
        return [bottom.roughness, bottom.n_ratio, bottom.diffuse_reflectance,
                1.0 if bottom.fresnel else 0.0, bottom.albedo_scale]
    if m == "hapke":
        return [bottom.albedo, bottom.asymmetry, bottom.opposition_amplitude,
                bottom.opposition_width, bottom.albedo_scale]
    if m == "table":
        return [0.0, 0.0, 0.0, 0.0, bottom.albedo_scale]   # slot 4: brdf/table.py SCALE
    return []


def describe(bottom) -> str:
    name = f"bottom.model = {bottom.model!r}"
    if bottom.model == "table":
        name += f" (file {bottom.file})"
    if isinstance(getattr(bottom, "albedo_scale", None), float) and bottom.albedo_scale != 1.0:
        name += (f" at albedo_scale = {bottom.albedo_scale:g} (the largest over the run's "
                 "wavelengths)")
    return name


def gauss01(m: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(m)
    return 0.5 * (x + 1.0), 0.5 * w


def gauss_points(bottom) -> int:
    """Gauss points per cell side: 4; GGX 8 to 12 (its lobe narrows towards the horizon at
    grazing incidence: with 8, alpha = 0.15 keeps rho_dh to 1e-3 up to 89.5 deg, against 8e-3
    with 4)."""
    if bottom.model == "ggx":
        return int(min(12, max(8, math.ceil(1.2 / bottom.roughness))))
    return 4


def uses_tabulated_sampler(bottom) -> bool:
    if bottom.model in ("hapke", "table"):
        return True
    return getattr(bottom, "sampling", "auto") == "tabulated"


def incident_grid(anisotropic: bool) -> tuple[np.ndarray, np.ndarray, int, int]:
    n_ti, n_pi, n_t, n_p = ANISOTROPIC_GRID if anisotropic else ISOTROPIC_GRID
    theta = np.radians(np.minimum(np.linspace(0.0, 90.0, n_ti), LAST_NODE_DEG))
    phi = 2.0 * math.pi * np.arange(n_pi) / n_pi
    return theta, phi, n_t, n_p


def sampler_block(cells: np.ndarray) -> np.ndarray:
    """The general sampler's tables (brdf/general.py) from cell integrals (n_ti, n_pi, n_p, n_t)
    of f cos."""
    n_ti, n_pi, n_p, n_t = cells.shape
    dt = 0.5 * math.pi / n_t
    dp = 2.0 * math.pi / n_p
    s_edges = np.cos(dt * np.arange(n_t + 1)) ** 2
    s_edges[-1] = 0.0
    ds = s_edges[:-1] - s_edges[1:]                      # (n_t,), positive
    cosine = np.broadcast_to(ds * dp / (2.0 * math.pi), (n_p, n_t))   # cos-weighted mass
    blocks = []
    for a in range(n_ti):
        for b in range(n_pi):
            mass = np.clip(cells[a, b], 0.0, None)
            total = mass.sum()
            prob = cosine.copy() if not total > 0.0 \
                else (1.0 - DEFENSIVE) * mass / total + DEFENSIVE * cosine
            prob /= prob.sum()
            col = prob.sum(axis=1)
            col_cdf = np.cumsum(col)
            col_cdf /= col_cdf[-1]
            col_cdf[-1] = 1.0
            cond = np.cumsum(prob, axis=1) / col[:, None]
            cond[:, -1] = 1.0
            dens = 2.0 * prob / (ds[None, :] * dp)
            blocks += [col_cdf, cond.ravel(), dens.ravel()]
    head = np.array([n_ti, n_pi, n_t, n_p, 0.0, 0.0, 0.0, 0.0])
    return np.concatenate([head, s_edges] + blocks)


def _reciprocity_pairs(table: dict | None) -> tuple[np.ndarray, np.ndarray]:
    """Rows of unit vectors (wi, wo) at which f(wi, wo) and f(wo, wi) are compared: for a
    measured table its own nodes (theta inside both theta ranges), else a fixed grid."""
    if table is None:
        thetas = np.radians([0.0, 10.0, 25.0, 40.0, 55.0, 70.0, 85.0])
        dphis = np.radians(np.arange(0.0, 360.0, 30.0))
        phis_i = np.radians([0.0, 50.0, 140.0, 230.0])
    else:
        lo = max(table["theta_i"][0], table["theta_r"][0])
        hi = min(table["theta_i"][-1], table["theta_r"][-1])
        nodes = np.union1d(table["theta_i"], table["theta_r"])
        thetas = np.radians(nodes[(nodes >= lo) & (nodes <= hi)])
        dphis = np.radians(table["phi"][table["phi"] < 360.0])
        phis_i = np.zeros(1) if table["phi_i"] is None \
            else np.radians(table["phi_i"][table["phi_i"] < 360.0])
    ti, to, dp, pi = np.meshgrid(thetas, thetas, dphis, phis_i, indexing="ij")
    ti, to, dp, pi = ti.ravel(), to.ravel(), dp.ravel(), pi.ravel()
    wi = np.stack([np.sin(ti) * np.cos(pi), np.sin(ti) * np.sin(pi), np.cos(ti)], axis=1)
    po = pi + dp
    wo = np.stack([np.sin(to) * np.cos(po), np.sin(to) * np.sin(po), np.cos(to)], axis=1)
    return np.ascontiguousarray(wi), np.ascontiguousarray(wo)


def check_reciprocity(model: int, params: np.ndarray, table: dict | None, tolerance: float,
                      what: str) -> float:
    """Raises ConfigError when f(i, o) and f(o, i) differ by more than tolerance (relative to
    the larger, or to 1e-3 of the largest f met); returns the worst relative difference."""
    wi, wo = _reciprocity_pairs(table)
    fo = ktables.both_ways(model, params, wi, wo)
    floor = 1e-3 * max(float(np.max(fo)), 1e-300)
    rel = np.abs(fo[:, 0] - fo[:, 1]) / np.maximum(np.max(fo, axis=1), floor)
    k = int(np.argmax(rel))
    if rel[k] > tolerance:
        ti, to = np.degrees(np.arccos(np.clip([wi[k, 2], wo[k, 2]], -1, 1)))
        dphi = np.degrees(np.mod(np.arctan2(wo[k, 1], wo[k, 0]) - np.arctan2(wi[k, 1], wi[k, 0]),
                                 2.0 * math.pi))
        raise ConfigError(
            f"{what}: not reciprocal: f(i, o) = {fo[k, 0]:.5g} but f(o, i) = {fo[k, 1]:.5g} "
            f"1/sr (relative difference {rel[k]:.3g}, tolerance {tolerance:g}) at incidence "
            f"theta_i = {ti:.1f} deg, theta_r = {to:.1f} deg, dphi = {dphi:.0f} deg (the worst "
            "pair); set bottom.allow_unphysical: true to run it anyway")
    return float(rel[k])


def check_energy(rho_dh: np.ndarray, theta_i: np.ndarray, phi_i: np.ndarray, what: str) -> None:
    a, b = np.unravel_index(int(np.argmax(rho_dh)), rho_dh.shape)
    if rho_dh[a, b] > 1.0 + ENERGY_TOLERANCE:
        where = f"theta_i = {math.degrees(theta_i[a]):.1f} deg"
        if len(phi_i) > 1:
            where += f", phi_i = {math.degrees(phi_i[b]):.1f} deg"
        raise ConfigError(
            f"{what}: not energy conserving: the directional-hemispherical reflectance rho_dh = "
            f"{rho_dh[a, b]:.4f} > 1 at incidence {where} (the worst; checked every "
            f"{math.degrees(theta_i[1] - theta_i[0]):.0f} deg); lower the reflectance "
            "parameters, or set bottom.allow_unphysical: true to run it anyway")


def bottom_arrays(bottom, diagnostics: dict | None = None) -> tuple[int, np.ndarray]:
    """(model id, packed parameter array) for a validated bottom config; reads a measured table,
    builds the general sampler's tables where needed and runs the physical checks. Raises
    TableError / ConfigError naming the model (and file) and the worst incidence angle.
    diagnostics, if given, receives the incident nodes and the cell integrals."""
    model = registry.bottom_id(bottom.model)
    params = np.zeros(models.BRDF_HEADER)
    sc = scalars(bottom)
    params[:len(sc)] = sc
    table = None
    if bottom.model == "table":
        table = read_brdf_table(bottom.file)
        params[models.BRDF_TABLE_AT] = len(params)
        params = np.concatenate([params, pack_table(table, bottom.quantity ==
                                                    "reflectance_factor")])
    what = describe(bottom)
    allow = getattr(bottom, "allow_unphysical", False)
    if bottom.model == "lambertian_specular" and not allow:
        total = bottom.diffuse_reflectance + bottom.specular_reflectance
        if total > 1.0:
            raise ConfigError(f"{what}: not energy conserving: diffuse_reflectance + "
                              f"specular_reflectance = {total:g} > 1 (rho_dh at every "
                              "incidence angle); set bottom.allow_unphysical: true to run it "
                              "anyway")
    tabulated = uses_tabulated_sampler(bottom)
    numeric_check = not allow and bottom.model in ("ggx", "hapke", "table",
                                                   "lambertian_specular")
    if not (tabulated or numeric_check or diagnostics is not None):
        return model, params
    anisotropic = table is not None and table["phi_i"] is not None
    theta_i, phi_i, n_t, n_p = incident_grid(anisotropic)
    gx, gw = gauss01(gauss_points(bottom))
    cells, f_min, where = ktables.cell_integrals(model, params, theta_i, phi_i, n_t, n_p, gx, gw)
    if diagnostics is not None:
        diagnostics.update(theta_i=theta_i, phi_i=phi_i, cells=cells)
    if numeric_check:
        if f_min < 0.0:
            raise ConfigError(
                f"{what}: negative BRDF value {f_min:.4g} 1/sr at incidence theta_i = "
                f"{math.degrees(where[0]):.1f} deg, theta_r = {math.degrees(where[2]):.1f} deg; "
                "set bottom.allow_unphysical: true to run it anyway")
        tolerance = bottom.reciprocity_tolerance if table is not None else ANALYTIC_RECIPROCITY
        check_reciprocity(model, params, table, tolerance, what)
        check_energy(cells.sum(axis=(2, 3)), theta_i, phi_i, what)
    if tabulated:
        params[models.BRDF_SAMPLER] = 1.0
        params[models.BRDF_SAMPLER_AT] = len(params)
        params = np.concatenate([params, sampler_block(cells)])
    return model, params


def tabulated_rho_dh(bottom) -> tuple[np.ndarray, np.ndarray]:
    """(theta_i nodes in deg, rho_dh at them) from the sampler grid's cell integrals (for
    reports and tests; isotropic models)."""
    out: dict = {}
    bottom_arrays(bottom.model_copy(update={"allow_unphysical": True})
                  if hasattr(bottom, "allow_unphysical") else bottom, out)
    return np.degrees(out["theta_i"]), out["cells"].sum(axis=(1, 2, 3))


def has_mirror(bottom) -> bool:
    """Whether the bottom reflects part of the light as a mirror (a delta function that local
    estimates cannot evaluate)."""
    return cfg.bottom_has_mirror(bottom)
