"""The results file's format: what an HDF5 results file holds and where, and a Result written
into it with h5py (save_result), atomically (placement.py), with dimension scales attached so
that xarray.open_dataset(path, engine="h5netcdf") names every dimension. hdf5.py reads it back.

The writing takes any Result (result.py) without importing its module, which imports this one
for Result.save."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from .derived import write_derived
from .placement import place_atomically

FORMAT_VERSION = 1
# the title attribute of a sweep's dataset (sweeps/dataset.py), and what show and plot say of
# such a file
SWEEP_TITLE = "oceanmc sweep"
SWEEP_DATASET_MESSAGE = ("an oceanmc sweep dataset (NetCDF), not the results file of one "
                         "run: open it with xarray.open_dataset (README, Sweeps); a point's own "
                         "results file is in the sweep's points folder")

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


def save_result(result, path: str | Path, overwrite: bool = True) -> Path:
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


def _write(f: h5py.File, result) -> None:
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
        # gzip at level 1 without the shuffle filter: faster to write and smaller than level 4
        # with it (measured on 20,000-photon runs of configs/: raman_fluorescence.yaml's 12
        # million values, 70% zeros, 0.49 s and 27.6 MB against 1.06 s and 31.3 MB;
        # windy_case1.yaml 0.066 s, 3.5 MB against 0.141 s, 4.2 MB)
        ds = write("batches/" + q.name, q.batches, ("batch",) + q.dims, q.units,
                   f"per-batch values of {q.name}", compression="gzip", compression_opts=1)
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
        ds.attrs["units"], ds.attrs["description"] = "m-1", description
        ds.dims[0].attach_scale(group["layer_top"])
        ds.dims[1].attach_scale(group["wavelength"])
    if "bottom_reflectance" in iops:
        ds = group.create_dataset("bottom_reflectance", data=iops["bottom_reflectance"])
        ds.attrs["units"] = "1"
        ds.attrs["description"] = ("the bottom's reflectance rho at each wavelength as the run "
                                   "used it (a mixture's fraction-weighted): a lambertian "
                                   "bottom's Eu/Ed, a minnaert bottom's scale (it reflects "
                                   "2 rho cos^k t_i / (k + 2))")
        ds.dims[0].attach_scale(group["wavelength"])
