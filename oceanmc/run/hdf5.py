"""Results files: a Result written to HDF5 with h5py, atomically (a temporary file renamed into
place), with dimension scales attached so that xarray.open_dataset(path, engine="h5netcdf")
names every dimension; and read back."""
from __future__ import annotations

import errno
import os
import re
import secrets
import tempfile
from pathlib import Path
from typing import Callable

import h5py
import numpy as np
import yaml

from .derived import write_derived
from .results import Quantity, Result

FORMAT_VERSION = 1

COORD_UNITS = {"depth": ("m", "depth below the mean surface, positive down; 0 is 0- "
                               "(just below the surface)"),
               "theta": ("deg", "polar angle of the direction of travel from nadir, band centre"),
               "phi": ("deg", "azimuth of travel from the sun's travel azimuth, band centre"),
               "theta_edges": ("deg", "theta band edges"),
               "phi_edges": ("deg", "phi band edges"),
               "batch": ("1", "independent batch index"),
               "direction": ("1", "index of a local-estimate direction"),
               "direction_theta": ("deg", "theta of travel of each local-estimate direction"),
               "direction_phi": ("deg", "phi of travel of each local-estimate direction"),
               "wavelength": ("nm", "wavelength in vacuum; spectral scenes only")}


# a partial run's unfinished batches (run/simulation.py), what --resume continues them from;
# their tallies are the named score arrays of group `tally` (scene/grid.py tally_arrays), read
# back as keys tally/<name>
RESUME_GROUP = "resume"
RESUME_FIELDS = ("batch", "rng", "beam", "next_photon", "events")
RESUME_DESCRIPTION = ("state of the batches begun but not finished when the run stopped, "
                      "not part of the estimates: batch index, random stream (xoshiro256**), "
                      "entered sun beam, next photon, scattering events, and in group tally "
                      "the tallies so far (batch first, wavelength last): flux (level, 4), "
                      "radiance (level, theta, phi), local (level, direction), cap (level), "
                      "budget")

AUXILIARY_COORDS = {"direction_theta": "direction", "direction_phi": "direction"}


def _write_attrs(obj, attrs: dict) -> None:
    for key, value in attrs.items():
        if value is None:
            continue
        obj.attrs[key] = value


class ResultsSavedElsewhere(OSError):
    """The results could not be placed at the path asked for (another process made that file
    meanwhile, or its disk is full); they were kept at `kept`, which the message names."""

    def __init__(self, wanted: Path, kept: Path, reason: str) -> None:
        super().__init__(f"{wanted}: {reason}; the results were kept in {kept} instead")
        self.wanted, self.kept, self.reason = wanted, kept, reason


# temporary files are `.<name>.oceanmc-<pid>-<token>.tmp`: recognisably oceanmc's, and the pid
# tells whether their writer is still alive (a SIGKILLed checkpoint leaves one behind)
_TEMP_NAME = re.compile(r"^\.(?P<name>.+)\.oceanmc-(?P<pid>\d+)-[0-9a-f]+\.tmp$")
_NO_SPACE = (errno.ENOSPC, errno.EDQUOT)


def _temp_path(path: Path) -> Path:
    return path.with_name(f".{path.name}.oceanmc-{os.getpid()}-{secrets.token_hex(4)}.tmp")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's live process
        return True
    return True


def remove_stale_temps(path: Path) -> None:
    """Removes the temporary files of `path` left by oceanmc writers that are no longer alive;
    never those of a live process (this one's included: another thread may be writing)."""
    folder = path.parent if str(path.parent) else Path(".")
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for entry in entries:
        match = _TEMP_NAME.match(entry.name)
        if match and match["name"] == path.name and not _alive(int(match["pid"])):
            Path(entry.path).unlink(missing_ok=True)


def place_atomically(path: str | Path, write: Callable[[Path], None],
                     overwrite: bool = True) -> Path:
    """Writes a file with write(tmp) under a temporary name in the same folder, then puts it at
    `path` in one step: os.replace if overwrite, else os.link, which fails if `path` exists, so
    that two processes never both believe they wrote it. The one that lost keeps its file at
    `<stem>.<pid>[.n]<suffix>` and is told so (ResultsSavedElsewhere), as is a writer whose disk
    filled up (its file goes to the system temporary folder, else the current folder)."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    folder.mkdir(parents=True, exist_ok=True)
    remove_stale_temps(path)
    tmp = _temp_path(path)
    try:
        try:
            _write_temp(tmp, write)
        except OSError as exc:
            if exc.errno not in _NO_SPACE and "No space left" not in str(exc):
                raise
            Path(tmp).unlink(missing_ok=True)
            kept = _write_fallback(path, write)
            raise ResultsSavedElsewhere(path, kept, f"no space left on {folder}") from None
        if overwrite:
            os.replace(tmp, path)
            return path
        try:
            os.link(tmp, path)
            return path
        except FileExistsError:
            kept = _link_free_name(tmp, path)
            raise ResultsSavedElsewhere(
                path, kept, "another process created this file while this one was running "
                "(pass --overwrite to replace it)") from None
    finally:
        tmp.unlink(missing_ok=True)


def _write_temp(tmp: Path, write: Callable[[Path], None]) -> None:
    with open(tmp, "xb"):  # claims the name; the writer reopens it
        pass
    write(tmp)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)


def _link_free_name(tmp: Path, path: Path) -> Path:
    """Links tmp to the first free name `<stem>.<pid>[.n]<suffix>` beside path."""
    for n in range(1000):
        kept = path.with_name(f"{path.stem}.{os.getpid()}{f'.{n}' if n else ''}{path.suffix}")
        try:
            os.link(tmp, kept)
            return kept
        except FileExistsError:
            continue
    raise FileExistsError(f"{path}: no free name to keep the results under")


def _write_fallback(path: Path, write: Callable[[Path], None]) -> Path:
    """Writes the file in the system temporary folder, else the current folder."""
    for folder in (Path(tempfile.gettempdir()), Path.cwd()):
        tmp = _temp_path(folder / path.name)
        try:
            _write_temp(tmp, write)
            return _link_free_name(tmp, folder / path.name)
        except OSError:
            continue
        finally:
            tmp.unlink(missing_ok=True)
    raise OSError(errno.ENOSPC, f"{path}: no space left there, nor in "
                  f"{tempfile.gettempdir()} or {Path.cwd()}; the results are lost")


def save_result(result: Result, path: str | Path, overwrite: bool = True) -> Path:
    """Writes the result atomically (place_atomically); overwrite=False refuses to replace an
    existing file even if one appears while this is being written."""
    def write(tmp: Path) -> None:
        # libver v110: attributes over 64 KB are stored densely. Each dataset attached to a
        # dimension scale adds a reference to the scale's REFERENCE_LIST attribute; with one
        # absorbed_layer_N quantity per layer, the batch scale of 4,100+ layers outgrew the
        # compact 64 KB limit and H5DSattach_scale failed after the whole run.
        with h5py.File(tmp, "w", libver=("v110", "latest")) as f:
            _write(f, result)
    return place_atomically(path, write, overwrite)


def _write(f: h5py.File, result: Result) -> None:
    """Each group holds the coordinates its variables use, as dimension scales, so that
    xarray.open_dataset(path, engine="h5netcdf", group=...) names every dimension."""
    _write_attrs(f, result.attrs)
    f.attrs["format_version"] = FORMAT_VERSION
    n_batches = next(iter(result.quantities.values())).batches.shape[0]
    coords = dict(result.coords, batch=np.arange(n_batches))
    scales: dict[tuple[str, str], h5py.Dataset] = {}

    def scale(group: str, dim: str) -> h5py.Dataset:
        if (group, dim) not in scales:
            ds = f.require_group(group or "/").create_dataset(dim, data=coords[dim])
            ds.make_scale(dim)
            ds.attrs["units"], ds.attrs["description"] = COORD_UNITS[dim]
            scales[group, dim] = ds
            auxiliary = auxiliary_of((dim,))
            if auxiliary:
                # named here too, so that xarray makes them coordinates even in a group where
                # no variable uses the dimension (no local directions)
                ds.attrs["coordinates"] = " ".join(auxiliary)
            for aux in auxiliary if group else ():  # the root's come with the other coordinates
                write(f"{group}/{aux}", coords[aux], (dim,), *COORD_UNITS[aux])
        return scales[group, dim]

    def auxiliary_of(dims: tuple[str, ...]) -> list[str]:
        return [aux for aux, dim in AUXILIARY_COORDS.items() if dim in dims]

    def write(name: str, values: np.ndarray, dims: tuple[str, ...], units: str, desc: str,
              **options) -> h5py.Dataset:
        ds = f.create_dataset(name, data=values, **options)
        ds.attrs["units"] = units
        ds.attrs["description"] = desc
        group = name.rpartition("/")[0]
        for axis, dim in enumerate(dims):
            ds.dims[axis].attach_scale(scale(group, dim))
        # CF auxiliary coordinates (direction_theta of `direction`): xarray's coordinates
        if auxiliary_of(dims) and name.rpartition("/")[2] not in AUXILIARY_COORDS:
            ds.attrs["coordinates"] = " ".join(auxiliary_of(dims))
        return ds

    for name, values in result.coords.items():
        if name in AUXILIARY_COORDS:
            write(name, values, (AUXILIARY_COORDS[name],), *COORD_UNITS[name])
        else:
            scale("", name)
    for q in result.quantities.values():
        write(q.name, q.mean, q.dims, q.units, q.description)
        write(q.name + "_stderr", q.stderr, q.dims, q.units,
              f"standard error of {q.name} over batches")
        ds = write("batches/" + q.name, q.batches, ("batch",) + q.dims, q.units,
                   f"per-batch values of {q.name}", compression="gzip", compression_opts=4,
                   shuffle=True)
        ds.attrs["dims"] = ",".join(q.dims)
    if result.resume_state is not None:
        group = f.create_group(RESUME_GROUP)
        group.attrs["description"] = RESUME_DESCRIPTION
        for name, values in result.resume_state.items():   # a key tally/<name> lands in group tally
            group.create_dataset(name, data=values)
    if result.iops:
        _write_iops(f.create_group("iops"), result.iops)
    write_derived(f, result)


IOPS_COORDS = {"layer_top": ("m", "depth of the top of each homogeneous layer (a depth profile "
                                  "is resolved into several)"),
               "wavelength": ("nm", "wavelength in vacuum (NaN: a monochromatic scene)")}
IOPS_VALUES = {"a": "absorption coefficient", "b": "scattering coefficient",
               "bb": "backscattering coefficient", "c": "beam attenuation coefficient a + b"}


def _write_iops(group: h5py.Group, iops: dict[str, np.ndarray]) -> None:
    """The IOPs the run used, per layer and wavelength, with their own dimension scales."""
    for dim, (units, description) in IOPS_COORDS.items():
        ds = group.create_dataset(dim, data=iops[dim])
        ds.make_scale(dim)
        ds.attrs["units"], ds.attrs["description"] = units, description
    thickness = group.create_dataset("layer_thickness", data=iops["layer_thickness"])
    thickness.attrs["units"] = "m"
    thickness.attrs["description"] = "thickness of each layer (inf: infinitely deep)"
    thickness.dims[0].attach_scale(group["layer_top"])
    for name, description in IOPS_VALUES.items():
        ds = group.create_dataset(name, data=iops[name])
        ds.attrs["units"], ds.attrs["description"] = "1/m", description
        ds.dims[0].attach_scale(group["layer_top"])
        ds.dims[1].attach_scale(group["wavelength"])
    if "bottom_reflectance" in iops:
        ds = group.create_dataset("bottom_reflectance", data=iops["bottom_reflectance"])
        ds.attrs["units"] = "1"
        ds.attrs["description"] = ("the bottom's reflectance at each wavelength as the run used "
                                   "it (a mixture's fraction-weighted)")
        ds.dims[0].attach_scale(group["wavelength"])


class ResultsFileError(ValueError):
    """A file that is not a results file this version of oceanmc can read; the message says
    what is wrong, in one line."""


def load_result(path: str | Path) -> Result:
    """Reads a results file written by Result.save back into the same Result. Raises
    ResultsFileError (one line) for a file of another format version or one whose structure is
    not what save_result writes (missing datasets or attributes, wrong shapes or types, links)."""
    path = Path(path)
    try:
        with h5py.File(path, "r") as f:
            version = _plain(f.attrs.get("format_version"))
            if version != FORMAT_VERSION:
                raise ResultsFileError(
                    "no format_version attribute: not an oceanmc results file" if version is None
                    else f"format_version {version!r}; this oceanmc reads format_version "
                         f"{FORMAT_VERSION}")
            return _read(f)
    except ResultsFileError:
        raise
    except RecursionError:
        raise ResultsFileError("nested too deeply to be a results file") from None
    except (OSError, KeyError, ValueError, TypeError, AttributeError, IndexError) as exc:
        # h5py reports a missing dataset, a dangling or external link, a truncated file as
        # OSError/KeyError; a wrong dtype or shape surfaces as ValueError/TypeError below
        detail = " ".join(str(exc).split()) or type(exc).__name__
        raise ResultsFileError(f"not an oceanmc results file ({detail[:200]})") from None


def _dataset(group: h5py.Group, name: str, kind: str = "fc") -> np.ndarray:
    """group[name] as an array, refusing links to other files and non-numeric data."""
    link = group.get(name, getlink=True)
    if link is None:
        raise KeyError(f"dataset {group.name.rstrip('/')}/{name} is missing")
    if not isinstance(link, h5py.HardLink):
        raise ValueError(f"{group.name.rstrip('/')}/{name} is a {type(link).__name__}, "
                         "not a dataset")
    obj = group[name]
    if not isinstance(obj, h5py.Dataset) or obj.dtype.kind not in kind:
        raise ValueError(f"{obj.name} is not a numeric dataset")
    return obj[()]


def _read(f: h5py.File) -> Result:
    attrs = {k: _plain(v) for k, v in f.attrs.items() if k != "format_version"}
    for key in ("config_yaml", "batches"):
        if key not in attrs:
            raise KeyError(f"attribute {key} is missing")
    _check_attrs(attrs)
    try:  # merge and resume compare the stored scenes as mappings
        scene = yaml.safe_load(attrs["config_yaml"]) if isinstance(attrs["config_yaml"], str) \
            else None
    except yaml.YAMLError:
        scene = None
    if not isinstance(scene, dict):
        raise ValueError("attribute config_yaml does not hold a scene")
    # the wavelength coordinate is in spectral files only; every other one is required
    coords = {name: _dataset(f, name, "fciu") for name in COORD_UNITS
              if name != "batch" and (name != "wavelength" or name in f)}
    quantities = {}

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            if "dims" not in obj.attrs:
                return  # a coordinate of the batches group
            dims = dims_of(obj)
            values = _dataset(obj.parent, obj.name.rsplit("/", 1)[1], "fciub")
            if values.ndim != len(dims) + 1:  # batch first, then the named dimensions
                raise ValueError(f"{obj.name} has {values.ndim} axes, not {len(dims) + 1}")
            quantities[name] = Quantity(name, dims, values, str(_plain(obj.attrs["units"])),
                                        str(_plain(f[name].attrs["description"])))
    f["batches"].visititems(visit)
    resume_state = None if RESUME_GROUP not in f else _read_resume(f[RESUME_GROUP])
    iops = {name: _dataset(f["iops"], name) for name in f["iops"]} if "iops" in f else {}
    return Result(coords, quantities, attrs, resume_state, iops)


def _read_resume(group: h5py.Group) -> dict[str, np.ndarray]:
    state = {name: _dataset(group, name, "fciu") for name in RESUME_FIELDS}
    if isinstance(group.get("tally", getlink=True), h5py.HardLink) \
            and isinstance(group["tally"], h5py.Group):
        state.update({f"tally/{name}": _dataset(group["tally"], name) for name in group["tally"]})
    else:
        # an earlier oceanmc's raw tally rows, whose layout cannot be known: kept as stored,
        # so that check_resumable refuses to continue them (the whole batches stay readable)
        state["tally"] = _dataset(group, "tally")
    return state


# the attributes the summary, merge and --resume read, and what each must be where present
COUNT_ATTRS = ("batches", "photons", "threads", "seed", "first_batch", "photons_per_batch",
               "scattering_events", "merged_from")
SECONDS_ATTRS = ("wall_time_s", "startup_time_s", "photons_per_s")
LIST_ATTRS = {"seeds": re.compile(r"\d+(,\d+)*"),
              "batch_ranges": re.compile(r"\d+:\d+:\d+(,\d+:\d+:\d+)*")}


def _check_attrs(attrs: dict) -> None:
    for key in COUNT_ATTRS + SECONDS_ATTRS:
        if key not in attrs and key != "merged_from":   # merged_from: merged files only
            raise KeyError(f"attribute {key} is missing")
    for key in COUNT_ATTRS:
        value = attrs.get(key, 0)
        if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value < 2**62:
            raise ValueError(f"attribute {key} is not an integer >= 0")
    for key in SECONDS_ATTRS:
        value = attrs.get(key, 0.0)
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not value >= 0:
            raise ValueError(f"attribute {key} is not a number >= 0")
    for key, pattern in LIST_ATTRS.items():
        if key in attrs and not (isinstance(attrs[key], str) and pattern.fullmatch(attrs[key])):
            raise ValueError(f"attribute {key} is not a list like {pattern.pattern}")
    if not isinstance(attrs.get("partial", False), (bool, int)):
        raise ValueError("attribute partial is not a boolean")
    for key in ("name", "data_files_sha256"):
        if not isinstance(attrs.get(key, ""), str):
            raise ValueError(f"attribute {key} is not text")
    if not attrs.get("name", "").isprintable():   # show prints it: no escapes, no surrogates
        raise ValueError("attribute name holds unprintable characters")


def dims_of(dataset: h5py.Dataset) -> tuple[str, ...]:
    return tuple(d for d in _plain(dataset.attrs["dims"]).split(",") if d)


def _plain(value):
    if isinstance(value, bytes):
        return value.decode("utf-8")
    if isinstance(value, np.generic):
        return value.item()
    return value
