"""What a run with inelastic light (water.inelastic) shows its user: the summary of `oceanmc run`
and `oceanmc show` names the processes and the wavelengths added for their excitation and
splits Rrs nadir into its parts; `oceanmc plot` draws the parts beside the whole. A run without
inelastic light shows none of it."""
import contextlib
import copy
import io

import numpy as np
import pytest
import yaml

from oceanmc.cli import main
from oceanmc.plot import close
from oceanmc.plot.results import added_spans, open_result, plot_result, rrs_figure
from oceanmc.run.hdf5 import load_result
from oceanmc.run.results import format_summary, wavelength_ranges

# the scene of the feature's first look, with few photons: 400-700 nm asked for, 340-390 nm
# added for the excitation of the Raman light at 400 nm
INELASTIC = {
    "name": "raman demo",
    "photons": 4000,
    "batches": 8,
    "seed": 7,
    "wavelengths_nm": {"start": 400, "stop": 700, "step": 10},
    "illumination": {"sun_zenith_deg": 30},
    "surface": {"model": "flat"},
    "water": {"layers": [{"thickness_m": float("inf"), "components": [
        {"model": "pure_water"}, {"model": "case1", "chl_mg_m3": 0.05}]}],
        "inelastic": {"raman": {}, "chlorophyll_fluorescence": {}}},
    "bottom": {"model": "none"},
    "tallies": {"depths_m": [0, 10]},
}
ELASTIC = copy.deepcopy(INELASTIC)
del ELASTIC["water"]["inelastic"]
ELASTIC["name"] = "elastic demo"

# the lines and words a run with inelastic light adds to the summary
INELASTIC_WORDS = ("inelastic", "traced also", "by part of the light", "raman/")


def run_cli(tmp_path_factory, scene: dict, name: str):
    """`oceanmc run` of the scene: (its printed output, the results file)."""
    folder = tmp_path_factory.mktemp(name)
    (folder / "scene.yaml").write_text(yaml.safe_dump(scene))
    out = folder / f"{name}.h5"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main(["run", str(folder / "scene.yaml"), "-o", str(out), "-q",
                     "--threads", "1"]) == 0
    return printed.getvalue(), out


@pytest.fixture(scope="module")
def inelastic_run(tmp_path_factory):
    return run_cli(tmp_path_factory, INELASTIC, "inelastic")


@pytest.fixture(scope="module")
def elastic_run(tmp_path_factory):
    return run_cli(tmp_path_factory, ELASTIC, "elastic")


def lines_of(text: str, start: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip().startswith(start)]


def test_summary_names_the_processes_and_the_added_wavelengths(inelastic_run):
    printed, _ = inelastic_run
    flat = " ".join(printed.split())
    assert "inelastic light: Raman scattering by water (b_R 0.00026 1/m at 488 nm, as " \
        "(488/l)^5.5; phase function 1 + 0.55 cos^2), chlorophyll fluorescence (quantum " \
        "yield 0.02, 685 nm" in flat
    assert "elastic/, raman/, chlorophyll_fluorescence/" in flat
    # (a user comparing elastic/ with a code without inelastic light is told it differs)
    assert "elastic/ is the light no process shifted, after their losses (not a run without " \
        "them)" in flat
    assert "traced also 340-390 nm (10 nm steps) for the excitation of inelastic light; " \
        "reported with the rest, though those below 400 nm lack the inelastic light excited " \
        "below 340 nm" in flat
    assert max(map(len, printed.splitlines())) <= 100, printed


def test_summary_splits_rrs_nadir_into_its_parts(inelastic_run):
    printed, out = inelastic_run
    result = load_result(out)
    heads = [" ".join(line.split()) for line in lines_of(printed, "nm")]
    assert "nm elastic share Raman share fluorescence share" in heads
    # the parts' table is the last one: its row at 550 nm holds each part's value and share
    row = lines_of(printed, "550")[-1].split()
    k = int(np.nonzero(result.coords["wavelength"] == 550.0)[0][0])
    whole = result["air/Rrs_nadir"][k]
    for i, part in enumerate(("elastic", "raman", "chlorophyll_fluorescence")):
        value, rel, share = row[1 + 3 * i: 4 + 3 * i]
        assert float(value) == pytest.approx(result[f"{part}/air/Rrs_nadir"][k], rel=1e-3)
        assert float(share.rstrip("%")) == pytest.approx(
            100 * result[f"{part}/air/Rrs_nadir"][k] / whole, abs=0.06)
    # Raman light is a part of Rrs at 550 nm, fluorescence is not (its band is near 685 nm)
    assert float(row[6].rstrip("%")) > 1.0 and float(row[9].rstrip("%")) < 0.1
    # every wavelength traced is a row, the added ones too
    assert lines_of(printed, "340") and lines_of(printed, "700")


def test_show_prints_the_summary_the_run_printed(inelastic_run, capsys):
    printed, out = inelastic_run
    assert main(["show", str(out)]) == 0
    shown = capsys.readouterr().out
    summary = printed.split("  wrote ")[0]
    assert shown.startswith(summary)
    assert summary == format_summary(load_result(out)) + "\n"


def test_plot_draws_the_parts_beside_the_whole_rrs(inelastic_run, tmp_path):
    _, out = inelastic_run
    written = plot_result(out, tmp_path / "fig")
    assert written["rrs"].stat().st_size > 10_000
    fig = rrs_figure(open_result(out))
    (ax,) = fig.axes
    labels = set(ax.get_legend_handles_labels()[1])
    assert labels == {"+- 1 standard error", "Rrs nadir (whole)", "elastic part", "Raman part",
                      "fluorescence part", "added for the excitation"}
    assert ax.get_yscale() == "log"
    # each part with its error bars: a line and a collection of bars per part
    assert len(ax.containers) == 3 and all(c.has_yerr for c in ax.containers)
    raman = next(c for c in ax.containers if c.get_label() == "Raman part")
    grid = load_result(out).coords["wavelength"]
    assert raman.lines[0].get_xdata().min() > 370.0   # Raman light needs excitation below it
    assert raman.lines[0].get_xdata().max() == grid[-1]
    close(fig)


def test_a_run_without_inelastic_light_shows_none_of_it(elastic_run, tmp_path):
    printed, out = elastic_run
    for word in INELASTIC_WORDS:
        assert word not in printed, word
    assert "air/Rrs_nadir" in printed   # the estimator line, as before
    assert [line.split()[0] for line in lines_of(printed, "nm")] == ["nm", "nm"]
    assert lines_of(printed, "400") and not lines_of(printed, "390")
    plot_result(out, tmp_path / "fig")
    fig = rrs_figure(open_result(out))
    (ax,) = fig.axes
    assert ax.get_legend_handles_labels()[1] == ["+- 1 standard error", "Rrs nadir"]
    assert ax.get_yscale() == "linear" and not ax.containers
    close(fig)


@pytest.mark.parametrize("wavelengths, said", [
    ([340, 350, 360, 370, 380, 390], "340-390 nm (10 nm steps)"),
    ([395], "395 nm"),
    ([340, 350], "340 nm, 350 nm"),
    ([340, 350, 360, 375, 380, 385, 390, 397],
     "340-360 nm (10 nm steps), 375-390 nm (5 nm steps), 397 nm"),
])
def test_added_wavelengths_in_few_words(wavelengths, said):
    assert wavelength_ranges(np.array(wavelengths, dtype=float)) == said


def test_the_shaded_spans_cover_every_added_wavelength():
    """Asked 400 and 550 nm with Raman light: the run adds 340-390 nm below them and others
    between them; each run of added wavelengths is shaded from halfway to its asked neighbours
    (the grid's end where there is none), and no asked wavelength is inside a span."""
    grid = np.array([340.0, 350.0, 400.0, 450.0, 460.0, 550.0])
    added = np.array([340.0, 350.0, 450.0, 460.0])
    assert added_spans(grid, added) == [(340.0, 375.0), (425.0, 505.0)]
    assert added_spans(grid, np.array([])) == []
    assert added_spans(np.array([400.0, 550.0, 600.0]), np.array([600.0])) == [(575.0, 600.0)]
