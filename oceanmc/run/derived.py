"""Derived quantities: the apparent optical properties HydroLight users read, from a Result's
irradiances and radiances, each with its standard error; the results file's group `derived`.

- the diffuse attenuation functions between adjacent tally depths z1 < z2,
  K_X = ln(X(z1) / X(z2)) / (z2 - z1) (K = -d ln X / dz over the interval), for X = Ed (Kd),
  Eu (Ku), Eo (Ko) and the nadir radiance Lu (KLu); dimension `depth_interval`, whose coordinate
  is the interval's midpoint, with `depth_upper` and `depth_lower` beside it. Closely spaced
  pairs, as HydroLight reports K, come from closely spaced tally depths: tallies.depths_m:
  [0, 5, 5.5, 20] gives K over 0-5, 5-5.5 and 5.5-20 m.
- at every tally depth: the irradiance reflectance R = Eu / Ed, the Q factor Q = Eu / Lu (sr),
  and the mean cosines mu_d = Ed / Eod (downward), mu_u = Eu / Eou (upward) and
  mu = (Ed - Eu) / Eo (total).
- with depth 0 tallied, the surface's upward transmittance for the run's upwelling light,
  t_up = Eu_water_leaving(0+) / Eu(0-) (no depth dimension). (Stored per batch as air/t_up
  until 2026-11-29: the mean of the batches' ratios read high where Eu(0-) is noisy, 34% at
  700 nm with 200 photons per batch.)
KLu and Q need Lu: a scene with tallies.radiance false and no local nadir estimate has neither.

Estimate and standard error. Each quantity is a function f of batch means (of Ed, Eu, ...), and
its estimate is f of the means over all batches. Its standard error is the delete-one jackknife
over batches: theta_i = f(means without batch i), se = sqrt((n - 1)/n sum_i (theta_i -
mean theta)^2), n the number of batches (Efron & Tibshirani 1993, An Introduction to the
Bootstrap, ch. 11). To first order in 1/n it is the delta method with the batches' covariance
of numerator and denominator (the same batches' photons give both, so they are correlated); it
needs no derivative and is exact for a linear f. A ratio per batch would be biased by the noise
of each batch's denominator; the jackknife is not. Fewer than 2 batches: NaN. Where a value is
undefined (a zero irradiance, K between irradiances of which one is 0) it is NaN.

Nothing here is stored per batch: the quantities are computed again from the batches whenever a
Result is written, shown or plotted, so merged and resumed results get them from all their
batches."""
from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .text_table import spectral_blocks, value_cell


@dataclass(frozen=True)
class Derived:
    name: str
    dims: tuple[str, ...]      # those of Ed ((wavelength,) depth); a K's end in depth_interval
    value: np.ndarray
    stderr: np.ndarray
    units: str
    description: str
    sources: tuple[str, ...]   # the quantities it is derived from (Eu, Ed, ...)


def jackknife(f: Callable[..., np.ndarray], *batches: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(f(batch means), delete-one jackknife standard error) for arrays (batch, ...) of equal
    leading length; f takes and returns arrays and broadcasts over a leading axis."""
    n = batches[0].shape[0]
    means = [b.mean(axis=0) for b in batches]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        value = f(*means)
        if n < 2:
            return value, np.full_like(value, np.nan)
        left_out = [(n * m - b) / (n - 1) for m, b in zip(means, batches)]
        theta = f(*left_out)
        spread = theta - theta.mean(axis=0)
        stderr = np.sqrt((n - 1) / n * (spread ** 2).sum(axis=0))
    return value, stderr


def _attenuation(depths: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    dz = np.diff(depths)

    def k(x: np.ndarray) -> np.ndarray:
        return np.log(x[..., :-1] / x[..., 1:]) / dz
    return k


K_FUNCTIONS = (("Kd", "Ed", "downward plane irradiance Ed"),
               ("Ku", "Eu", "upward plane irradiance Eu"),
               ("Ko", "Eo", "scalar irradiance Eo"),
               ("KLu", "Lu", "nadir-viewing radiance Lu"))
# every name derive() may give (a Result does not hold them: result.py names them in a KeyError)
DERIVED_NAMES = tuple(name for name, _, _ in K_FUNCTIONS) + ("R", "Q", "mu_d", "mu_u", "mu",
                                                              "t_up")


def derive(result) -> dict[str, Derived]:
    """Every derived quantity the result's tallies allow, by name (none for a file without Ed):
    Kd, Ku, Ko, KLu between adjacent tally depths, R, Q, mu_d, mu_u, mu at each tally depth,
    t_up (with depth 0 tallied); each a Derived with .value, .stderr (the delete-one jackknife
    over batches), .dims, .units, .description (the module's docstring says how)."""
    q = result.quantities
    if "Ed" not in q or q["Ed"].batches.shape[0] == 0:   # a partial file with no whole batch
        return {}
    dims = q["Ed"].dims
    depths = np.asarray(result.coords["depth"], dtype=np.float64)
    out: dict[str, Derived] = {}

    def add(name, these, units, description, f, *sources):
        if all(s in q for s in sources):
            value, err = jackknife(f, *(q[s].batches for s in sources))
            # a ratio or a logarithm of a zero irradiance or radiance (say Eu at a black
            # bottom) has no value: NaN with a NaN error, not inf
            undefined = ~np.isfinite(value)
            value = np.where(undefined, np.nan, value)
            err = np.where(undefined, np.nan, err)
            out[name] = Derived(name, these, value, err, units,
                                description + " (NaN where undefined: a zero "
                                + " or ".join(sources) + ")", sources)

    if len(depths) > 1:
        k = _attenuation(depths)
        for name, source, what in K_FUNCTIONS:
            add(name, dims[:-1] + ("depth_interval",), "m-1",
                f"diffuse attenuation function of the {what} between adjacent tally depths: "
                f"ln({source}(upper) / {source}(lower)) / (lower - upper)", k, source)
    add("R", dims, "1", "irradiance reflectance Eu / Ed", lambda eu, ed: eu / ed, "Eu", "Ed")
    add("Q", dims, "sr", "Q factor Eu / Lu, Lu the results' nadir-viewing radiance (its "
        "estimator: attribute Lu_method)",
        lambda eu, lu: eu / lu, "Eu", "Lu")
    add("mu_d", dims, "1", "mean cosine of the downwelling light Ed / Eod", lambda e, eo: e / eo,
        "Ed", "Eod")
    add("mu_u", dims, "1", "mean cosine of the upwelling light Eu / Eou", lambda e, eo: e / eo,
        "Eu", "Eou")
    add("mu", dims, "1", "mean cosine of the whole light field (Ed - Eu) / Eo",
        lambda ed, eu, eo: (ed - eu) / eo, "Ed", "Eu", "Eo")
    at_surface = np.nonzero(depths == 0.0)[0]
    if len(at_surface):
        surface = int(at_surface[0])
        add("t_up", dims[:-1], "1", "upward transmittance of the surface for this run's "
            "upwelling light: air/Eu_water_leaving (0+) / Eu(0-)",
            lambda leaving, eu: leaving / eu[..., surface], "air/Eu_water_leaving", "Eu")
    return out


def intervals(depths) -> dict[str, np.ndarray]:
    """The coordinates of dimension depth_interval: midpoint, upper and lower depth (m)."""
    depths = np.asarray(depths, dtype=np.float64)
    return {"depth_interval": 0.5 * (depths[:-1] + depths[1:]),
            "depth_upper": depths[:-1], "depth_lower": depths[1:]}


METHOD = "delete-one jackknife over batches (oceanmc/run/derived.py)"
COORDS = {"depth": ("m", "tally depth below the mean surface; 0 is 0-"),
          "depth_interval": ("m", "midpoint of two adjacent tally depths, where a K applies"),
          "depth_upper": ("m", "upper depth of each interval"),
          "depth_lower": ("m", "lower depth of each interval"),
          "wavelength": ("nm", "wavelength in vacuum")}


def write_derived(f, result) -> None:
    """The derived quantities into the group `derived` of an open h5py file (none, and no group,
    for a result without a whole batch): X and X_stderr with units and descriptions, dimension
    scales attached (depth, depth_interval with its depth_upper and depth_lower, wavelength), so
    that xarray.open_dataset(path, engine="h5netcdf", group="derived") names every dimension."""
    derived = derive(result)
    if not derived:
        return
    group = f.create_group("derived")
    group.attrs["description"] = ("apparent optical properties derived from the irradiances and "
                                  "radiances; standard errors by the " + METHOD)
    coords = dict(intervals(result.coords["depth"]), depth=result.coords["depth"])
    if "wavelength" in result.coords:
        coords["wavelength"] = result.coords["wavelength"]
    used = {dim for d in derived.values() for dim in d.dims}   # no K with one tally depth
    scales = {}
    for dim in ("depth", "depth_interval", "wavelength"):
        if dim in used:
            ds = group.create_dataset(dim, data=np.asarray(coords[dim], dtype=np.float64))
            ds.make_scale(dim)
            ds.attrs["units"], ds.attrs["description"] = COORDS[dim]
            scales[dim] = ds
    if "depth_interval" in used:
        scales["depth_interval"].attrs["coordinates"] = "depth_upper depth_lower"
        for aux in ("depth_upper", "depth_lower"):
            ds = group.create_dataset(aux, data=coords[aux])
            ds.attrs["units"], ds.attrs["description"] = COORDS[aux]
            ds.dims[0].attach_scale(scales["depth_interval"])
    for d in derived.values():
        for name, values, text in ((d.name, d.value, d.description),
                                   (d.name + "_stderr", d.stderr,
                                    f"standard error of {d.name}: {METHOD}")):
            ds = group.create_dataset(name, data=values)
            ds.attrs["units"], ds.attrs["description"] = d.units, text
            for axis, dim in enumerate(d.dims):
                ds.dims[axis].attach_scale(scales[dim])
            if "depth_interval" in d.dims:
                ds.attrs["coordinates"] = "depth_upper depth_lower"


def _where(depth: float) -> str:
    return "0-" if depth == 0.0 else f"{depth:g} m"


def _spectral_cell(value: float, err: float) -> str:
    """A derived quantity's cell in a spectral table (text_table.value_cell): 'undefined' where a
    ratio's denominator is 0, '?' for an error a batch left out leaves undefined."""
    if math.isnan(value):
        return "undefined"
    if math.isnan(err):
        return f"{value:>9.4g} {'?':>5}"
    return value_cell(value, err)


def format_derived(result) -> str:
    """The derived quantities as text for `oceanmc show`: a monochromatic file one row per
    quantity and depth (or interval), value, standard error and relative error; a spectral one a
    table by wavelength of the K functions over the first interval and the ratios at the first
    depth (every depth is in the file's group derived)."""
    derived = derive(result)
    if not derived:
        return ""
    depths = np.asarray(result.coords["depth"], dtype=np.float64)
    lines = ["  derived (standard errors by the delete-one jackknife over batches):"]

    def label(d: Derived, index: int) -> str:
        if "depth_interval" in d.dims:
            return f"{d.name}({_where(depths[index])}..{depths[index + 1]:g} m)"
        if "depth" not in d.dims:   # t_up: from 0- to 0+
            return d.name
        return f"{d.name}({_where(depths[index])})"

    def first(values: np.ndarray) -> np.ndarray:
        """Per wavelength, the value at the first depth or interval (of a quantity that has
        one)."""
        return values[:, 0] if values.ndim == 2 else values

    if "wavelength" not in result.coords:
        lines.append(f"  {'quantity':<28}{'units':<9}{'value':>13}{'std err':>12}"
                     f"{'rel err':>10}")
        for d in derived.values():
            for i, (value, err) in enumerate(zip(np.atleast_1d(d.value),
                                                 np.atleast_1d(d.stderr))):
                if math.isnan(value):
                    lines.append(f"  {label(d, i):<28}{d.units:<9}{'undefined':>13}   "
                                 f"(a zero {' or '.join(d.sources)})")
                    continue
                if math.isnan(err):   # a batch left out leaves it undefined (one lit batch)
                    lines.append(f"  {label(d, i):<28}{d.units:<9}{value:>13.6g}"
                                 f"{'unknown':>12}{'-':>10}")
                    continue
                rel = f"{abs(err / value):>10.2%}" if value != 0.0 else f"{'-':>10}"
                lines.append(f"  {label(d, i):<28}{d.units:<9}{value:>13.6g}{err:>12.3g}{rel}")
        return "\n".join(lines)
    # the K functions (over the first interval) in blocks of their own, then the ratios (at
    # the first depth), as the run's own spectral table (text_table.spectral_blocks)
    ordered = sorted(derived.values(), key=lambda d: "depth_interval" not in d.dims)
    cells = [[_spectral_cell(value, err) for value, err in zip(first(d.value), first(d.stderr))]
             for d in ordered]
    k_functions = sum("depth_interval" in d.dims for d in ordered)
    lines += spectral_blocks(result.coords["wavelength"], [label(d, 0) for d in ordered], cells,
                             (range(0, k_functions), range(k_functions, len(ordered))))
    note = ("(value and relative standard error; K in 1/m over the first interval of tally "
            "depths, the others at the first depth (t_up from 0- to 0+); Q in sr; every depth "
            "and interval in the file's group derived)")
    return "\n".join(lines + textwrap.wrap(note, 100, initial_indent="  ",
                                           subsequent_indent="  "))
