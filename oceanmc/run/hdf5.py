"""Results files read back: load_result(path) -> the Result that format.save_result wrote, every
part of the file checked against the format (format.py) so that a file of another version or a
damaged one is refused in one line (ResultsFileError).

`oceanmc.run.hdf5` is where users find both save_result and load_result (README: Migration)."""
from __future__ import annotations

import re
from pathlib import Path

import h5py
import numpy as np
import yaml

from .format import (COORD_UNITS, FORMAT_VERSION, SWEEP_DATASET_MESSAGE, RESUME_FIELDS,
                     RESUME_GROUP, SWEEP_TITLE)
from .format import save_result  # noqa: F401  (the documented path: oceanmc.run.hdf5)
from .result import Quantity, Result


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
            if version is None and _plain(f.attrs.get("title")) == SWEEP_TITLE:
                raise ResultsFileError(SWEEP_DATASET_MESSAGE)
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
    except (OSError, KeyError, ValueError, TypeError, AttributeError, IndexError,
            RuntimeError) as exc:
        # h5py reports a missing dataset, a dangling or external link, a truncated file as
        # OSError/KeyError; a wrong dtype or shape surfaces as ValueError/TypeError below; a
        # damaged one as RuntimeError ('Object visitation failed (incorrect metadata
        # checksum)': a user's review, show, merge and --resume gave a traceback)
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


def _datasets_within(group: h5py.Group, prefix: str = "") -> dict[str, np.ndarray]:
    """Every dataset under `group` by its path below it (a run with inelastic light keeps each
    part's tally arrays in a group of its own: part1/flux, ...), refusing links as _dataset
    does."""
    out = {}
    for name in group:
        link = group.get(name, getlink=True)
        if isinstance(link, h5py.HardLink) and isinstance(group[name], h5py.Group):
            out.update(_datasets_within(group[name], f"{prefix}{name}/"))
        else:
            out[prefix + name] = _dataset(group, name)
    return out


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
        state.update({f"tally/{name}": values
                      for name, values in _datasets_within(group["tally"]).items()})
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
