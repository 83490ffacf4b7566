"""`oceanmc plot`: the figures of a real monochromatic run and of a synthetic spectral file (the
layout of spectral results: a leading `wavelength` dimension), the PNGs the command writes and
its one-line errors."""
import os
import struct
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr

from conftest import REPO, SMALL_SCENE
from oceanmc.cli import main
from oceanmc.config.tallies import HYDROLIGHT_THETA_EDGES_DEG
from oceanmc.plot import DPI, close
from oceanmc.plot.results import (MAX_PROFILE_WAVELENGTHS, kd_r_figure, open_result,
                                  profiles_figure, radiance_figure, rrs_figure,
                                  wavelength_indices)

WAVELENGTHS = np.arange(400.0, 701.0, 10.0)
SPECTRAL_DEPTHS = np.array([0.0, 2.0, 5.0])


@pytest.fixture(scope="module")
def mono_file(tmp_path_factory):
    """A real (small) monochromatic run."""
    import oceanmc
    result = oceanmc.simulate(oceanmc.load_config(SMALL_SCENE), threads=1)
    return result.save(tmp_path_factory.mktemp("mono") / "mono.h5")


@pytest.fixture(scope="module")
def spectral_file(tmp_path_factory):
    """A synthetic spectral results file: every spectral quantity with a leading wavelength
    dimension, values chosen so that each wavelength and depth is told apart."""
    theta_edges = np.array(HYDROLIGHT_THETA_EDGES_DEG)
    phi_edges = np.arange(-7.5, 360.0, 15.0)
    theta = 0.5 * (theta_edges[1:] + theta_edges[:-1])
    phi = 0.5 * (phi_edges[1:] + phi_edges[:-1])
    k = 0.02 + 1e-4 * (WAVELENGTHS - 400.0)                # attenuation per wavelength (1/m)
    ed = np.exp(-np.outer(k, SPECTRAL_DEPTHS))             # (wavelength, depth)
    shape = (len(WAVELENGTHS), len(SPECTRAL_DEPTHS), len(theta), len(phi))
    radiance = 1.0 + np.arange(np.prod(shape), dtype=np.float64).reshape(shape)
    spectral = {"wavelength": WAVELENGTHS}
    water = xr.Dataset(
        {name: (("wavelength", "depth"), scale * ed) for name, scale in
         (("Ed", 1.0), ("Ed_stderr", 0.01), ("Eu", 0.05), ("Eu_stderr", 0.001),
          ("Eo", 1.3), ("Eo_stderr", 0.02))}
        | {"radiance": (("wavelength", "depth", "theta", "phi"), radiance),
           "radiance_stderr": (("wavelength", "depth", "theta", "phi"), 0.01 * radiance)},
        coords=spectral | {"depth": SPECTRAL_DEPTHS, "theta": theta, "phi": phi,
                           "theta_edges": theta_edges, "phi_edges": phi_edges},
        attrs={"format_version": 1, "name": "synthetic spectrum"})
    rrs = 0.005 * np.exp(-((WAVELENGTHS - 490.0) / 80.0) ** 2)
    air = xr.Dataset({"Rrs_nadir": ("wavelength", rrs), "Rrs_nadir_stderr": ("wavelength",
                                                                             0.05 * rrs),
                      "radiance": (("wavelength", "theta", "phi"), 2.0 * radiance[:, 0])},
                     coords=spectral | {"theta": theta, "phi": phi})
    path = tmp_path_factory.mktemp("spectral") / "spectral.h5"
    water.to_netcdf(path, engine="h5netcdf")
    air.to_netcdf(path, engine="h5netcdf", group="air", mode="a")
    return path


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


def polar_axes(fig):
    return [ax for ax in fig.axes if ax.name == "polar"]


# --- the figures --------------------------------------------------------------------------------

def test_rrs_spectrum_line_and_standard_error_band(spectral_file):
    result = open_result(spectral_file)
    fig = rrs_figure(result)
    (ax,) = fig.axes
    (line,) = ax.get_lines()
    np.testing.assert_array_equal(line.get_xdata(), WAVELENGTHS)
    np.testing.assert_allclose(line.get_ydata(), result.air["Rrs_nadir"])
    (band,) = ax.collections                               # fill_between: value +- stderr
    lower = band.get_paths()[0].vertices[:, 1].min()
    assert lower == pytest.approx(float((result.air["Rrs_nadir"]
                                         - result.air["Rrs_nadir_stderr"]).min()))
    close(fig)


def test_rrs_monochromatic_is_one_marker(mono_file):
    result = open_result(mono_file)
    fig = rrs_figure(result)
    (ax,) = fig.axes
    (bars,) = ax.containers
    marker = bars.lines[0]
    assert marker.get_ydata()[0] == pytest.approx(float(result.air["Rrs_nadir"]))
    assert len(marker.get_xdata()) == 1
    close(fig)


def test_profiles_spectral_lines_per_wavelength(spectral_file):
    result = open_result(spectral_file)
    indices = wavelength_indices(result, None)
    assert len(indices) == MAX_PROFILE_WAVELENGTHS
    assert WAVELENGTHS[indices[0]] == 400.0 and WAVELENGTHS[indices[-1]] == 700.0
    fig = profiles_figure(result, indices)
    assert [ax.get_title() for ax in fig.axes] == ["downward plane irradiance Ed",
                                                   "upward plane irradiance Eu",
                                                   "scalar irradiance Eo"]
    for ax, name in zip(fig.axes, ("Ed", "Eu", "Eo")):
        assert ax.get_xscale() == "log" and ax.yaxis_inverted()
        assert len(ax.containers) == MAX_PROFILE_WAVELENGTHS
        for bars, i in zip(ax.containers, indices):
            np.testing.assert_allclose(bars.lines[0].get_xdata(), result.water[name][i])
            np.testing.assert_array_equal(bars.lines[0].get_ydata(), SPECTRAL_DEPTHS)
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert legend == [f"{WAVELENGTHS[i]:g} nm" for i in indices]
    close(fig)
    fig = profiles_figure(result, wavelength_indices(result, 550.0))
    assert [len(ax.containers) for ax in fig.axes] == [1, 1, 1]
    close(fig)


def test_a_notebook_passes_the_path_and_takes_the_defaults(mono_file, spectral_file):
    # as the README says: each figure function from a results file's path, with the profiles'
    # wavelengths and the radiance's depth and wavelength chosen as `oceanmc plot` chooses them
    spectral = open_result(spectral_file)
    fig = profiles_figure(str(spectral_file))
    assert [len(ax.containers) for ax in fig.axes] == [MAX_PROFILE_WAVELENGTHS] * 3
    close(fig)
    fig = radiance_figure(spectral_file)
    assert fig.axes[0].get_title() == radiance_figure(spectral, 0, 15).axes[0].get_title()
    close(fig)
    for figure in (rrs_figure, kd_r_figure):
        close(figure(spectral_file))
    assert kd_r_figure(mono_file) is None   # (Kd, R against wavelength: a spectral file's)
    close(rrs_figure(mono_file))
    close(profiles_figure(mono_file))


def test_profiles_monochromatic(mono_file):
    result = open_result(mono_file)
    fig = profiles_figure(result, wavelength_indices(result, None))
    assert len(fig.axes) == 3
    for ax, name in zip(fig.axes, ("Ed", "Eu", "Eo")):
        (bars,) = ax.containers
        np.testing.assert_allclose(bars.lines[0].get_xdata(), result.water[name])
        np.testing.assert_array_equal(bars.lines[0].get_ydata(), SMALL_SCENE["tallies"]
                                      ["depths_m"])
    close(fig)


def test_radiance_hemispheres_at_depth_and_in_air(spectral_file):
    result = open_result(spectral_file)
    fig = radiance_figure(result, depth=1, wavelength=3)
    axes = polar_axes(fig)
    assert len(axes) == 4                                  # (depth, 0+) x (down, up)
    meshes = [ax.collections[0].get_array().reshape(10, 24) for ax in axes]
    at_depth = result.water["radiance"].values[3, 1]       # (theta, phi), 20 bands
    np.testing.assert_array_equal(meshes[0], at_depth[:10])
    np.testing.assert_array_equal(meshes[1], at_depth[10:][::-1])   # nadir at the centre
    in_air = result.air["radiance"].values[3]
    np.testing.assert_array_equal(meshes[2], in_air[:10])
    np.testing.assert_array_equal(meshes[3], in_air[10:][::-1])
    assert "430 nm" in fig.get_suptitle() and "2 m" in axes[0].get_title()
    close(fig)


def test_radiance_monochromatic_real_run(mono_file):
    result = open_result(mono_file)
    fig = radiance_figure(result, depth=0, wavelength=None)
    axes = polar_axes(fig)
    assert len(axes) == 4
    radiance = result.water["radiance"].values[0]
    mesh = axes[0].collections[0].get_array().reshape(10, -1)
    np.testing.assert_array_equal(mesh.filled(np.nan), np.where(radiance[:10] > 0,
                                                                radiance[:10], np.nan))
    close(fig)


# --- the command --------------------------------------------------------------------------------

EXPECTED_INCHES = {"rrs": (3.5, 4.0), "profiles": (12.6, 4.6), "radiance": (9.2, 8.4)}


def test_command_writes_pngs_of_the_figure_size(mono_file, tmp_path):
    env = dict(os.environ, PYTHONPATH=str(REPO))
    done = subprocess.run([sys.executable, "-m", "oceanmc", "plot", str(mono_file), "-o",
                           str(tmp_path / "figs") + "/"], env=env, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    for name, (width, height) in EXPECTED_INCHES.items():
        png = tmp_path / "figs" / f"mono_{name}.png"
        assert f"wrote {png}" in done.stdout
        assert png.stat().st_size > 10_000
        w, h = png_size(png)
        assert abs(w - width * DPI) <= 1 and abs(h - height * DPI) <= 1, (name, w, h)


def test_command_spectral_with_prefix_and_options(spectral_file, tmp_path, capsys):
    prefix = tmp_path / "sub" / "fig"
    assert main(["plot", str(spectral_file), "-o", str(prefix), "--depth", "5",
                 "--wavelength", "550"]) == 0
    written = sorted(tmp_path.joinpath("sub").glob("*.png"))
    assert [p.name for p in written] == ["fig_profiles.png", "fig_radiance.png", "fig_rrs.png"]
    w, h = png_size(tmp_path / "sub" / "fig_rrs.png")
    assert abs(w - 6.0 * DPI) <= 1 and abs(h - 4.0 * DPI) <= 1
    assert all(p.stat().st_size > 10_000 for p in written)


def one_line_error(capsys, argv):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("oceanmc: error: "), err
    return err


def test_errors_name_the_problem(mono_file, spectral_file, tmp_path, capsys):
    err = one_line_error(capsys, ["plot", str(tmp_path / "none.h5")])
    assert "none.h5: no such file" in err
    text = tmp_path / "notes.h5"
    text.write_text("not hdf5")
    assert "not an oceanmc results file" in one_line_error(capsys, ["plot", str(text)])
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f["x"] = np.arange(3)
    assert "not an oceanmc results file" in one_line_error(capsys, ["plot", str(other)])
    err = one_line_error(capsys, ["plot", str(mono_file), "--depth", "3"])
    assert "--depth 3: not a tallied depth" in err and "allowed: 0, 1, 2 (m)" in err
    err = one_line_error(capsys, ["plot", str(mono_file), "--wavelength", "550"])
    assert "--wavelength 550" in err and "monochromatic" in err
    err = one_line_error(capsys, ["plot", str(spectral_file), "--wavelength", "555"])
    assert "--wavelength 555: not a wavelength" in err and "allowed: 400, 410," in err
    assert not list(tmp_path.glob("*.png"))


def test_file_without_radiance_draws_the_rest(mono_file, tmp_path, capsys):
    bare = tmp_path / "bare.h5"
    bare.write_bytes(mono_file.read_bytes())
    with h5py.File(bare, "a") as f:
        for name in ("radiance", "radiance_stderr", "air/radiance", "air/radiance_stderr"):
            del f[name]
    assert main(["plot", str(bare)]) == 0
    captured = capsys.readouterr()
    assert "bare.h5 has no radiance" in captured.err and captured.err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["bare_profiles.png",
                                                             "bare_rrs.png"]


def test_a_run_without_tally_depths_draws_its_rrs_and_says_why_not_the_rest(tmp_path,
                                                                               capsys):
    """tallies.depths_m: [] leaves nothing to draw in the water: the Rrs figure alone, and a
    note for each other figure naming the key (no IndexError)."""
    import oceanmc
    config = dict(SMALL_SCENE, photons=2000, tallies={"depths_m": []})
    path = oceanmc.simulate(oceanmc.load_config(config), threads=1).save(tmp_path / "air.h5")
    assert main(["plot", str(path)]) == 0
    err = capsys.readouterr().err
    assert "has no Ed at any depth (tallies.depths_m: []); no profiles figure" in err
    assert "has no radiance in the water" in err and "tallies.depths_m: []" in err
    assert [p.name for p in tmp_path.glob("*.png")] == ["air_rrs.png"]


def _copy(source, target):
    target.write_bytes(source.read_bytes())
    return target


def test_all_nan_is_refused_and_a_nan_figure_is_left_out(mono_file, tmp_path, capsys):
    """A file whose every value to plot is NaN (a run stopped before its first whole batch) is
    refused in one line, exit 2, no PNG; one figure's quantity all NaN: that figure is left out
    with a one-line note on stderr, the others drawn."""
    from oceanmc.run.hdf5 import load_result
    empty = load_result(mono_file)
    for q in empty.quantities.values():
        q.batches = q.batches[:0]
    empty.attrs.update(batches=0, partial=True, photons=0)
    stopped = empty.save(tmp_path / "stopped.h5")
    err = one_line_error(capsys, ["plot", str(stopped)])
    assert "stopped.h5: every value to plot is NaN (a partial file with no whole batch yet" in err
    assert "nothing to plot" in err and not list(tmp_path.glob("*.png"))

    no_rrs = _copy(mono_file, tmp_path / "no_rrs.h5")
    with h5py.File(no_rrs, "a") as f:
        f["air/Rrs_nadir"][...] = np.nan
    assert main(["plot", str(no_rrs)]) == 0
    err = capsys.readouterr().err
    assert err == f"oceanmc: plot: {no_rrs} holds only NaN in air/Rrs_nadir; no rrs figure\n"
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["no_rrs_profiles.png",
                                                             "no_rrs_radiance.png"]


def test_a_partial_file_says_so_in_every_figure(mono_file, tmp_path):
    """A stopped run's file (attribute partial) is drawn from its whole batches, and each figure
    says so in its corner with the batches it has of those asked for, as `oceanmc show` does,
    whether `oceanmc plot` or a notebook draws it (a user's review: the notebook's did not); a
    whole file's figures carry no such line, and a Result in hand is drawn as its file is."""
    from oceanmc.plot import close
    from oceanmc.plot.results import (profiles_figure, radiance_figure, rrs_figure)
    from oceanmc.run.hdf5 import load_result
    stopped = load_result(mono_file)
    for q in stopped.quantities.values():
        q.batches = q.batches[:5]
    stopped.attrs.update(batches=5, partial=True)
    path = stopped.save(tmp_path / "stopped.h5")
    asked = load_result(mono_file).attrs["batches"]
    for source, expected in ((path, [f"PARTIAL: 5 of {asked} batches whole (a stopped run)"]),
                             (stopped, [f"PARTIAL: 5 of {asked} batches whole (a stopped run)"]),
                             (mono_file, [])):
        for figure in (rrs_figure, profiles_figure, radiance_figure):
            fig = figure(source)
            said = [t.get_text() for t in fig.texts if t.get_text().startswith("PARTIAL")]
            assert said == expected, figure
            close(fig)


def test_a_notebook_s_figures_refuse_what_they_cannot_draw_in_one_line(mono_file, spectral_file,
                                                                      tmp_path):
    """From a notebook (a user's review): a file with no whole batch gave a blank figure and a
    numpy warning, radiance_figure's depth in metres numpy's IndexError, and something other
    than a file AttributeError; each is a PlotInputError saying what the figures take."""
    from oceanmc.plot.results import PlotInputError, radiance_figure, rrs_figure
    from oceanmc.run.hdf5 import load_result
    empty = load_result(mono_file)
    for q in empty.quantities.values():
        q.batches = q.batches[:0]
    empty.attrs.update(batches=0, partial=True, photons=0)
    path = empty.save(tmp_path / "empty.h5")
    with pytest.raises(PlotInputError, match="a partial file with no whole batch yet"):
        rrs_figure(path)
    depths = load_result(mono_file).coords["depth"]
    for depth in (5.0, len(depths), -1):
        with pytest.raises(PlotInputError, match=rf"depth = {depth!r}: the index of one of the "
                                                 rf"file's depths, an integer 0 \.\. "
                                                 rf"{len(depths) - 1} \(m: .*`oceanmc plot` "
                                                 "takes --depth in metres"):
            radiance_figure(mono_file, depth=depth)
    with pytest.raises(PlotInputError, match="dict: the figures take a results file's path"):
        rrs_figure({"air": None})
    # a wavelength index for a monochromatic file, or one a spectral file lacks
    from oceanmc.plot.results import profiles_figure
    for call in (lambda: radiance_figure(mono_file, wavelength=0),
                 lambda: profiles_figure(mono_file, indices=[0])):
        with pytest.raises(PlotInputError, match="wavelength = 0: mono.h5 holds one wavelength"):
            call()
    a_result = load_result(mono_file)
    with pytest.raises(PlotInputError, match="the Result of .* holds one wavelength"):
        radiance_figure(a_result, wavelength=0)
    with pytest.raises(PlotInputError, match=r"wavelength = 99: the index of one of the file's "
                                             r"wavelengths, an integer 0 \.\. "):
        profiles_figure(spectral_file, indices=[0, 99])


LONG_NAME = ("clear oligotrophic water with Petzold particles and a Fournier-Forand tail over "
             "a Lambertian sand bottom of reflectance 0.3 at ten metres, sun at 30 deg, 20% sky, "
             "run for the issue")


@pytest.mark.parametrize("which", ["mono", "spectral"])
def test_a_long_scene_name_fits_in_the_title(mono_file, spectral_file, tmp_path, which):
    """A scene name of up to 200 characters is wrapped (at most 3 lines, then shortened with
    '...') so that the title lies inside the figure, which keeps its size."""
    import matplotlib
    source = mono_file if which == "mono" else spectral_file
    named = _copy(source, tmp_path / f"{which}.h5")
    with h5py.File(named, "a") as f:
        f.attrs["name"] = LONG_NAME
    fig = rrs_figure(open_result(named))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    title = fig.axes[0].title
    box, page = title.get_window_extent(renderer), fig.bbox
    assert box.x0 >= page.x0 and box.x1 <= page.x1 and box.y1 <= page.y1, (box, page)
    text = title.get_text()
    assert text.startswith("remote-sensing reflectance:") and 2 <= text.count("\n") + 1 <= 3
    assert text.replace("\n", " ").replace(" ...", "") in f"remote-sensing reflectance: " \
        f"{LONG_NAME}"
    assert isinstance(fig.canvas, matplotlib.backends.backend_agg.FigureCanvasAgg)
    close(fig)


@pytest.mark.long(cpu_s=15)
def test_output_folder_with_or_without_a_trailing_separator(mono_file, tmp_path, capsys):
    """-o DIR writes DIR/RESULT_*.png when DIR exists (with or without a trailing separator)
    or when DIR ends in one (created); otherwise -o is a prefix."""
    existing = tmp_path / "figs"
    existing.mkdir()
    for out in (str(existing), str(existing) + os.sep, str(tmp_path / "new") + os.sep):
        assert main(["plot", str(mono_file), "-o", out]) == 0
        folder = Path(out.rstrip(os.sep))
        assert sorted(p.name for p in folder.iterdir()) == ["mono_profiles.png",
                                                           "mono_radiance.png", "mono_rrs.png"]
        for png in folder.iterdir():
            png.unlink()
    assert main(["plot", str(mono_file), "-o", str(tmp_path / "run1")]) == 0
    assert sorted(p.name for p in tmp_path.glob("run1*")) == ["run1_profiles.png",
                                                             "run1_radiance.png", "run1_rrs.png"]
    # a prefix written as a figure's name: its .png left out (it gave pic.png_rrs.png)
    assert main(["plot", str(mono_file), "-o", str(tmp_path / "pic.png")]) == 0
    assert sorted(p.name for p in tmp_path.glob("pic*")) == ["pic_profiles.png",
                                                            "pic_radiance.png", "pic_rrs.png"]
    capsys.readouterr()


def test_a_device_as_the_figures_name_is_refused(mono_file, capsys):
    """`plot -o /dev/full` took the device as a prefix and wrote /dev/full_rrs.png and the rest
    into /dev (a user's review, as root): one line, exit 2, nothing written."""
    before = set(os.listdir("/dev"))
    err = one_line_error(capsys, ["plot", str(mono_file), "-o", "/dev/null"])
    assert "-o /dev/null: not a folder or a name for the figures (it is a device" in err
    assert set(os.listdir("/dev")) == before
