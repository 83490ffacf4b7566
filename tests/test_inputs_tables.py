"""Malformed sky map and BRDF table files: one TableError naming the file, never a traceback
or a huge allocation (an .npy header may claim 10^10 values in a file of a few bytes)."""
import zipfile

import h5py
import numpy as np
import pytest

from oceanmc.scene.phase_tables import TableError
from oceanmc.scene.sky_maps import read_sky_map


def _huge_npy_header() -> bytes:
    header = "{'descr': '<f8', 'fortran_order': False, 'shape': (100000, 100000), }"
    header += " " * (63 - (10 + len(header)) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header.encode() + bytes(8)


def test_npy_header_claiming_ten_billion_values_is_refused(tmp_path):
    path = tmp_path / "sky.npy"
    path.write_bytes(_huge_npy_header())
    with pytest.raises(TableError, match=r"sky.npy.*claims shape \(100000, 100000\)"):
        read_sky_map(path)


def test_same_header_inside_an_npz_is_refused(tmp_path):
    path = tmp_path / "sky.npz"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("radiance.npy", _huge_npy_header())
    with pytest.raises(TableError, match="claims shape"):
        read_sky_map(path)


@pytest.mark.parametrize("content", [b"PK\x03\x04 not really a zip", b"garbage" * 10])
def test_corrupt_npz_is_refused(tmp_path, content):
    path = tmp_path / "sky.npz"
    path.write_bytes(content)
    with pytest.raises(TableError, match="cannot read it as .npz"):
        read_sky_map(path)


def test_truncated_npz_is_refused(tmp_path):
    path = tmp_path / "sky.npz"
    np.savez(path, radiance=np.ones((9, 36)))
    path.write_bytes(path.read_bytes()[:200])
    with pytest.raises(TableError, match="sky.npz"):
        read_sky_map(path)


def test_valid_npz_still_reads(tmp_path):
    path = tmp_path / "sky.npz"
    np.savez(path, radiance=np.ones((9, 36)))
    theta, phi, radiance = read_sky_map(path)
    assert radiance.shape == (9, 36) and theta[-1] == 90.0


@pytest.mark.parametrize("link", ["soft", "external"])
def test_links_in_an_hdf5_map_are_not_followed(tmp_path, link):
    path = tmp_path / "sky.h5"
    with h5py.File(path, "w") as f:
        f["radiance"] = h5py.SoftLink("/nowhere") if link == "soft" \
            else h5py.ExternalLink("/etc/passwd", "/x")
    with pytest.raises(TableError, match="no array 'radiance'"):
        read_sky_map(path)


def test_string_array_is_refused(tmp_path):
    path = tmp_path / "sky.npy"
    np.save(path, np.array([["a", "b"], ["c", "d"]]))
    with pytest.raises(TableError, match="not real numbers"):
        read_sky_map(path)


def test_brdf_table_uses_the_same_bounded_reader(tmp_path):
    from oceanmc.scene.brdf_tables import _load_arrays
    path = tmp_path / "brdf.npz"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("brdf.npy", _huge_npy_header())
    with pytest.raises(TableError, match=r"BRDF table .*brdf.npz.*claims shape"):
        _load_arrays(path)
    path.write_bytes(b"PK\x03\x04 broken")
    with pytest.raises(TableError, match="cannot read it as .npz"):
        _load_arrays(path)
