"""Crafted results files given to show, merge and --resume: one line (exit 2) naming what is
wrong, never a traceback; refusals of a different scene name the key that differs."""
import shutil

import h5py
import numpy as np
import pytest

import oceanmc
from oceanmc.cli import main
from oceanmc.run.hdf5 import ResultsFileError, load_result
from oceanmc.run.results import MergeError, merge_results


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    from conftest import SMALL_SCENE
    return oceanmc.simulate(SMALL_SCENE).save(tmp_path_factory.mktemp("r") / "run.h5")


def _edit_copy(saved, tmp_path, edit):
    path = tmp_path / "crafted.h5"
    shutil.copy(saved, path)
    with h5py.File(path, "r+") as f:
        edit(f)
    return path


def _set_attr(name, value):
    def edit(f):
        f.attrs[name] = value
    return edit


def _delete(name):
    def edit(f):
        del f[name]
    return edit


def _replace(name, value):
    def edit(f):
        del f[name]
        f[name] = value
    return edit


def _soft_link(name, target):
    def edit(f):
        del f[name]
        f[name] = h5py.SoftLink(target)
    return edit


def _external_link(name):
    def edit(f):
        del f[name]
        f[name] = h5py.ExternalLink("/etc/passwd", "/x")
    return edit


CRAFTED = {
    "other format_version": (_set_attr("format_version", 99), "format_version 99"),
    "no format_version": (lambda f: f.attrs.__delitem__("format_version"),
     "no format_version"),
    "missing coordinate": (_delete("depth"), "depth is missing"),
    "dangling link": (_soft_link("depth", "/nowhere"), "SoftLink"),
    "external link": (_external_link("depth"), "ExternalLink"),
    "string coordinate": (_replace("depth", np.array([b"a", b"b"])), "not a numeric dataset"),
    "wrong batch shape": (lambda f: f["batches/Ed"].attrs.__setitem__("dims", "a,b,c,d,e,f"),
                          "axes"),
    "config not a scene": (_set_attr("config_yaml", "[1, 2"), "config_yaml"),
    "batches not an integer": (_set_attr("batches", "many"), "batches is not an integer"),
}


@pytest.mark.parametrize("case", sorted(CRAFTED))
def test_crafted_file_is_refused_in_one_line(saved, tmp_path, case, capsys):
    edit, expected = CRAFTED[case]
    path = _edit_copy(saved, tmp_path, edit)
    with pytest.raises(ResultsFileError, match=expected):
        load_result(path)
    for argv in (["show", str(path)], ["merge", str(path), str(saved), "-o",
                                       str(tmp_path / "m.h5")]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and expected.split()[0] in err and "Traceback" not in err
        assert err.count("results file") <= 1  # said once, not nested


def test_truncated_and_garbage_files_are_refused(saved, tmp_path, capsys):
    truncated = tmp_path / "truncated.h5"
    truncated.write_bytes(saved.read_bytes()[:5000])
    garbage = tmp_path / "garbage.h5"
    garbage.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(3000))
    for path in (truncated, garbage):
        assert main(["show", str(path)]) == 2
        assert capsys.readouterr().err.strip().count("\n") == 0


def test_merge_names_the_key_that_differs(small_scene):
    a = oceanmc.simulate(dict(small_scene, seed=1))
    small_scene["bottom"]["reflectance"] = 0.5
    b = oceanmc.simulate(dict(small_scene, seed=2))
    with pytest.raises(MergeError, match=r"different scene .*bottom\.reflectance differs"):
        merge_results([a, b])
