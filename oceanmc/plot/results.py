"""`oceanmc plot RESULT.h5`: the figures of a results file, as PNG.

- the remote-sensing reflectance Rrs (air/Rrs_nadir) against wavelength with its standard-error
  band (one marker for a monochromatic file); with inelastic light also its parts (elastic,
  Raman, fluorescence: elastic/air/Rrs_nadir, ...) with error bars, on a log axis;
- Ed, Eu and Eo against depth, one line per selected wavelength, log irradiance axis, error bars
  of one standard error;
- the radiance distribution at one depth and at 0+ (group air) on the polar quads, the downwelling
  and the upwelling hemispheres side by side;
- for a spectral file, the diffuse attenuation Kd and the irradiance reflectance R against
  wavelength (group derived, run/derived.py), a line per tally interval and depth, shaded +- one
  standard error.

Files are read with xarray. A spectral file has a coordinate `wavelength` (nm) as the leading
dimension of every spectral quantity; a monochromatic file has none, and both are drawn.
"""
from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config.loading import file_problem
from ..run.format import FORMAT_VERSION, SWEEP_DATASET_MESSAGE, SWEEP_TITLE
from ..run.results import PART_LABELS
from ..run.summary import planned_batches
from . import fit_title, log_norm, panels, polar_quads, pyplot, save

# at most this many wavelengths share a profile panel (evenly spaced over the file's grid), so
# that the lines stay distinguishable
MAX_PROFILE_WAVELENGTHS = 6


class PlotInputError(ValueError):
    """A results file or an option the figures cannot be drawn from; the message says why."""


@dataclass
class ResultFile:
    water: object          # xarray.Dataset of the root group (in water)
    air: object            # xarray.Dataset of the group air (0+)
    path: Path
    derived: object = None  # xarray.Dataset of the group derived; None in a file without it
    # xarray.Dataset of the group PART/air of each part of the light of a run with inelastic
    # light (attribute inelastic_parts: elastic, raman, ...); empty without inelastic light
    parts: dict = field(default_factory=dict)

    @property
    def wavelengths(self) -> np.ndarray | None:
        """The wavelengths (nm) of a spectral file; None for a monochromatic one."""
        if "wavelength" not in self.water.coords:
            return None
        return np.asarray(self.water.coords["wavelength"], dtype=np.float64)

    @property
    def depths(self) -> np.ndarray:
        return np.asarray(self.water.coords["depth"], dtype=np.float64)


def open_result(path: str | Path) -> ResultFile:
    import xarray as xr
    path = Path(path)
    problem = file_problem(path)
    if problem:
        raise PlotInputError(f"{path}: {problem}")
    try:
        water = xr.load_dataset(path, engine="h5netcdf", phony_dims="access")
    except UNREADABLE as exc:
        raise PlotInputError(f"{path}: not an oceanmc results file (not readable as HDF5: "
                             f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__})"
                             ) from None
    if water.attrs.get("title") == SWEEP_TITLE:
        raise PlotInputError(f"{path}: {SWEEP_DATASET_MESSAGE}")
    if "format_version" not in water.attrs or "Ed" not in water:
        raise PlotInputError(f"{path}: not an oceanmc results file (no format_version attribute "
                             "or no Ed)")
    version = water.attrs["format_version"]
    if version != FORMAT_VERSION:   # (as show, merge and --resume refuse it: a review)
        raise PlotInputError(f"{path}: format_version {version!r}; this oceanmc reads "
                             f"format_version {FORMAT_VERSION}")
    if "batches" in water.attrs and not str(water.attrs["batches"]).isdigit():
        raise PlotInputError(f"{path}: its attribute batches = "
                             f"{water.attrs.get('batches')!r} is not a count of batches")
    try:
        air = xr.load_dataset(path, engine="h5netcdf", group="air")
    except UNREADABLE:
        raise PlotInputError(f"{path}: not an oceanmc results file (no group air)") from None
    try:
        derived = xr.load_dataset(path, engine="h5netcdf", group="derived")
    except UNREADABLE:   # written before oceanmc derived them, or no whole batch
        derived = None
    names = str(water.attrs.get("inelastic_parts", "")).split()
    try:
        parts = {name: xr.load_dataset(path, engine="h5netcdf", group=f"{name}/air")
                 for name in names} if len(names) > 1 else {}
    except UNREADABLE:
        raise PlotInputError(f"{path}: its attribute inelastic_parts names parts "
                             f"({', '.join(names)}) without their group PART/air") from None
    return ResultFile(water, air, path, derived, parts)


# what xarray and h5netcdf raise for a file or group they cannot read: a damaged file's
# metadata checksum gave RuntimeError or AttributeError (a user's review: tracebacks)
UNREADABLE = (OSError, ValueError, KeyError, RuntimeError, AttributeError, TypeError)


def _listed(values: np.ndarray, most: int = 12) -> str:
    """The values for a one-line message: all of them, or the first and last few of a long
    list."""
    text = [f"{v:g}" for v in values]
    if len(text) > most:
        text = text[:most // 2] + [f"... ({len(text)} values)"] + text[-(most // 2):]
    return ", ".join(text)


def depth_index(result: ResultFile, depth: float | None) -> int:
    """The index of --depth in the file's tallied depths; the first (0 = 0-) by default."""
    if depth is None:
        return 0
    hits = np.nonzero(np.isclose(result.depths, depth, rtol=0.0, atol=1e-9))[0]
    if hits.size == 0:
        raise PlotInputError(f"--depth {depth:g}: not a tallied depth of {result.path.name}; "
                             f"allowed: {_listed(result.depths)} (m)")
    return int(hits[0])


def wavelength_indices(result: ResultFile, wavelength: float | None) -> list[int]:
    """The wavelengths to draw: --wavelength alone, else up to MAX_PROFILE_WAVELENGTHS evenly
    spaced over the file's grid; [] for a monochromatic file."""
    grid = result.wavelengths
    if grid is None:
        if wavelength is not None:
            raise PlotInputError(f"--wavelength {wavelength:g}: {result.path.name} is "
                                 "monochromatic (it has no wavelength dimension); leave it out")
        return []
    if wavelength is not None:
        hits = np.nonzero(np.isclose(grid, wavelength, rtol=0.0, atol=1e-6))[0]
        if hits.size == 0:
            raise PlotInputError(f"--wavelength {wavelength:g}: not a wavelength of "
                                 f"{result.path.name}; allowed: {_listed(grid)} (nm)")
        return [int(hits[0])]
    count = min(len(grid), MAX_PROFILE_WAVELENGTHS)
    return [int(i) for i in np.unique(np.round(np.linspace(0, len(grid) - 1, count)))]


def _at(array, index: int | None):
    """The values of one wavelength of a spectral quantity (index None: monochromatic)."""
    return array if index is None else array.isel(wavelength=index)


def _wavelength_colours(result: ResultFile, indices: list[int]) -> dict:
    plt = pyplot()
    grid = result.wavelengths
    if grid is None:
        return {None: "k"}
    span = max(float(grid[-1] - grid[0]), 1e-9)
    cmap = plt.get_cmap("turbo")
    return {i: cmap(0.05 + 0.9 * (grid[i] - grid[0]) / span) for i in indices}


def _wavelength_label(result: ResultFile, index: int | None) -> str:
    return "" if index is None else f"{result.wavelengths[index]:g} nm"


# --- the figures -------------------------------------------------------------------------------

def opened(result) -> ResultFile:
    """What the figure functions below take, opened: a results file's path (open_result), a
    Result that simulate() returned in a notebook (written to a temporary file and read back:
    the figures read the file's groups), or a ResultFile. A file without a whole batch (a run
    stopped before its first) is a PlotInputError, as `oceanmc plot` refuses it."""
    from ..run.result import Result
    if isinstance(result, Result):
        # (named after its scene in what the figures and their messages say: the file is gone)
        with tempfile.TemporaryDirectory(prefix="oceanmc-plot-") as folder:
            file = opened(result.save(Path(folder) / "result.h5"))
        scene = str(result.attrs.get("name") or "a run").replace("/", "-")
        file.path = Path(f"the Result of {scene!r}")
        return file
    if isinstance(result, (str, Path)):
        result = open_result(result)
    if not isinstance(result, ResultFile):
        raise PlotInputError(f"{type(result).__name__}: the figures take a results file's "
                             "path, a Result (oceanmc.simulate's) or an opened file "
                             "(open_result)")
    if int(result.water.attrs.get("batches", 1)) == 0:
        raise PlotInputError(f"{result.path}: a partial file with no whole batch yet, nothing "
                             "to draw (`oceanmc run --resume` continues it)")
    return result


def rrs_figure(result: ResultFile | str | Path):
    """air/Rrs_nadir against wavelength, shaded +- one standard error; one marker with its error
    bar for a monochromatic file. With inelastic light, its parts beside it (rrs_parts). None
    where the file has no Rrs_nadir."""
    result = opened(result)
    if "Rrs_nadir" not in result.air:
        return None
    rrs = result.air["Rrs_nadir"]
    err = result.air["Rrs_nadir_stderr"]
    grid = result.wavelengths
    value, se = np.atleast_1d(np.asarray(rrs)), np.atleast_1d(np.asarray(err))
    size = (6.0, 4.0) if grid is not None else (3.5, 4.0)
    fig, (ax,) = panels(1, 1, size)
    if grid is None:
        ax.errorbar([0.0], value, yerr=se, fmt="o", color="k", capsize=4,
                    label=f"Rrs nadir = {value[0]:.4g} +- {se[0]:.2g}\n(monochromatic run)")
        ax.set_xticks([])
        ax.set_xlim(-1.0, 1.0)
    else:
        ax.fill_between(grid, value - se, value + se, color="C0", alpha=0.3,
                        label="+- 1 standard error")
        ax.plot(grid, value, "o-", color="C0", ms=3,
                label="Rrs nadir (whole)" if result.parts else "Rrs nadir")
        ax.set_xlabel("wavelength (nm)")
    if result.parts and grid is not None:
        rrs_parts(ax, result, value)
    else:
        top = np.nanmax(value + np.nan_to_num(se))
        ax.set_ylim(0.0, 1.3 * top if top > 0 else 1.0)
    ax.set_ylabel(f"Rrs ({rrs.attrs.get('units', 'sr-1')})")
    name = result.water.attrs.get("name", result.path.name)
    # the axes' width (the figure's less the y axis labels): a long scene name is wrapped
    ax.set_title(fit_title(f"remote-sensing reflectance: {name}", size[0] - 0.9, 9), fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7 if result.parts else 8)
    return marked_partial(fig, result)


# the log axis of Rrs by part reaches at most this far below its largest value: in clear water
# the Raman part in the red is some 3e-4 of the whole Rrs in the blue; smaller values (the
# tails of the fluorescence band) fall below the axis
RRS_PARTS_RANGE = 1e4


def rrs_parts(ax, result: ResultFile, whole: np.ndarray) -> None:
    """The parts of Rrs nadir of a run with inelastic light (PART/air/Rrs_nadir) on the Rrs
    axes, beside the whole, each with error bars of one standard error, on a log axis (they
    span decades); zeros are left out (Raman light at a wavelength whose excitation lies below
    the traced grid, fluorescence away from its band). The wavelengths the run added for the
    excitation, below those asked for or between them, are shaded (added_spans): not asked
    for, they are traced to excite the others (the lowest ones' own Raman light lacks what
    would be excited below the traced grid)."""
    grid = result.wavelengths
    ax.set_yscale("log", nonpositive="clip")
    drawn = [whole]
    for k, (part, air) in enumerate(result.parts.items()):
        if "Rrs_nadir" not in air:
            continue
        value = np.asarray(air["Rrs_nadir"])
        err = np.asarray(air["Rrs_nadir_stderr"])
        shown = value > 0
        ax.errorbar(grid[shown], value[shown], yerr=err[shown], fmt="s-", ms=2.5, lw=1,
                    capsize=2, color=f"C{k + 1}", label=f"{PART_LABELS.get(part, part)} part")
        drawn.append(value)
    positive = np.concatenate(drawn)
    positive = positive[np.isfinite(positive) & (positive > 0)]
    if positive.size:
        top = float(positive.max())
        ax.set_ylim(max(float(positive.min()), top / RRS_PARTS_RANGE) / 1.5, 2.0 * top)
    added = np.atleast_1d(np.asarray(result.water.attrs.get("wavelengths_added_nm", []),
                                     dtype=np.float64))
    label = "added for the excitation"
    for lo, hi in added_spans(grid, added):
        ax.axvspan(lo, hi, color="0.6", alpha=0.15, lw=0, label=label)
        label = None


def added_spans(grid: np.ndarray, added: np.ndarray) -> list[tuple[float, float]]:
    """(left, right) in nm of each run of neighbouring grid wavelengths that the run added for
    the excitation (below the asked ones or between them), from halfway to the asked neighbour
    on each side (the grid's end where there is none)."""
    is_added = [np.isclose(added, w).any() for w in grid]
    # where a run of added wavelengths starts and where the next asked one stands
    change = np.flatnonzero(np.diff(np.concatenate([[0], is_added, [0]]).astype(int)))
    last = len(grid) - 1
    return [(float(grid[0] if start == 0 else 0.5 * (grid[start - 1] + grid[start])),
             float(grid[last] if stop > last else 0.5 * (grid[stop - 1] + grid[stop])))
            for start, stop in zip(change[::2], change[1::2])]


PROFILE_QUANTITIES = (("Ed", "downward plane irradiance Ed"), ("Eu", "upward plane irradiance Eu"),
                      ("Eo", "scalar irradiance Eo"))


def kd_r_figure(result: ResultFile | str | Path):
    """Kd (one line per interval between adjacent tally depths) and R = Eu/Ed (one line per
    tally depth) against wavelength, at most MAX_DERIVED_LINES of each, shaded +- one standard
    error (the jackknife over batches of run/derived.py). None for a monochromatic file or one
    without derived quantities."""
    result = opened(result)
    derived, grid = result.derived, result.wavelengths
    if grid is None or derived is None or "Kd" not in derived:
        return None
    fig, axes = panels(2, 2, (4.8, 4.0))
    for ax, name, dim, title in ((axes[0], "Kd", "depth_interval",
                                  "diffuse attenuation of Ed, Kd"),
                                 (axes[1], "R", "depth", "irradiance reflectance R = Eu/Ed")):
        count = derived.sizes[dim]
        picks = np.unique(np.round(np.linspace(0, count - 1, min(count, MAX_DERIVED_LINES))))
        for k, i in enumerate(int(i) for i in picks):
            value = np.asarray(derived[name].isel({dim: i}))
            err = np.asarray(derived[name + "_stderr"].isel({dim: i}))
            if dim == "depth":
                z = float(derived["depth"][i])
                label = "0-" if z == 0.0 else f"{z:g} m"
            else:
                label = (f"{float(derived['depth_upper'][i]):g}-"
                         f"{float(derived['depth_lower'][i]):g} m")
            ax.fill_between(grid, value - err, value + err, color=f"C{k}", alpha=0.25)
            ax.plot(grid, value, "o-", ms=3, color=f"C{k}", label=label)
        units = derived[name].attrs.get("units", "")
        ax.set_xlabel("wavelength (nm)")
        ax.set_ylabel(f"{name} ({units})" if units and units != "1" else name)
        ax.set_title(title, fontsize=9)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, title="depths", title_fontsize=7)
    kd = np.asarray(derived["Kd"])
    if np.isfinite(kd).any() and np.nanmin(kd) > 0.0:   # (all NaN: numpy would warn)
        axes[0].set_yscale("log")
    return marked_partial(fig, result)


def profiles_figure(result: ResultFile | str | Path, indices: list[int] | None = None):
    """Ed, Eu and Eo against depth (one panel each), one line per wavelength index (indices []:
    monochromatic; None: up to MAX_PROFILE_WAVELENGTHS spread over a spectral file's),
    irradiance on a log axis, error bars of one standard error."""
    result = opened(result)
    if indices is None:
        indices = wavelength_indices(result, None)
    for index in indices:
        _check_wavelength(result, index)
    fig, axes = panels(len(PROFILE_QUANTITIES), 3, (4.2, 4.6))
    lines = indices or [None]
    colours = _wavelength_colours(result, lines)
    for ax, (name, title) in zip(axes, PROFILE_QUANTITIES):
        for index in lines:
            value = np.asarray(_at(result.water[name], index))
            err = np.asarray(_at(result.water[name + "_stderr"], index))
            shown = value > 0   # a log axis: a zero (e.g. Eu over a black bottom) is left out
            ax.errorbar(value[shown], result.depths[shown], xerr=err[shown], fmt="o-", ms=3,
                        capsize=2, color=colours[index],
                        label=_wavelength_label(result, index) or None)
        _log_x(ax, np.asarray(result.water[name]))
        ax.invert_yaxis()
        units = result.water[name].attrs.get("units")
        ax.set_xlabel(f"{name} ({units})" if units else name, fontsize=8)
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("depth (m; 0 is 0-, just below the surface)")
    if indices:
        axes[0].legend(fontsize=7, title="wavelength", title_fontsize=7)
    return marked_partial(fig, result)


def _log_x(ax, values: np.ndarray) -> None:
    """A logarithmic x axis whose tick labels stay readable: over less than a decade the default
    labels every minor tick (they overlap), so a few plain ticks are placed instead."""
    from matplotlib.ticker import MaxNLocator, NullFormatter, ScalarFormatter
    ax.set_xscale("log")
    positive = values[np.isfinite(values) & (values > 0)]
    if positive.size and positive.max() < 10.0 * positive.min():
        ax.xaxis.set_major_locator(MaxNLocator(4))
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())


def _hemispheres(theta_edges: np.ndarray, values: np.ndarray):
    """(title, radius edges, rows) of the downwelling (travel theta < 90) and the upwelling
    hemisphere; the radius is the angle from the pole one looks at: theta for downwelling light
    (0 = light from the zenith), 180 - theta for upwelling light (0 = light from the nadir)."""
    split = int(np.nonzero(np.isclose(theta_edges, 90.0))[0][0])
    down = (theta_edges[:split + 1], values[:split])
    up = (180.0 - theta_edges[split:][::-1], values[split:][::-1])
    return (("downwelling (radius: zenith angle looked at)",) + down,
            ("upwelling (radius: nadir angle looked at)",) + up)


def radiance_figure(result: ResultFile | str | Path, depth: int = 0,
                    wavelength: int | None = None):
    """The radiance on the polar quads at the tallied depth of index `depth` (top row) and at 0+
    (bottom row), downwelling and upwelling hemispheres side by side, each on its own
    logarithmic colour scale, at the wavelength of index `wavelength` (None: a spectral file's
    middle one). None where the file has no radiance."""
    result = opened(result)
    if wavelength is None and result.wavelengths is not None:
        wavelength = len(result.wavelengths) // 2
    if "radiance" not in result.water:
        return None
    _check_index("depth", depth, result.depths, "m", "--depth in metres")
    if wavelength is not None:
        _check_wavelength(result, wavelength)
    theta_edges = np.asarray(result.water.coords["theta_edges"], dtype=np.float64)
    phi_edges = np.asarray(result.water.coords["phi_edges"], dtype=np.float64)
    rows = [(f"{result.depths[depth]:g} m" + (" (0-)" if result.depths[depth] == 0 else ""),
             _at(result.water["radiance"], wavelength).isel(depth=depth))]
    if "radiance" in result.air:
        rows.append(("0+ (in air)", _at(result.air["radiance"], wavelength)))
    fig, axes = panels(2 * len(rows), 2, (4.6, 4.2), projection="polar")
    for r, (where, radiance) in enumerate(rows):
        for c, (title, radius_edges, values) in enumerate(
                _hemispheres(theta_edges, np.asarray(radiance))):
            ax = axes[2 * r + c]
            norm = log_norm(values)
            if norm is not None:
                mesh = polar_quads(ax, radius_edges, phi_edges, values, norm)
                bar = fig.colorbar(mesh, ax=ax, shrink=0.75, pad=0.1)
                bar.set_label(radiance.attrs.get("units", ""), fontsize=8)
                bar.ax.tick_params(labelsize=7)
            ax.set_ylim(0.0, 90.0)
            ax.set_yticks([30, 60, 90])
            ax.tick_params(labelsize=7)
            ax.set_title(f"{where}, {title}" + ("" if norm is not None else ": no light"),
                         fontsize=8)
    label = _wavelength_label(result, wavelength)
    fig.suptitle("radiance on the quads (azimuth: phi of travel from the sun's travel azimuth)"
                 + (f", {label}" if label else ""), fontsize=9)
    return marked_partial(fig, result)


def _check_index(name: str, index, values: np.ndarray, units: str, command: str) -> None:
    """radiance_figure's depth and wavelength are indices into the file's coordinates (the
    command's options are the values): anything else is a PlotInputError naming them, not
    numpy's IndexError."""
    if isinstance(index, bool) or not isinstance(index, (int, np.integer)) \
            or not 0 <= index < len(values):
        raise PlotInputError(f"{name} = {index!r}: the index of one of the file's {name}s, an "
                             f"integer 0 .. {len(values) - 1} ({units}: {_listed(values)}); "
                             f"`oceanmc plot` takes {command}")


def _check_wavelength(result: ResultFile, index) -> None:
    """A wavelength index the figure functions take: one of a spectral file's; a monochromatic
    file takes none (its quantities have no wavelength dimension)."""
    if result.wavelengths is None:
        raise PlotInputError(f"wavelength = {index!r}: {result.path.name} holds one wavelength "
                             "and no wavelength dimension; leave the wavelength index out")
    _check_index("wavelength", index, result.wavelengths, "nm", "--wavelength in nm")


# the quantity each figure needs, for the note when a file lacks it
NEEDS = {"rrs": "air/Rrs_nadir", "profiles": "Ed at any depth (tallies.depths_m: [])",
         "radiance": "radiance in the water (tallies.radiance: false, or tallies.depths_m: [])",
         "kd_r": "derived/Kd and derived/R (group derived: written by an oceanmc that derives "
                 "them, from at least two tally depths)"}
# at most this many depths (and intervals) get a line in the Kd and R panels, evenly spaced
MAX_DERIVED_LINES = 4


def _drawn_values(result: ResultFile, indices: list[int], depth: int,
                  wavelength: int | None) -> dict[str, dict[str, np.ndarray]]:
    """What each figure would draw, by quantity (an empty mapping: the file lacks it)."""
    lines = indices or [None]
    drawn: dict[str, dict[str, np.ndarray]] = {"rrs": {}, "profiles": {}, "radiance": {}}
    if "Rrs_nadir" in result.air:
        drawn["rrs"]["air/Rrs_nadir"] = np.asarray(result.air["Rrs_nadir"])
    # a run with tallies.depths_m: [] has no depth to draw in the water
    has_depths = len(result.depths) > 0
    for name, _ in PROFILE_QUANTITIES:
        if name in result.water and has_depths:
            drawn["profiles"][name] = np.array([np.asarray(_at(result.water[name], i))
                                                for i in lines])
    derived = result.derived
    if result.wavelengths is not None:   # Kd(l) and R(l): spectral files only
        drawn["kd_r"] = {f"derived/{name}": np.asarray(derived[name]) for name in ("Kd", "R")
                         if derived is not None and "Kd" in derived and "R" in derived}
    if "radiance" in result.water and has_depths:
        drawn["radiance"]["radiance"] = np.asarray(
            _at(result.water["radiance"], wavelength).isel(depth=depth))
        if "radiance" in result.air:
            drawn["radiance"]["air/radiance"] = np.asarray(_at(result.air["radiance"],
                                                               wavelength))
    return drawn


def _all_nan(values: dict[str, np.ndarray]) -> bool:
    return bool(values) and all(np.isnan(np.asarray(v, dtype=np.float64)).all()
                                for v in values.values())


def plot_result(path: str | Path, out: str | Path | None = None, depth: float | None = None,
                wavelength: float | None = None) -> dict[str, Path | str]:
    """Writes the figures of a results file as PNG; returns each figure's path by name (rrs,
    profiles, radiance, and kd_r for a spectral file), or, for one not drawn, why: the words
    that follow the file's name in a note ("has no radiance (...)", "holds only NaN in ...").
    A figure whose every value is NaN is not drawn; a file of which nothing can be drawn (every
    value NaN: a run stopped before its first whole batch) is a PlotInputError. out: a folder
    (existing, or ending in '/'), the files then named after the results file, or a prefix to
    which _rrs.png, _profiles.png, _radiance.png (and _kd_r.png) are appended (a .png it ends
    with left out); by default the results file's path without .h5."""
    result = open_result(path)
    at_depth = depth_index(result, depth)
    indices = wavelength_indices(result, wavelength)
    prefix = _prefix(result.path, out)
    radiance_wavelength = None
    if result.wavelengths is not None:
        radiance_wavelength = indices[0] if wavelength is not None else len(result.wavelengths) // 2
    drawn = _drawn_values(result, indices, at_depth, radiance_wavelength)
    skipped: dict[str, str] = {}
    for name, values in drawn.items():
        if not values:
            skipped[name] = f"has no {NEEDS[name]}"
        elif _all_nan(values):
            skipped[name] = f"holds only NaN in {', '.join(values)}"
    if len(skipped) == len(drawn):
        whole = result.water.attrs.get("batches")
        why = " (a partial file with no whole batch yet: `oceanmc run --resume` continues " \
            "it)" if whole is not None and int(whole) == 0 else ""
        raise PlotInputError(f"{result.path}: every value to plot is NaN{why}; nothing to plot")
    makers = {"rrs": lambda: rrs_figure(result),
              "profiles": lambda: profiles_figure(result, indices),
              "radiance": lambda: radiance_figure(result, at_depth, radiance_wavelength),
              "kd_r": lambda: kd_r_figure(result)}
    prefix.parent.mkdir(parents=True, exist_ok=True)
    return {name: skipped[name] if name in skipped else save(makers[name](), f"{prefix}_{name}.png")
            for name in drawn}


def marked_partial(fig, result: ResultFile):
    """The figure, with a line in its bottom left corner when the file is partial (a stopped
    run: its estimates use its whole batches only), as `oceanmc show` says it, so that a figure
    passed on without the file still says so."""
    attrs = result.water.attrs
    if bool(attrs.get("partial", False)):
        total = planned_batches(str(attrs.get("config_yaml", "")))
        of = f" of {total}" if total is not None else ""
        fig.text(0.005, 0.005, f"PARTIAL: {int(attrs['batches'])}{of} batches whole (a stopped "
                 "run)", fontsize=7, color="C3", ha="left", va="bottom")
    return fig


def _prefix(path: Path, out: str | Path | None) -> Path:
    if out is None:
        return path.with_suffix("")
    text = str(out)
    if text.endswith(("/", "\\")) or Path(text).is_dir():
        return Path(text) / path.stem
    if Path(text).exists() and not Path(text).is_file():
        # a device (-o /dev/full wrote /dev/full_rrs.png and the rest into /dev: a review)
        raise PlotInputError(f"-o {text}: not a folder or a name for the figures (it is a "
                             "device or another special file)")
    # a prefix given as a figure's name (-o pic.png): pic_rrs.png, not pic.png_rrs.png
    return Path(text[:-len(".png")] if text.lower().endswith(".png") else text)
