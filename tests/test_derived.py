"""Derived quantities (run/derived.py): Kd, Ku, Ko, KLu between adjacent tally depths, R, Q and
the mean cosines at each depth, their jackknife standard errors, the file's group `derived`,
`oceanmc show` and `oceanmc plot`."""
import math

import h5py
import numpy as np
import pytest
import xarray as xr
from scipy import stats

import oceanmc
from oceanmc.cli import main
from oceanmc.run.derived import derive, format_derived, jackknife
from oceanmc.run.hdf5 import load_result


def test_the_jackknife_of_a_mean_is_its_standard_error_and_of_a_ratio_the_delta_method():
    rng = np.random.default_rng(5)
    x = rng.normal(10.0, 1.0, size=(400, 3))
    value, err = jackknife(lambda m: 2.0 * m, x)
    np.testing.assert_allclose(value, 2.0 * x.mean(axis=0))
    np.testing.assert_allclose(err, 2.0 * x.std(axis=0, ddof=1) / math.sqrt(400), rtol=1e-12)
    # correlated numerator and denominator: the delta method with their covariance
    d = rng.normal(5.0, 1.0, size=400)
    u = 0.3 * d + rng.normal(0.0, 0.2, size=400)
    value, err = jackknife(lambda a, b: a / b, u, d)
    mu, md = u.mean(), d.mean()
    cov = np.cov(u, d) / 400
    delta = abs(mu / md) * math.sqrt(cov[0, 0] / mu ** 2 + cov[1, 1] / md ** 2
                                     - 2.0 * cov[0, 1] / (mu * md))
    assert value == pytest.approx(mu / md, rel=1e-12)
    assert err == pytest.approx(delta, rel=0.02)
    # a ratio of independent ones would be much wider: the covariance matters here
    assert err < 0.7 * abs(mu / md) * math.sqrt(cov[0, 0] / mu ** 2 + cov[1, 1] / md ** 2)


def scene(seed=1, photons=16 * 2000, **water):
    layer = {"thickness_m": 8.0, "a": 0.15, "b": 0.6, "phase": {"model": "petzold"}, **water}
    return {"photons": photons, "batches": 16, "seed": seed,
            "illumination": {"Ed0": 1.0, "sun_zenith_deg": 30.0, "diffuse_fraction": 0.2},
            "surface": {"model": "flat"}, "water": {"layers": [layer]},
            "bottom": {"model": "lambertian", "reflectance": 0.3},
            "tallies": {"depths_m": [0.0, 2.0, 2.5, 6.0], "radiance": False,
                        "nadir_estimator": "local"}}


def test_pure_absorber_k_and_mean_cosine_are_exact():
    """No scattering, black bottom, sun only: Ed(z) = Ed(0-) exp(-a z / mu_w), so Kd = a / mu_w
    over every interval (also the closely spaced 2-2.5 m) and mu_d = mu_w (DESIGN 4)."""
    config = scene(b=0.0, phase={"model": "isotropic"})
    config["bottom"] = {"model": "black"}
    config["illumination"]["diffuse_fraction"] = 0.0
    derived = derive(oceanmc.simulate(config, threads=2))
    mu_w = math.cos(math.asin(math.sin(math.radians(30.0)) / 1.34))
    kd = derived["Kd"]
    assert kd.dims == ("depth_interval",) and kd.value.shape == (3,)
    z = (kd.value - 0.15 / mu_w) / np.maximum(kd.stderr, 1e-12)
    assert np.all(np.abs(kd.value / (0.15 / mu_w) - 1.0) < 0.01) and np.all(np.abs(z) < 4), z
    np.testing.assert_allclose(derived["mu_d"].value, mu_w, rtol=1e-6)
    assert np.all(derived["R"].value == 0.0)
    assert "Ku" in derived and np.all(np.isnan(derived["Ku"].value))   # Eu = 0: undefined


def test_standard_errors_match_the_spread_of_repeated_runs():
    """12 runs of one scene with seeds 1..12 (16 batches of 2000 photons each). For every
    derived quantity at every depth or interval, the standard deviation of the 12 estimates
    against the root mean square of their 12 reported standard errors: s/sigma of 12 normal
    values lies within sqrt(chi2(11)/11) quantiles, here at a two-sided 0.001 divided among the
    compared values (Bonferroni), and the median over all of them within 0.75-1.33 (a mean
    over 33 values of a ratio whose own spread is 0.21; they are correlated, so wider than
    that mean's)."""
    runs = [derive(oceanmc.simulate(scene(seed), threads=2)) for seed in range(1, 13)]
    names = sorted(runs[0])
    assert set(names) == {"Kd", "Ku", "Ko", "KLu", "R", "Q", "mu_d", "mu_u", "mu", "t_up"}
    ratios = {}
    for name in names:
        values = np.array([r[name].value for r in runs])
        errors = np.array([r[name].stderr for r in runs])
        assert np.all(np.isfinite(values)) and np.all(errors > 0.0), name
        ratios[name] = np.atleast_1d(values.std(axis=0, ddof=1)
                                     / np.sqrt((errors ** 2).mean(axis=0)))
    every = np.concatenate(list(ratios.values()))
    alpha = 0.001 / every.size
    low, high = (math.sqrt(stats.chi2.ppf(p, 11) / 11) for p in (alpha / 2, 1 - alpha / 2))
    assert np.all((every > low) & (every < high)), {k: np.round(v, 2) for k, v in ratios.items()}
    assert 0.75 < np.median(every) < 1.33, np.median(every)


def test_t_up_is_the_ratio_of_the_batch_means():
    """The surface's upward transmittance Eu_water_leaving(0+) / Eu(0-) from the batch means
    (stored per batch as air/t_up before 2026-11-29, whose mean of ratios read 34% high at 700
    nm with 200 photons per batch: a user's review), with the jackknife's error; a Result holds
    no t_up, and asking one for it (or a K, R, Q) says where it is."""
    result = oceanmc.simulate(scene(photons=16 * 100), threads=2)
    t_up = derive(result)["t_up"]
    leaving = result.quantities["air/Eu_water_leaving"].batches
    eu = result.quantities["Eu"].batches[:, 0]
    assert t_up.dims == () and t_up.value == pytest.approx(leaving.mean() / eu.mean(), rel=1e-14)
    assert t_up.value != pytest.approx((leaving / eu).mean(), rel=1e-6)
    assert t_up.stderr == pytest.approx(jackknife(lambda a, b: a / b, leaving, eu)[1], rel=1e-14)
    assert 0.3 < t_up.value < 0.7   # about 0.5 for diffuse upwelling light (Mobley 1994, 4.3)
    for name in ("t_up", "air/t_up", "Kd", "derived/Q"):
        with pytest.raises(KeyError, match=r"derived from the batch means: "
                                           r"oceanmc\.derive\(result\)"):
            result[name]
    assert oceanmc.derive is derive and "t_up" in oceanmc.derive(result)
    result.attrs["inelastic_parts"] = "elastic raman"   # (as a run with Raman light says)
    with pytest.raises(KeyError, match="raman/Kd.*derived from the whole light's batch means"):
        result["raman/Kd"]
    with pytest.raises(KeyError, match="the derived quantities are Kd, Ku"):
        result["derived/K"]
    deep = scene(photons=16 * 100)
    deep["tallies"]["depths_m"] = [2.0]     # no depth 0: no t_up, one depth: no Kd
    deep = oceanmc.simulate(deep, threads=2)
    for name in ("t_up", "Kd"):
        with pytest.raises(KeyError, match="this result's tallies do not give it"):
            deep[name]
    assert set(result.keys()) == set(result.quantities) and "air/Rrs_nadir" in result.keys()


def test_a_zero_irradiance_leaves_a_quantity_undefined_not_infinite():
    """Eu = 0 at a black bottom: Ku down to it (ln(Eu / 0)) and Q, mu_u there (0 / 0) are NaN
    with NaN errors, not inf; R there is 0; the summary says 'undefined' and why, and prints
    no inf or nan."""
    config = scene(photons=16 * 500)
    config["bottom"] = {"model": "black"}
    config["tallies"]["depths_m"] = [0.0, 8.0]
    result = oceanmc.simulate(config, threads=2)
    derived = derive(result)
    for name in ("Ku", "Q", "mu_u"):
        assert np.isnan(derived[name].value[-1]) and np.isnan(derived[name].stderr[-1]), name
        assert "NaN where undefined" in derived[name].description
    assert np.isfinite(derived["Kd"].value).all() and derived["R"].value[-1] == 0.0
    text = format_derived(result)
    assert "Ku(0-..8 m)                 m-1          undefined   (a zero Eu)" in text, text
    assert "Q(8 m)" in text and "(a zero Eu or Lu)" in text
    assert "inf" not in text and " nan" not in text


def test_the_file_holds_them_and_show_prints_them(tmp_path, capsys):
    result = oceanmc.simulate(scene(photons=16 * 500), threads=2)
    path = result.save(tmp_path / "r.h5")
    expected = derive(result)
    with h5py.File(path) as f:
        group = f["derived"]
        for name, d in expected.items():
            np.testing.assert_array_equal(group[name][()], d.value)
            np.testing.assert_array_equal(group[name + "_stderr"][()], d.stderr)
            assert group[name].attrs["units"] == d.units
    data = xr.open_dataset(path, engine="h5netcdf", group="derived")
    assert data["Kd"].dims == ("depth_interval",) and data["R"].dims == ("depth",)
    np.testing.assert_allclose(data["depth_interval"], [1.0, 2.25, 4.25])
    np.testing.assert_allclose(data["Kd"].coords["depth_upper"], [0.0, 2.0, 2.5])
    data.close()
    # read back, the quantities come again from the stored batches
    again = derive(load_result(path))
    for name, d in expected.items():
        np.testing.assert_array_equal(again[name].value, d.value)
    assert main(["show", str(path)]) == 0
    out = capsys.readouterr().out
    assert "Kd(2 m..2.5 m)" in out and "mu_d(0-)" in out and "Q(6 m)" in out
    assert "\n  t_up    " in out
    assert "jackknife" in format_derived(result)
    # one tally depth: the ratios, no K and no empty depth_interval dimension
    one = scene(photons=16 * 200)
    one["tallies"]["depths_m"] = [0.0]
    path = oceanmc.simulate(one, threads=2).save(tmp_path / "one.h5")
    with xr.open_dataset(path, engine="h5netcdf", group="derived") as data:
        assert dict(data.sizes) == {"depth": 1} and "R" in data and "Kd" not in data


def test_a_spectral_file_plots_kd_and_r(tmp_path, capsys):
    config = {"photons": 8 * 300, "batches": 8, "seed": 2, "wavelengths_nm": [443, 555, 670],
              "illumination": {"Ed0": 1.0, "sun_zenith_deg": 30.0, "diffuse_fraction": 0.2},
              "water": {"layers": [{"thickness_m": math.inf, "components": [
                  {"model": "pure_water"}, {"model": "case1", "chl_mg_m3": 1.0}]}]},
              "bottom": {"model": "none"}, "tallies": {"depths_m": [0, 5, 10],
                                                        "radiance": False}}
    result = oceanmc.simulate(config, threads=2)
    path = result.save(tmp_path / "s.h5")
    data = xr.open_dataset(path, engine="h5netcdf", group="derived")
    assert data["Kd"].dims == ("wavelength", "depth_interval")
    data.close()
    assert main(["plot", str(path), "-o", str(tmp_path) + "/"]) == 0
    png = tmp_path / "s_kd_r.png"
    assert png.stat().st_size > 10_000
    assert main(["show", str(path)]) == 0
    table = capsys.readouterr().out.split("derived (")[1]
    assert "Kd(0-..5 m)" in table and "R(0-)" in table
    # in blocks of columns, the K functions and the ratios apart, as the run's own table: every
    # line fits 100 characters (one block of all nine was 170 wide)
    assert max(len(line) for line in table.splitlines()) <= 100
    k_heading = next(line for line in table.splitlines() if "Kd(0-..5 m)" in line)
    assert "R(0-)" not in k_heading
    assert ("Q(0-)" in table) == ("Lu" in result)   # Q only where the run has a nadir radiance
