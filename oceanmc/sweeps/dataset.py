"""The sweep's results: each finished point kept as its own results file in a folder beside the
dataset (what a rerun skips and a Ctrl-C keeps), and the dataset assembled from them, written
atomically as NetCDF4 (HDF5, via h5netcdf).

Dataset layout: one dimension per axis (named by its key path, or by its short name; the other
keys of a zip group are coordinates along it), then each quantity's own dimensions
(wavelength, depth, theta, phi, and direction when the scene has local_directions_deg);
every quantity X of the results file (`air/Rrs_nadir` becomes `air_Rrs_nadir`, `budget/total`
`budget_total`, the derived `Kd` `derived_Kd`, along depth_interval with depth_upper and
depth_lower) with `X_stderr` beside it; per point `status` (done, failed, pending), `error`,
`photons` and `wall_time_s`; the base scene and the sweep in the attributes. The wavelength
grid is every wavelength some point traces, with `wavelength_traced` per point (wavelength_grid:
inelastic light makes points trace other grids)."""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from .. import __version__
from ..config.base import key_units
from ..run.derived import COORDS as DERIVED_COORDS
from ..run.derived import derive, intervals
from ..run.format import COORD_UNITS, SWEEP_TITLE
from ..run.hdf5 import load_result
from ..run.merge import merge_results, scene_difference
from ..run.placement import place_atomically
from ..run.result import Result
from .axes import SweepError, SweepSpec, coordinate, load_sweep
from .points import Point

DONE, FAILED, PENDING = "done", "failed", "pending"


class OutputExists(Exception):
    """The output path holds something this sweep must not replace without overwrite=True (a
    file that is not a sweep dataset, or the dataset of another sweep); the message says which
    and how to go on."""


@dataclass
class Summary:
    """What the dataset keeps of a point's Result: estimates, standard errors, coordinates."""
    quantities: dict[str, tuple[tuple[str, ...], np.ndarray, np.ndarray, str, str]]
    coords: dict[str, np.ndarray]
    photons: int
    wall_time_s: float

    @classmethod
    def of(cls, result: Result) -> "Summary":
        """The result's quantities, and its derived ones (K functions, R, Q, mean cosines: the
        results file's group `derived`) as `derived/NAME`."""
        quantities = {name: (q.dims, q.mean, q.stderr, q.units, q.description)
                      for name, q in result.quantities.items()}
        coords = dict(result.coords)
        for d in derive(result).values():
            quantities[f"derived/{d.name}"] = (d.dims, d.value, d.stderr, d.units,
                                               d.description)
            if "depth_interval" in d.dims and "depth_interval" not in coords:
                coords.update(intervals(result.coords["depth"]))
        return cls(quantities, coords, int(result.attrs["photons"]),
                   float(result.attrs["wall_time_s"]))


class PointStore:
    """A folder of results files, one per finished point (`<key>.h5`, the file `oceanmc run`
    would write for that scene) and one per finished batch group of a point spread over several
    tasks (`<key>.batches-<first>-<end>.h5`, merged into the point's file when all are in)."""

    def __init__(self, folder: Path) -> None:
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)

    def path(self, point: Point, batches: tuple[int, int] | None = None) -> Path:
        if batches is None:
            return self.folder / f"{point.key}.h5"
        return self.folder / f"{point.key}.batches-{batches[0]}-{batches[1]}.h5"

    def _load(self, path: Path, scene_yaml: str) -> Result | None:
        """The stored result if it is complete and of exactly this scene."""
        if not path.is_file():
            return None
        try:
            result = load_result(path)
        except (OSError, KeyError, ValueError):
            return None  # unreadable: run it again
        if result.config_yaml != scene_yaml or result.attrs.get("partial", False):
            return None
        return result

    def finished(self, point: Point) -> Summary | None:
        result = self._load(self.path(point), point.yaml)
        return None if result is None else Summary.of(result)

    def part_done(self, point: Point, batches: tuple[int, int]) -> bool:
        return self._load(self.path(point, batches), point.part_yaml(*batches)) is not None

    def save(self, point: Point, result: Result) -> Summary:
        result.save(self.path(point))
        return Summary.of(result)

    def save_part(self, point: Point, batches: tuple[int, int], result: Result) -> None:
        result.save(self.path(point, batches))

    def merge_parts(self, point: Point, ranges: list[tuple[int, int]]) -> Summary:
        """The point's Result from its batch groups: their batches concatenated in order, which
        is the Result of one run of all of them (same batches, same means, same errors)."""
        parts = []
        for batches in ranges:
            part = self._load(self.path(point, batches), point.part_yaml(*batches))
            part.attrs["config_yaml"] = point.yaml   # the same batches of the point's scene
            parts.append(part)
        result = merge_results(parts, resume=True) if len(parts) > 1 else parts[0]
        summary = self.save(point, result)
        for batches in ranges:
            self.path(point, batches).unlink(missing_ok=True)
        return summary


def axis_units(key: str) -> str | None:
    """The CF units of an axis over the scene key at path `key` (water.layers[0].thickness_m:
    m; config.base.key_units), or None where its name does not say (a user's review: ncview
    and Panoply showed the axes without)."""
    return key_units(re.sub(r"\[\d+\]", "", key).rpartition(".")[2])


def variable_name(quantity: str) -> str:
    """`air/Rrs_nadir` -> `air_Rrs_nadir`: one flat dataset (a '/' would mean a group)."""
    return quantity.replace("/", "_")


def assemble(spec: SweepSpec, points: list[Point], summaries: dict[str, Summary],
             errors: dict[str, str]):
    """The sweep's xarray Dataset from the points finished so far (NaN where a point failed or
    has not run yet; `status` says which)."""
    import xarray as xr

    shape = spec.shape
    dims = tuple(axis.dim for axis in spec.axes)
    coords: dict[str, tuple] = {}
    for axis in spec.axes:
        for name, key, values in zip(axis.names, axis.keys, axis.values):
            values = coordinate(values)
            units = axis_units(key) if values.dtype.kind in "if" else None
            coords[name] = (axis.dim, values,
                            {"description": f"the scene's {key} along this axis",
                             "key_path": key} | ({"units": units} if units else {}))
    status = np.full(shape, PENDING, dtype=object)
    error = np.full(shape, "", dtype=object)
    photons = np.zeros(shape, dtype=np.int64)
    wall = np.full(shape, np.nan)
    data: dict[str, tuple] = {}
    reference = next((summaries[p.key] for p in points if p.key in summaries), None)
    if reference is not None:
        # a scene without local_directions_deg has no quantity along `direction`: no empty
        # dimension for it
        directions = len(reference.coords.get("direction", ())) > 0
        for name, values in reference.coords.items():
            if name in ("direction", "direction_theta", "direction_phi") and not directions:
                continue
            if name in ("direction_theta", "direction_phi"):
                coords[name] = ("direction", values, _coord_attrs(name))
            elif name in ("depth_upper", "depth_lower"):
                coords[name] = ("depth_interval", values, _coord_attrs(name))
            elif name not in coords:
                coords[name] = (name, values, _coord_attrs(name))
    grid, places, traced = wavelength_grid(points, shape)
    if grid is not None:
        coords["wavelength"] = ("wavelength", grid, _coord_attrs("wavelength"))
    arrays: dict[str, tuple] = {}
    for point in points:
        summary = summaries.get(point.key)
        if summary is None:
            if point.key in errors:
                status[point.index], error[point.index] = FAILED, errors[point.key]
            continue
        status[point.index] = DONE
        photons[point.index] = summary.photons
        wall[point.index] = summary.wall_time_s
        for name, (qdims, mean, stderr, units, description) in summary.quantities.items():
            if grid is not None and qdims[:1] != ("wavelength",):
                # a one-wavelength point among spectral ones: its one wavelength's place
                qdims, mean, stderr = ("wavelength",) + qdims, mean[None], stderr[None]
            if name not in arrays:
                size = (len(grid),) + mean.shape[1:] if grid is not None else mean.shape
                arrays[name] = (qdims, np.full(shape + size, np.nan),
                                np.full(shape + size, np.nan), units, description)
            # a point's wavelengths in their places on the sweep's grid (NaN at the others)
            at = point.index + (places[point.key],) if grid is not None else point.index
            arrays[name][1][at] = mean
            arrays[name][2][at] = stderr
    for name, (qdims, mean, stderr, units, description) in arrays.items():
        var = variable_name(name)
        data[var] = (dims + qdims, mean, {"units": units, "description": description})
        data[var + "_stderr"] = (dims + qdims, stderr,
                                 {"units": units, "description": f"standard error of {var}"})
    if grid is not None:
        data["wavelength_traced"] = (dims + ("wavelength",), traced, {
            "flag_values": np.array([0, 1, 2], dtype=np.int8),
            "flag_meanings": "not_traced asked added_for_the_excitation",
            "description": "how the point traces each wavelength: 0 not at all (its quantities "
                           "NaN there), 1 asked for (wavelengths_nm), 2 added for the "
                           "excitation of its inelastic light (without the inelastic light "
                           "excited below the point's grid); a point not run (status) is NaN "
                           "at every wavelength"})
    data["status"] = (dims, status.astype(str), {"description": "done, failed or pending "
                                                 "(not run yet: an interrupted sweep)"})
    data["error"] = (dims, error.astype(str), {"description": "why a failed point failed"})
    data["photons"] = (dims, photons, {"description": "photons traced at the point"})
    data["wall_time_s"] = (dims, wall, {"units": "s", "description": "run time of the point"})
    counts = {s: int((status == s).sum()) for s in (DONE, FAILED, PENDING)}
    attrs = {
        "title": SWEEP_TITLE,
        "oceanmc_version": __version__,
        "base_scene_yaml": yaml.safe_dump(spec.base, sort_keys=False),
        "sweep_yaml": spec.to_yaml(),
        "axes": ",".join(dims),
        "points": int(np.prod(shape, dtype=np.int64)),
        "points_done": counts[DONE],
        "points_failed": counts[FAILED],
        "points_pending": counts[PENDING],
        "partial": int(counts[PENDING] > 0),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


NOT_TRACED, ASKED, ADDED = 0, 1, 2


def wavelength_grid(points: list[Point], shape: tuple[int, ...]
                    ) -> tuple[np.ndarray | None, dict[str, np.ndarray], np.ndarray | None]:
    """The sweep's wavelength grid, every wavelength some point traces (points trace other
    grids where an axis is wavelengths_nm, or switches Raman scattering on, or moves an
    excitation range), each point's places on it by key, and per point and wavelength the
    flag wavelength_traced (NOT_TRACED, ASKED, ADDED); (None, {}, None) where every point
    traces one wavelength (a one-wavelength result's layout: no wavelength dimension). A
    scene without wavelengths_nm among spectral ones is refused before any run
    (points.build_points)."""
    traced = {p.key: np.asarray(p.config.wavelengths, dtype=np.float64) for p in points}
    if all(len(w) == 1 for w in traced.values()):
        return None, {}, None
    # one value per wavelength however each grid was computed (400 and 400.00000000000006)
    merged = np.unique(np.concatenate(list(traced.values())))
    keep = np.concatenate([[True], np.diff(merged) > WAVELENGTH_MATCH_NM])
    grid = merged[keep]
    places = {key: _nearest_places(grid, w) for key, w in traced.items()}
    flags = np.full(shape + (len(grid),), NOT_TRACED, dtype=np.int8)
    for point in points:
        flags[point.index + (places[point.key],)] = ASKED
        added = np.asarray(point.config.added_wavelengths, dtype=np.float64)
        if len(added):
            flags[point.index + (_nearest_places(grid, added),)] = ADDED
    return grid, places, flags


def _nearest_places(grid: np.ndarray, wavelengths: np.ndarray) -> np.ndarray:
    """Each wavelength's index on the grid (the nearest: the grid holds them all)."""
    return np.abs(grid[None, :] - wavelengths[:, None]).argmin(axis=1)


# two traced wavelengths closer than this are one (grids are computed, not typed)
WAVELENGTH_MATCH_NM = 1e-6


def _coord_attrs(name: str) -> dict:
    units, description = COORD_UNITS[name] if name in COORD_UNITS else DERIVED_COORDS[name]
    return {"units": units, "description": description}


def write_dataset(dataset, path: Path) -> Path:
    """NetCDF4 via h5netcdf, atomically (a temporary file renamed into place), so a crash or a
    second Ctrl-C never leaves half a dataset."""
    return place_atomically(path, lambda tmp: dataset.to_netcdf(tmp, engine="h5netcdf"))


def check_replaceable(path: Path, folder: Path, spec: SweepSpec) -> None:
    """Raises OutputExists unless writing this sweep's dataset at `path` loses nothing: there is
    no file there, or it is the dataset of this sweep or of one whose every point this sweep
    also has (a rerun, or a rerun with values added to an axis: the resume feature). Points
    are compared as their scenes (the base scene with the point's keys set), rebuilt from the
    dataset's base_scene_yaml and sweep_yaml, so the order of the axes does not matter. The
    points folder is never refused: its files are named by their scenes' hashes, so another
    sweep's points there are kept, never replaced."""
    how = "pass --overwrite to replace it (overwrite=True), or write this sweep elsewhere " \
        "with -o"
    if folder.exists() and not folder.is_dir():
        raise OutputExists(f"{folder} exists and is not a folder: a sweep keeps its finished "
                           f"points there; move it away or write the sweep elsewhere with -o")
    if not path.exists():
        return
    if path.is_dir():
        raise OutputExists(f"{path} is a folder, not a dataset; write the sweep elsewhere with -o")
    import h5py
    try:
        with h5py.File(path, "r") as f:
            attrs = {key: f.attrs.get(key) for key in ("title", "base_scene_yaml", "sweep_yaml")}
    except OSError:
        raise OutputExists(f"{path} exists and is not an oceanmc sweep dataset (not HDF5/NetCDF4)"
                           f"; {how}") from None
    text = {key: value.decode() if isinstance(value, bytes) else value
            for key, value in attrs.items()}
    if text["title"] != SWEEP_TITLE:
        raise OutputExists(f"{path} exists and is not an oceanmc sweep dataset; {how}")
    try:
        stored = yaml.safe_load(text["sweep_yaml"])
        base = yaml.safe_load(text["base_scene_yaml"])
        old = load_sweep({"base": base, "set": stored.get("set"), "axes": stored.get("axes")})
        old_scenes = {_canonical(old.scene_at(a)): a for _, a in old.points()}
    except (SweepError, yaml.YAMLError, AttributeError, TypeError):
        raise OutputExists(f"{path} is an oceanmc sweep dataset whose sweep cannot be read back "
                           f"(attributes base_scene_yaml, sweep_yaml); {how}") from None
    new_scenes = {_canonical(spec.scene_at(a)) for _, a in spec.points()}
    missing = [a for scene, a in old_scenes.items() if scene not in new_scenes]
    if not missing:
        return
    if len(missing) == len(old_scenes) and base != spec.base:
        differs = scene_difference(text["base_scene_yaml"], yaml.safe_dump(spec.base))
        why = f"its base scene differs: {differs or 'the scene differs'}"
    elif len(missing) == len(old_scenes) and old.settings != spec.settings:
        keys = sorted(set(old.settings) ^ set(spec.settings)) or \
            sorted(k for k in old.settings if old.settings[k] != spec.settings[k])
        why = f"its `set` differs: {keys[0]}"
    else:
        more = f", and {len(missing) - 1} more of its {len(old_scenes)} points" \
            if len(missing) > 1 else ""
        why = f"its point ({old.label(missing[0])}) is not one of this sweep's{more}"
    raise OutputExists(f"{path} holds the dataset of another sweep ({why}); {how}")


def _canonical(scene: dict) -> str:
    """A point's scene as text that equal scenes share (keys sorted)."""
    return yaml.safe_dump(scene, sort_keys=True)
