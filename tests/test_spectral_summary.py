"""The printed summary names its estimators and shows what the scene asked for (Ed(0+), an Rrs
per exact direction of local_directions_deg); the stored scene and the results file say what a
spectrum model gave (the sky's share of Ed(0+) per wavelength, which the scene's
diffuse_fraction key does not)."""
import numpy as np
import pytest
import yaml

import oceanmc
from oceanmc.cli import main
from oceanmc.config import load_config
from oceanmc.optics import illumination_spectrum
from oceanmc.run.derived import format_derived
from oceanmc.run.results import format_summary

SPECTRAL = {
    "name": "spectral summary scene",
    "photons": 4000,
    "batches": 8,
    "seed": 3,
    "wavelengths_nm": [440, 550, 670],
    "illumination": {"sun_position": {"time": "2024-06-21T14:00:00Z", "latitude_deg": 31.7,
                                      "longitude_deg": -64.2},
                     "spectrum": {"model": "spectrl2"}},
    "water": {"layers": [{"thickness_m": 5.0, "components": [
        {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": 0.3}]}]},
    "bottom": {"model": "lambertian", "reflectance": 0.2},
    "tallies": {"depths_m": [0, 2], "local_directions_deg": [[180, 0], [140, 135]]},
}


@pytest.fixture(scope="module")
def spectral_result():
    return oceanmc.simulate(SPECTRAL, threads=1)


def test_spectral_summary_names_estimators_and_shows_what_was_asked(spectral_result):
    text = format_summary(spectral_result)
    head = " ".join(line for line in text.splitlines() if line.strip().startswith("nm"))
    for column in ("Ed(0+)", "Rrs nadir", "Rrs 180,0", "Rrs 140,135", "Eu(0+)", "Ed(0-)"):
        assert column in head, column
    # auto: the cap's local estimate (with the crossing one beside it), and the summary says so
    assert "air/Rrs_nadir_crossing" in spectral_result
    assert "Rrs nadir: air/Rrs_nadir, the 175-180 deg polar cap's average, local (next-event) " \
        "estimate" in " ".join(text.split())
    assert "air/Rrs_local in the exact directions" in " ".join(text.split())
    assert "heavy-tailed with forward-peaked phase functions" in " ".join(text.split())
    assert "sun_position" in text and "spectrum spectrl2" in text and "sky share" in text
    # the Ed(0+) column is air/Ed, the Rrs 140,135 column air/Rrs_local's second direction
    row = next(line for line in text.splitlines() if line.strip().startswith("550"))
    cells = row.split()
    assert float(cells[1]) == pytest.approx(spectral_result["air/Ed"][1], rel=1e-3)
    assert float(cells[7]) == pytest.approx(spectral_result["air/Rrs_local"][1, 1], rel=1e-3)


def test_the_spectral_table_fits_100_columns_in_blocks_that_keep_every_column(spectral_result):
    """The table of configs/case1_spectral.yaml was 149 characters wide (8 columns of 16,
    more with local_directions_deg): it is printed in blocks of at most 5 columns, each after
    the nm column, the surface's (Ed(0+), the Rrs columns, Eu(0+)) first, every wavelength in
    each block, and every line of the summary fits 100 characters."""
    text = format_summary(spectral_result)
    assert max(map(len, text.splitlines())) <= 100, text
    heads = [line.split() for line in text.splitlines() if line.strip().startswith("nm")]
    assert [" ".join(head) for head in heads] == [
        "nm Ed(0+) Rrs nadir Rrs 180,0 Rrs 140,135 Eu(0+)",
        "nm Ed(0-) Eu(0-) Eo(0-) leaving total"]
    rows = [line.split()[0] for line in text.splitlines()
            if line.strip()[:3] in ("440", "550", "670")]
    assert rows == ["440", "550", "670"] * 2
    many = dict(SPECTRAL, tallies={"depths_m": [0], "local_directions_deg": [
        [180, 0], [170, 0], [160, 0], [150, 0], [140, 0]]}, photons=400)
    text = format_summary(oceanmc.simulate(many, threads=1))
    assert max(map(len, text.splitlines())) <= 100, text
    heads = [" ".join(line.split()) for line in text.splitlines()
             if line.strip().startswith("nm")]
    assert heads == ["nm Ed(0+) Rrs nadir Rrs 180,0 Rrs 170,0 Rrs 160,0",
                     "nm Rrs 150,0 Rrs 140,0 Eu(0+)",
                     "nm Ed(0-) Eu(0-) Eo(0-) leaving total"], heads


def test_spectral_summary_with_the_local_nadir_estimate_says_so(tmp_path):
    scene = dict(SPECTRAL, tallies={"depths_m": [0], "nadir_estimator": "local"})
    result = oceanmc.simulate(scene, threads=1)
    assert "air/Rrs_nadir_crossing" in result
    text = " ".join(format_summary(result).split())
    assert "Rrs nadir: air/Rrs_nadir, the 175-180 deg polar cap's average, local (next-event) " \
        "estimate" in text
    assert "Rrs 180,0" not in text     # no local directions asked for
    # without radiance quads there is no crossing estimate of the cap: the local one is named
    # all the same (from the file's Lu_method), and no crossing estimate is promised
    scene["tallies"] = {"depths_m": [0], "nadir_estimator": "local", "radiance": False}
    result = oceanmc.simulate(scene, threads=1)
    assert "air/Rrs_nadir_crossing" not in result
    text = " ".join(format_summary(result).split())
    assert "local (next-event) estimate" in text and "Rrs_nadir_crossing" not in text


def test_a_crossing_estimate_says_how_to_get_the_local_one_or_why_not():
    """Waves of isotropic slopes: the cap's local estimate by default; asked for the crossing
    one, the summary names the key that gives the local one. Anisotropic waves keep the
    crossing estimate, and the summary says why (it once advised the exact nadir's local
    estimate instead, which is heavy-tailed with forward-peaked particles)."""
    scene = dict(SPECTRAL, surface={"model": "cox_munk", "wind_speed_m_s": 5},
                 tallies={"depths_m": [0]}, photons=800)
    assert "air/Rrs_nadir_crossing" in oceanmc.simulate(scene, threads=1)
    scene["tallies"] = {"depths_m": [0], "nadir_estimator": "crossing"}
    text = " ".join(format_summary(oceanmc.simulate(scene, threads=1)).split())
    assert "crossing estimate (photons leaving through the cap; tallies.nadir_estimator: local " \
        "gives the cap's local estimate)" in text
    scene["surface"] = {"model": "cox_munk", "wind_speed_m_s": 5, "wind_direction_deg": 30}
    scene["tallies"] = {"depths_m": [0]}
    text = " ".join(format_summary(oceanmc.simulate(scene, threads=1)).split())
    assert "the cap's local estimate through waves needs isotropic slopes (no " \
        "wind_direction_deg) of mean square slope <= 0.2)" in text


def test_show_prints_the_same_summary(spectral_result, tmp_path, capsys):
    path = spectral_result.save(tmp_path / "s.h5")
    assert main(["show", str(path)]) == 0
    out = capsys.readouterr().out   # the run's summary, then the derived quantities
    derived = format_derived(oceanmc.load_result(path))
    assert derived.startswith("  derived (") and out.endswith(derived + "\n")
    assert out[:-len(derived) - 1].strip() == format_summary(oceanmc.load_result(path)).strip()
    assert format_summary(oceanmc.load_result(path)) == format_summary(spectral_result)


def test_stored_scene_and_attributes_hold_the_spectrum_models_diffuse_share(spectral_result,
                                                                             tmp_path):
    ed0, diffuse, _ = illumination_spectrum(load_config(SPECTRAL))
    assert np.all((diffuse > 0.0) & (diffuse < 1.0))
    back = oceanmc.load_result(spectral_result.save(tmp_path / "s.h5"))
    for result in (spectral_result, back):
        assert np.array_equal(result.attrs["illumination_diffuse_fraction"], diffuse)
        assert np.array_equal(result.attrs["illumination_Ed0"], ed0)
    text = back.config_yaml
    comments = [line for line in text.splitlines() if line.startswith("  #")]
    said = " ".join(comments)
    assert "SPECTRL2" in said and f"mean {diffuse.mean():.4f}" in said
    for wavelength, share in zip((440, 550, 670), diffuse):
        assert f"{wavelength}: {share:.4g}" in said
    # the comments sit under illumination, and the text still loads as the same scene
    lines = text.splitlines()
    at = lines.index(comments[0])
    assert lines[at - 1] == "  diffuse_fraction: 0.0"
    assert load_config(yaml.safe_load(text)) == load_config(SPECTRAL)


def test_flat_spectrum_scene_text_has_no_note(small_scene):
    result = oceanmc.simulate(small_scene, threads=1)
    assert "#" not in result.config_yaml
    assert np.array_equal(result.attrs["illumination_diffuse_fraction"], [0.2])


def test_monochromatic_summary_names_estimators_and_local_directions(small_scene):
    small_scene["tallies"]["local_directions_deg"] = [[180, 0]]
    text = format_summary(oceanmc.simulate(small_scene, threads=1))
    labels = [line[2:30].strip() for line in text.splitlines()]
    for label in ("Lu(0+) nadir (crossing)", "Lw nadir (local)", "Rrs nadir (local)",
                  "Rrs 180,0 (local)", "Lu(0-) (local)"):
        assert label in labels, label
    small_scene["tallies"]["nadir_estimator"] = "crossing"
    labels = [line[2:30].strip()
              for line in format_summary(oceanmc.simulate(small_scene)).splitlines()]
    assert "Rrs nadir (crossing)" in labels and "Lu(1 m) (crossing)" in labels


def test_one_wavelength_with_its_excitation_says_the_table_holds_more():
    # Raman light at 550 nm is excited at 450-540 nm, which the run traces and prints too
    config = dict(SPECTRAL, wavelengths_nm=[550], photons=400)
    config["water"] = dict(SPECTRAL["water"], inelastic={"raman": {}})
    text = " ".join(format_summary(oceanmc.simulate(config, threads=1)).split())
    assert "asked for 550 nm alone; the table holds the wavelengths traced for its " \
        "excitation as well" in text
    assert "the scene's one wavelength" not in text


def test_a_run_at_one_wavelength_says_which():
    """A file of one wavelength has no wavelength coordinate: the summary names it, and says
    nothing of the kind for a monochromatic scene or a spectrum."""
    from oceanmc.run.summary import single_wavelength
    one = oceanmc.simulate(dict(SPECTRAL, wavelengths_nm=[550], photons=400), threads=1)
    assert single_wavelength(one) == 550.0
    assert "  at 550 nm (the scene's one wavelength)" in format_summary(one).splitlines()
    ranged = oceanmc.simulate(dict(SPECTRAL, photons=400,
                                   wavelengths_nm={"start": 555, "stop": 555, "step": 10}),
                              threads=1)
    assert single_wavelength(ranged) == 555.0
    mono = dict(SPECTRAL, photons=400, illumination={"Ed0": 1.0, "sun_zenith_deg": 30},
                water={"layers": [{"thickness_m": 5.0, "a": 0.1, "b": 0.2,
                                   "phase": {"model": "isotropic"}}]})
    del mono["wavelengths_nm"]
    assert single_wavelength(oceanmc.simulate(mono, threads=1)) is None
