"""Sky radiance distributions for the kernel's sky sampler (kernel/sources.py).

Built-in shapes: `uniform`; `cardioidal` = `overcast`, the CIE standard overcast sky
L(Z) = L_zenith (1 + 2 cos Z)/3 (Moon & Spencer 1942, Illum. Eng. 37, 707; CIE S 011/E:2003
sky type 1), sampled exactly by rejection; `harrison_coombes`, the clear sky of Harrison &
Coombes (1988, Solar Energy 41(4), 387-392, Eqs. 3-5; the formula HydroLight's hcnrad routine
uses):

    L(Z, psi) ~ [1.63 + 53.7 exp(-5.49 psi) + 2.04 cos^2(psi) cos(Z_sun)]
                x [1 - exp(-0.19 / cos Z)] x [1 - exp(-0.53 / cos Z_sun)]

with Z the zenith angle of the viewed sky element, Z_sun the sun's zenith angle
(illumination.sun_zenith_deg) and psi (rad) the angle between the viewed element and the sun.
The direct sun is not part of it (it stays the separate collimated beam).

Sky maps (`sky: {map: FILE}`): the radiance of the sky as seen looking UP at zenith angle
theta_view and azimuth phi_view, on an equirectangular grid of cells, each of constant radiance:
  - .npy: a 2-D array (n_theta, n_phi); rows cover theta_view 0..90 deg in equal steps (row 0
    at the zenith), columns phi_view 0..360 deg in equal steps (column 0 starting at 0);
  - .npz or HDF5 (.h5, .hdf5): the array `radiance` (or the name given as `dataset`), optionally
    with `theta_edges_deg` (n_theta + 1, strictly increasing from 0 to 90) and `phi_edges_deg`
    (n_phi + 1, strictly increasing, spanning exactly 360 deg);
  - OpenEXR (.exr), read with the OpenEXR package: a single-part scanline or tiled image whose
    pixel rows are theta_view rows and columns phi_view columns, in equal steps, as for .npy
    (image row 0, the top, at the zenith; column 0, the left, starting at phi_view = 0). The key
    `layout` says what the rows cover: `sphere`, a full-sphere equirectangular panorama (the
    common HDRI layout: rows cover theta_view 0..180 deg), of which only the upper half (rows
    0..height/2 - 1, the sky) is used, so its height must be even; `hemisphere`, the upper
    hemisphere alone (rows 0..90 deg); `auto` (the default), sphere for an image exactly twice
    as wide as it is high and hemisphere for any other shape. The radiance is the channel
    named `dataset` if the image has one; otherwise, with the default `dataset` (radiance), the
    channel Y if present, else the luminance of the linear R, G, B channels with the Rec. 709 /
    sRGB primaries and D65 white, Y = 0.2126 R + 0.7152 G + 0.0722 B (ITU-R BT.709-6, item 3.2;
    the Y row of the RGB -> XYZ matrix of IEC 61966-2-1:1999, sRGB). An image whose header
    declares other primaries (a `chromaticities` attribute not Rec. 709 to 1e-3, or a
    `colorInteropID` other than lin_rec709_scene) is refused for this conversion: give it a Y
    channel or name a channel. Other channels (A, depth, ...) are ignored. The data window must
    be the display window. No flip or rotation is applied: orient the image to the frame below.
phi_view is measured in oceanmc's frame: from the horizontal direction in which the sun's rays
travel (DESIGN.md section 1), so the sun itself is seen at phi_view = 180 deg. A photon coming
from the viewed element travels the opposite way: theta_travel (from nadir) = theta_view and
phi_travel = phi_view + 180 deg. The map's absolute scale does not matter: the sky supplies
diffuse_fraction x Ed0 of the downward irradiance at 0+.

Sampling: photons carry the sky's irradiance, so directions are drawn with probability
proportional to L cos(theta) dOmega = L sin(theta) cos(theta) dtheta dphi: a row from the
marginal CDF over rows, a cell within the row from its conditional CDF, then sin^2(theta)
and phi uniformly within the cell. For a map (piecewise constant) this density is exactly
proportional to L cos, so every sky photon carries the same weight. Harrison-Coombes is drawn
from its cell averages on a 1 x 2 deg grid and weighted by L(direction) / L(cell) (the exact
density is used in the weight), so it is reproduced exactly, not only to the grid.

A map with `sampling: cosine` is drawn cosine-weighted over the whole hemisphere instead
(sin^2(theta) and phi uniform: density cos(theta) / pi, whatever L), and each photon is weighted
by L(cell) pi / E, E = integral of L cos dOmega over the map = sum over cells of
L (sin^2 theta_hi - sin^2 theta_lo) dphi / 2; its expectation is therefore 1, and every tally
has the same expectation as under importance sampling. The cell of a drawn direction is found by
bisection on the same sin^2(theta) and phi_view edges the direction was drawn in, so the weight
is exactly the radiance of the cell the photon comes from. It exists to show what importance
sampling gains (oceanmc bench: a small bright spot), or to check it.
"""
from __future__ import annotations

import contextlib
import io
import math
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

from ..config.loading import file_problem
from .phase_tables import (ARRAY_FILE_ERRORS, TableError, bounded_npy, hdf5_arrays, is_real,
                           npz_arrays)

HC_GRID = (90, 180)       # Harrison-Coombes proposal cells: 1 deg in zenith, 2 deg in azimuth
HC_GAUSS = 8              # Gauss points per cell side for its cell averages

# Luminance of linear RGB with the Rec. 709 / sRGB primaries and D65 white: ITU-R BT.709-6
# (2015), item 3.2; the Y row of the RGB -> XYZ matrix of IEC 61966-2-1:1999 (sRGB).
REC709_Y = (0.2126, 0.7152, 0.0722)
# (red x, y, green x, y, blue x, y, white x, y) of Rec. 709 / sRGB (BT.709-6 items 1.3, 1.4),
# in the order of the OpenEXR `chromaticities` header attribute
REC709_CHROMATICITIES = (0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290)


def _fail(path, problem: str):
    raise TableError(f"sky map {path}: {problem}")


def _call_quietly(fn):
    """(fn(), None, printed) or (None, the exception, printed), printed being the non-empty lines
    the library wrote meanwhile: the OpenEXR bindings print warnings to sys.stdout and
    OpenEXRCore writes its errors straight to file descriptor 2; both are collected here so that
    a bad file gives one error message and nothing else on the terminal."""
    out = io.StringIO()
    result, exc = None, None
    with tempfile.TemporaryFile() as err, contextlib.redirect_stdout(out):
        try:
            sys.stderr.flush()
            saved = os.dup(2)
        except (OSError, ValueError, AttributeError):
            saved = None          # no usable descriptor 2: let the messages through
        if saved is not None:
            os.dup2(err.fileno(), 2)
        try:
            result = fn()
        except Exception as e:    # the bindings raise RuntimeError, ValueError, ...
            exc = e
        finally:
            if saved is not None:
                os.dup2(saved, 2)
                os.close(saved)
        err.seek(0)
        printed = err.read().decode("utf-8", errors="replace") + "\n" + out.getvalue()
    return result, exc, [line.strip() for line in printed.splitlines() if line.strip()]


def _pixels(path, channels: dict, name: str, shape: tuple[int, int], rows: int) -> np.ndarray:
    """The first `rows` rows of one channel's pixels as float64, checked (full resolution,
    real; finite and >= 0 in those rows: the ground of a full-sphere image is not read)."""
    ch = channels[name]
    px = np.asarray(ch.pixels)
    if px.shape != shape or ch.xSampling != 1 or ch.ySampling != 1:
        _fail(path, f"channel {name!r} is subsampled or misshapen ({px.shape}, sampling "
                    f"{ch.xSampling} x {ch.ySampling}); the image is {shape[0]} x {shape[1]} "
                    f"pixels")
    if not np.issubdtype(px.dtype, np.number) or np.iscomplexobj(px):
        _fail(path, f"channel {name!r} is not real numbers ({px.dtype})")
    px = px[:rows].astype(np.float64)
    if not np.all(np.isfinite(px)):
        k = np.argwhere(~np.isfinite(px))[0]
        _fail(path, f"channel {name!r} contains NaN or inf (at pixel row {k[0]}, column {k[1]})")
    if np.any(px < 0.0):
        k = np.argwhere(px < 0.0)[0]
        _fail(path, f"negative value {px[k[0], k[1]]:g} in channel {name!r} at pixel row {k[0]}, "
                    f"column {k[1]}")
    return px


def _read_exr(path, dataset: str, layout: str) -> np.ndarray:
    """The radiance (n_theta, n_phi) of an equirectangular OpenEXR sky image (module docstring):
    the channel `dataset`, else Y, else the Rec. 709 luminance of R, G, B; the upper half of a
    full-sphere image (layout sphere, or auto with width = 2 height)."""
    try:
        import OpenEXR
    except ImportError as exc:
        _fail(path, f"reading .exr needs the OpenEXR package (pip install 'OpenEXR>=3.3'): {exc}")
    f, exc, printed = _call_quietly(lambda: OpenEXR.File(str(path), separate_channels=True))
    if exc is not None or f is None or len(f.parts) == 0:
        why = printed[0] if printed else (str(exc) if exc is not None else "no image in it")
        _fail(path, f"cannot read it as OpenEXR ({why})")
    if len(f.parts) > 1:
        _fail(path, f"has {len(f.parts)} parts; oceanmc reads single-part images")
    header = f.header()
    if "deep" in str(header.get("type", "")).lower():
        _fail(path, "is a deep image; oceanmc reads flat (scanline or tiled) images")
    data_win = [np.asarray(v).tolist() for v in header.get("dataWindow", ())]
    disp_win = [np.asarray(v).tolist() for v in header.get("displayWindow", ())]
    if data_win != disp_win:
        _fail(path, f"its data window {data_win} is not its display window {disp_win}; the "
                    f"pixels must cover the whole equirectangular image")
    channels = f.channels()
    part = f.parts[0]
    shape = (int(part.height()), int(part.width()))
    rows = shape[0]
    if layout == "sphere" or (layout == "auto" and 2 * shape[0] == shape[1]):
        # full sphere, rows 0..180 deg: keep the sky
        if shape[0] % 2:
            _fail(path, f"a full-sphere image ({shape[0]} x {shape[1]} pixels, layout "
                        f"{layout}) needs an even height, so that the horizon falls between "
                        f"two rows")
        rows = shape[0] // 2
    names = sorted(channels)
    if dataset in channels:
        return _pixels(path, channels, dataset, shape, rows)
    if dataset != "radiance":
        _fail(path, f"no channel {dataset!r} (found: {names or 'nothing'})")
    if "Y" in channels:
        return _pixels(path, channels, "Y", shape, rows)
    if not all(c in channels for c in "RGB"):
        _fail(path, f"no channel 'radiance' or 'Y', nor all of 'R', 'G', 'B' (found: "
                    f"{names or 'nothing'}); name the radiance channel with dataset")
    chroma = header.get("chromaticities")
    if chroma is not None and not np.allclose(np.asarray(chroma, dtype=np.float64),
                                              REC709_CHROMATICITIES, rtol=0.0, atol=1e-3):
        _fail(path, f"its RGB primaries (chromaticities {tuple(round(c, 4) for c in chroma)}) "
                    f"are not Rec. 709 / sRGB, so Y = 0.2126 R + 0.7152 G + 0.0722 B does not "
                    f"apply; give it a Y channel or name a channel with dataset")
    interop = header.get("colorInteropID")
    if interop is not None and str(interop) != "lin_rec709_scene":
        _fail(path, f"its colorInteropID is {str(interop)!r}, not linear Rec. 709 "
                    f"(lin_rec709_scene), so Y = 0.2126 R + 0.7152 G + 0.0722 B does not apply; "
                    f"give it a Y channel or name a channel with dataset")
    r, g, b = (_pixels(path, channels, c, shape, rows) for c in "RGB")
    return REC709_Y[0] * r + REC709_Y[1] * g + REC709_Y[2] * b


def _edges(path, data: dict, name: str, n: int, span: tuple[float, float] | None) -> np.ndarray:
    e = np.asarray(data[name])
    if not is_real(e):
        _fail(path, f"{name} is not real numbers ({e.dtype})")
    e = e.astype(np.float64)
    if e.ndim != 1 or e.size != n + 1:
        _fail(path, f"{name} must be one-dimensional with {n + 1} values (one more than the "
                    f"map's {'rows' if span else 'columns'}), got shape {e.shape}")
    if not np.all(np.isfinite(e)):
        _fail(path, f"{name} contains NaN or inf")
    if np.any(np.diff(e) <= 0.0):
        bad = int(np.argmin(np.diff(e) > 0.0)) + 1
        _fail(path, f"{name} must increase strictly ({e[bad]:g} after {e[bad - 1]:g} at index "
                    f"{bad})")
    if span is not None and (e[0] != span[0] or e[-1] != span[1]):
        _fail(path, f"{name} must run from {span[0]:g} to {span[1]:g} deg (the zenith to the "
                    f"horizon), got {e[0]:g}..{e[-1]:g}")
    if span is None and not math.isclose(e[-1] - e[0], 360.0, abs_tol=1e-9):
        _fail(path, f"{name} must span 360 deg, got {e[0]:g}..{e[-1]:g}")
    return e


def read_sky_map(path, dataset: str = "radiance", layout: str = "auto"
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(theta_edges_deg, phi_edges_deg, radiance (n_theta, n_phi)) of a sky map file, checked;
    every problem is a TableError naming the file. layout: what an .exr image's rows cover."""
    path = Path(str(path))
    problem = file_problem(path)
    if problem:
        _fail(path, problem)
    if path.stat().st_size == 0:
        _fail(path, "is empty")
    suffix = path.suffix.lower()
    data: dict[str, np.ndarray] = {}
    if suffix == ".npy":
        try:
            with open(path, "rb") as file:
                data[dataset] = bounded_npy(file, dataset)
        except ARRAY_FILE_ERRORS as exc:
            _fail(path, f"cannot read it as .npy ({exc})")
    elif suffix == ".npz":
        try:
            data = npz_arrays(path)
        except ARRAY_FILE_ERRORS as exc:
            _fail(path, f"cannot read it as .npz ({exc})")
    elif suffix in (".h5", ".hdf5", ".he5"):
        try:
            data = hdf5_arrays(path)
        except ARRAY_FILE_ERRORS as exc:
            _fail(path, f"cannot read it as HDF5 ({exc})")
    elif suffix == ".exr":
        data[dataset] = _read_exr(path, dataset, layout)
    else:
        _fail(path, f"unknown file type {suffix!r}; use .npy, .npz, .h5/.hdf5 or .exr")
    if dataset not in data:
        _fail(path, f"no array {dataset!r} (found: {sorted(data) or 'nothing'})")
    L = np.asarray(data[dataset])
    if L.size == 0:
        _fail(path, f"the array {dataset!r} is empty")
    if not is_real(L):
        _fail(path, f"the array {dataset!r} is not real numbers ({L.dtype})")
    if L.ndim != 2:
        _fail(path, f"the array {dataset!r} must be two-dimensional (theta_view rows x phi_view "
                    f"columns), got shape {L.shape}")
    L = L.astype(np.float64)
    if not np.all(np.isfinite(L)):
        k = np.argwhere(~np.isfinite(L))[0]
        _fail(path, f"radiance contains NaN or inf (at row {k[0]}, column {k[1]})")
    if np.any(L < 0.0):
        k = np.argwhere(L < 0.0)[0]
        _fail(path, f"negative radiance {L[k[0], k[1]]:g} at row {k[0]}, column {k[1]}")
    n_t, n_p = L.shape
    theta = _edges(path, data, "theta_edges_deg", n_t, (0.0, 90.0)) \
        if "theta_edges_deg" in data else np.linspace(0.0, 90.0, n_t + 1)
    phi = _edges(path, data, "phi_edges_deg", n_p, None) \
        if "phi_edges_deg" in data else np.linspace(0.0, 360.0, n_p + 1)
    weight = np.sin(np.radians(theta[1:])) ** 2 - np.sin(np.radians(theta[:-1])) ** 2
    if not np.any(L * weight[:, None] > 0.0):
        _fail(path, "the sky is dark everywhere (no radiance above the horizon); use "
                    "diffuse_fraction: 0 for no sky")
    return theta, phi, L


def map_radiance(theta_deg: np.ndarray, phi_deg: np.ndarray, L: np.ndarray,
                 dirs: np.ndarray) -> np.ndarray:
    """The radiance of a sky map of unit irradiance (integral L cos dOmega = 1 over its cells)
    arriving in directions of travel dirs (downward, z > 0): each direction's cell, seen at
    theta_view = its angle from nadir and phi_view = its travel azimuth - 180 deg (the
    sampler's convention, module docstring)."""
    s_edges = sin2_edges(theta_deg)
    # relative to the brightest cell first, as sky.pack does: sums over a map near 1.7e308
    # would overflow
    shape = L / L.max()
    unit = shape / cell_cos_mass(s_edges, np.radians(phi_deg), shape).sum()
    theta = np.degrees(np.arccos(np.clip(dirs[:, 2], -1.0, 1.0)))
    phi = np.degrees(np.arctan2(dirs[:, 1], dirs[:, 0])) - 180.0
    phi = phi_deg[0] + np.mod(phi - phi_deg[0], 360.0)
    row = np.clip(np.searchsorted(theta_deg, theta, side="right") - 1, 0, len(theta_deg) - 2)
    col = np.clip(np.searchsorted(phi_deg, phi, side="right") - 1, 0, len(phi_deg) - 2)
    return np.where(dirs[:, 2] > 0.0, unit[row, col], 0.0)


def harrison_coombes(cos_zenith, cos_psi, cos_sun):
    """Harrison & Coombes (1988) clear-sky radiance (relative units) of a sky element at zenith
    angle acos(cos_zenith), at the angle acos(cos_psi) from the sun at zenith acos(cos_sun)."""
    cos_zenith = np.asarray(cos_zenith, dtype=np.float64)
    cos_psi = np.clip(np.asarray(cos_psi, dtype=np.float64), -1.0, 1.0)
    psi = np.arccos(cos_psi)
    with np.errstate(divide="ignore"):
        horizon = 1.0 - np.exp(-0.19 / np.maximum(cos_zenith, 0.0))
    return ((1.63 + 53.7 * np.exp(-5.49 * psi) + 2.04 * cos_psi ** 2 * cos_sun) * horizon
            * (1.0 - math.exp(-0.53 / cos_sun)))


def sun_travel(sun_zenith_deg: float) -> np.ndarray:
    t = math.radians(sun_zenith_deg)
    return np.array([math.sin(t), 0.0, math.cos(t)])


def harrison_coombes_cells(sun_zenith_deg: float, n_t: int = HC_GRID[0], n_p: int = HC_GRID[1],
                           m: int = HC_GAUSS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(theta_edges_deg, phi_edges_deg, cell averages of L weighted by cos dOmega) of the
    Harrison-Coombes sky on a view-direction grid (sun seen at phi_view = 180 deg)."""
    theta = np.linspace(0.0, 90.0, n_t + 1)
    phi = np.linspace(0.0, 360.0, n_p + 1)
    x, w = np.polynomial.legendre.leggauss(m)
    x, w = 0.5 * (x + 1.0), 0.5 * w
    s_edges = np.sin(np.radians(theta)) ** 2
    # Gauss points in s = sin^2(theta_view) (cos dOmega = ds dphi / 2) and phi within each cell
    s = s_edges[:-1, None] + x[None, :] * np.diff(s_edges)[:, None]          # (n_t, m)
    ph = np.radians(phi[:-1, None] + x[None, :] * np.diff(phi)[:, None])      # (n_p, m)
    sin_t = np.sqrt(s)
    cos_t = np.sqrt(1.0 - s)
    sun = sun_travel(sun_zenith_deg)
    # travel direction u = (-sin cos phi_view, -sin sin phi_view, cos)
    cos_psi = (-sin_t[:, None, :, None] * np.cos(ph)[None, :, None, :] * sun[0]
               - sin_t[:, None, :, None] * np.sin(ph)[None, :, None, :] * sun[1]
               + cos_t[:, None, :, None] * sun[2])
    L = harrison_coombes(cos_t[:, None, :, None], cos_psi, sun[2])
    avg = np.einsum("abkj,k,j->ab", L, w, w)
    return theta, phi, avg


def cosine_weights(s_edges: np.ndarray, phi_edges: np.ndarray, L: np.ndarray) -> np.ndarray:
    """The weight L pi / E of a photon from each cell under cosine-weighted sampling (density
    cos / pi), E = integral of L cos dOmega over the map, on the sampler's own edges (sin^2 theta,
    phi in rad): the cells' probabilities ds dphi / (2 pi) times these weights sum to 1."""
    return np.ascontiguousarray(L * (math.pi / cell_cos_mass(s_edges, phi_edges, L).sum()))


def cell_cos_mass(s_edges: np.ndarray, phi_edges: np.ndarray, L: np.ndarray) -> np.ndarray:
    """L x integral of cos dOmega over each cell = L (sin^2 theta_hi - sin^2 theta_lo) dphi / 2
    (s_edges: sin^2 theta; phi_edges in rad)."""
    return L * np.diff(s_edges)[:, None] * np.diff(phi_edges)[None, :] * 0.5


def sky_parameters(sun_zenith_deg: float) -> np.ndarray:
    """(sun travel x, y, z, cos sun zenith, 0...) for the kernel's Harrison-Coombes radiance."""
    sun = sun_travel(sun_zenith_deg)
    return np.array([sun[0], sun[1], sun[2], sun[2], 0.0, 0.0, 0.0, 0.0])


def sin2_edges(theta_deg: np.ndarray) -> np.ndarray:
    """A map's row edges as sin^2 theta (cos dOmega = d(sin^2) dphi / 2), its first and last
    exactly 0 and 1."""
    s_edges = np.sin(np.radians(theta_deg)) ** 2
    s_edges[0], s_edges[-1] = 0.0, 1.0
    return s_edges


def sampling_tables(theta_deg: np.ndarray, phi_deg: np.ndarray, L: np.ndarray) -> dict:
    """Marginal CDF over rows and conditional CDFs within rows of the cell probabilities
    L x integral of cos dOmega (= L (sin^2 theta_hi - sin^2 theta_lo) dphi / 2)."""
    s_edges = sin2_edges(theta_deg)
    phi = np.radians(phi_deg)
    mass = cell_cos_mass(s_edges, phi, L)
    rows = mass.sum(axis=1)
    row_cdf = np.cumsum(rows) / rows.sum()
    last = int(np.nonzero(rows > 0.0)[0][-1])
    row_cdf[last:] = 1.0
    with np.errstate(invalid="ignore", divide="ignore"):
        cell_cdf = np.cumsum(mass, axis=1) / rows[:, None]
    cell_cdf[rows <= 0.0, :] = 1.0
    for i in range(len(rows)):
        if rows[i] > 0.0:
            k = int(np.nonzero(mass[i] > 0.0)[0][-1])
            cell_cdf[i, k:] = 1.0
    return {"s_edges": s_edges, "phi_edges": phi, "row_cdf": row_cdf,
            "cell_cdf": np.ascontiguousarray(cell_cdf),
            "cell_l": np.ascontiguousarray(L.astype(np.float64))}

