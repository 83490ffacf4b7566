"""The constituent models against the published formulas and values, computed here from the
papers' equations and printed numbers (not from oceanmc.optics), and their bad input."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import oceanmc
from oceanmc import optics, registry
from oceanmc.config import ConfigError, data_file_hashes
from oceanmc.run.simulation import prepare

WL = [400.0, 440.0, 550.0, 700.0]


def scene(components, wavelengths=WL, **extra):
    return oceanmc.load_config({"wavelengths_nm": wavelengths, "water": {"layers": [
        {"thickness_m": math.inf, "components": components}]}, "bottom": {"model": "none"},
        **extra})


def layer(components, wavelengths=WL):
    (only,) = optics.column_iops(scene(components, wavelengths))
    return only


def test_registry_lists_every_schema_constituent_and_its_module():
    from oceanmc.config.components import Component
    import typing
    union = typing.get_args(typing.get_args(Component)[0])
    names = {typing.get_args(m.model_fields["model"].annotation)[0] for m in union}
    assert names == set(registry.CONSTITUENT)
    folder = Path(optics.__file__).parent / "components"
    assert all((folder / f"{m}.py").exists() for m in registry.CONSTITUENT.values())


def test_pure_water_ioccg_pope_fry_morel():
    wavelengths = [300.0, 350.0, 400.0, 420.0, 440.0, 550.0, 700.0, 800.0]
    iop = layer([{"model": "pure_water"}], wavelengths)
    # Pope & Fry (1997) as printed (OMLC, 1/cm x 100) from 420 nm: 420 nm 0.00454, 440 nm
    # 0.00635, 550 nm 0.0565, 700 nm 0.624; outside, the IOCCG Protocols (2018): 300 nm 0.0147
    # (Jonasz & Fournier 2007), 350 nm 0.0071, 400 nm 0.0046 (Morel et al. 2007 Table 2a),
    # 800 nm 2.25 (Kou et al. 1993)
    assert iop.a == pytest.approx([0.0147, 0.0071, 0.0046, 0.00454, 0.00635, 0.0565, 0.624,
                                   2.25], rel=1e-9)
    # Morel (1974): b_sw = 0.00288 (lambda / 500)^-4.32; molecular scattering bb/b = 1/2
    b = [0.00288 * (wl / 500.0) ** -4.32 for wl in wavelengths]
    assert iop.b == pytest.approx(b, rel=1e-12)
    assert iop.bb == pytest.approx(0.5 * np.array(b), rel=1e-12)
    assert [p.model for p in iop.phases] == ["pure_water"]


def test_pure_water_absorption_has_no_step_where_its_sources_meet():
    # every 2.5 nm from 300 to 800 nm, across the joins at 420 nm (Morel et al. 2007 to Pope &
    # Fry) and 727.5 nm (Pope & Fry to Kou et al. 1993), a_w changes by less than 20%: Pope &
    # Fry's own steepest steps (505-512.5, 595-600 nm) are 14-16%; Smith & Baker 1981 below
    # Pope & Fry's 380 nm, before 2026-11-29, met it with a step of 2.6x (0.030 1/m at 370 nm
    # to 0.0114 at 380 nm; 2.1x within this test's 2.5 nm)
    wavelengths = np.arange(300.0, 800.01, 2.5)
    a = layer([{"model": "pure_water"}], wavelengths.tolist()).a
    assert np.max(np.abs(np.diff(np.log(a)))) < np.log(1.2)


def test_chlorophyll_bricaud_1998_and_morel_maritorena_2001():
    chl = 0.3
    iop = layer([{"model": "chlorophyll", "chl_mg_m3": chl}], [440.0, 550.0])
    # Bricaud et al. (1998), the 440 nm row as printed: A_phi = 0.037824, E_phi = 0.626633
    a440 = 0.037824 * chl ** 0.626633
    assert iop.a[0] == pytest.approx(a440, rel=1e-6)
    # Morel & Maritorena (2001): b_p = 0.416 Chl^0.766 (550 / lambda)
    b = [0.416 * chl ** 0.766 * 550.0 / wl for wl in (440.0, 550.0)]
    assert iop.b == pytest.approx(b, rel=1e-12)
    # Morel et al. (2002): bb/b = 0.002 + 0.01 (0.5 - 0.25 log10 Chl) (lambda/550)^nu,
    # nu = 0.5 (log10 Chl - 0.3) below 2 mg/m3 (FF phases carry it to 4 significant digits)
    nu = 0.5 * (math.log10(chl) - 0.3)
    ratio = [0.002 + 0.01 * (0.5 - 0.25 * math.log10(chl)) * (wl / 550.0) ** nu
             for wl in (440.0, 550.0)]
    assert iop.bb / iop.b == pytest.approx(ratio, rel=5e-4)
    assert all(p.model == "fournier_forand" for p in iop.phases)
    assert iop.weights.sum(axis=1) == pytest.approx([1.0, 1.0])


def test_chlorophyll_beyond_bricaud_range_follows_published_shapes():
    """Below 400 nm a_ph takes the shape of Vasilkov et al. (2005)'s a*_ph = A Chl^-B (their
    Table 1: A, B = 0.0709, 0.153 at 350 nm and 0.0520, 0.198 at 400 nm), joined to Bricaud's
    a_ph at 400 nm; above 700 nm the shape of HydroLight's particle absorption (A_p, E_p =
    0.0002, 1 at 715 nm; Bricaud's 0.0039342, 1.0131636 at 700 nm), 0 from 720 nm; below 300 nm
    the particles' own continuation (their table's log-slope over 300-310 nm), never held flat:
    Raman light at 400 nm is excited near 350 nm."""
    chl = 1.0 / 3.0
    wl = np.array([290.0, 300.0, 310.0, 350.0, 400.0, 700.0, 715.0, 720.0, 800.0])
    # (with pure water: the infinitely deep layer needs a > 0, and a_ph is 0 from 720 nm)
    a = optics.column_iops(scene([{"model": "pure_water"},
                                  {"model": "chlorophyll", "chl_mg_m3": chl}], list(wl)))[0].a
    a_ph = a - optics.column_iops(scene([{"model": "pure_water"}], list(wl)))[0].a
    a400 = 0.0240515 * chl ** 0.687735            # Bricaud et al. (1998) A_phi, E_phi at 400 nm
    assert a_ph[4] == pytest.approx(a400, rel=1e-9)
    assert a_ph[3] == pytest.approx(a400 * 0.0709 * chl ** -0.153 / (0.0520 * chl ** -0.198),
                                    rel=1e-9)
    assert a_ph[1] == pytest.approx(a400 * 0.1023 * chl ** -0.0983 / (0.0520 * chl ** -0.198),
                                    rel=1e-9)
    assert a_ph[3] > a_ph[4]                      # it rises into the ultraviolet
    a700 = 0.00248126 * chl ** 1.028608
    assert a_ph[5] == pytest.approx(a700, rel=1e-9)
    assert a_ph[6] == pytest.approx(a700 * 0.0002 * chl / (0.0039342 * chl ** 1.0131636),
                                    rel=1e-9)
    assert a_ph[7] == 0.0 and a_ph[8] == 0.0
    # below 300 nm as the particles' HydroLight table continues (A_p, E_p = 0.0736, 0.8524 at
    # 300 nm and 0.0767, 0.8453 at 310 nm): ln a_p(290) - ln a_p(300) = ln a_p(300) - ln a_p(310)
    ln_ap = [math.log(0.0736) + 0.8524 * math.log(chl), math.log(0.0767) + 0.8453 * math.log(chl)]
    assert math.log(a_ph[0] / a_ph[1]) == pytest.approx(ln_ap[0] - ln_ap[1], rel=1e-6)
    assert a_ph[0] != a_ph[1]


def test_cdom_particles_constant_and_their_sum():
    comps = [{"model": "cdom", "a440": 0.05, "slope": 0.015},
             {"model": "particles", "b550": 0.5, "exponent": 0.8, "bb_ratio": 0.02,
              "a443": 0.03, "slope": 0.011},
             {"model": "constant", "a": [0.1, 0.2, 0.3, 0.4], "b": 0.2,
              "phase": {"model": "isotropic"}}]
    wl = np.array(WL)
    a_g = 0.05 * np.exp(-0.015 * (wl - 440.0))
    a_p = 0.03 * np.exp(-0.011 * (wl - 443.0))
    b_p = 0.5 * (550.0 / wl) ** 0.8
    iop = layer(comps)
    assert iop.a == pytest.approx(a_g + a_p + np.array([0.1, 0.2, 0.3, 0.4]), rel=1e-12)
    assert iop.b == pytest.approx(b_p + 0.2, rel=1e-12)
    assert iop.bb == pytest.approx(0.02 * b_p + 0.5 * 0.2, rel=1e-12)
    # the isotropic share of scattering is 0.2 / b at every wavelength
    iso = [p.model for p in iop.phases].index("isotropic")
    assert iop.weights[:, iso] == pytest.approx(0.2 / (b_p + 0.2), rel=1e-12)
    assert iop.c == pytest.approx(iop.a + iop.b)


def test_pure_water_from_the_user_s_absorption_file(tmp_path):
    """pure_water.absorption_file replaces the IOCCG spectrum's a_w (linear in wavelength),
    keeps Morel's b_w; a file relative to the config's folder; problems name the key; a
    wavelength the run added for the Raman excitation, outside the file, is said to be one; the
    file is among those whose content the stored run hashes."""
    (tmp_path / "aw.csv").write_text("# my water\nwavelength_nm,a\n380,0.01\n500,0.03\n"
                                     "700,0.63\n")
    iop = layer([{"model": "pure_water", "absorption_file": str(tmp_path / "aw.csv")}],
                [400.0, 600.0])
    assert iop.a == pytest.approx([0.01 + 0.02 * 20 / 120, 0.33])
    assert iop.b == pytest.approx(layer([{"model": "pure_water"}], [400.0, 600.0]).b)
    config = {"name": "own water", "photons": 100, "wavelengths_nm": [450.0, 550.0],
              "illumination": {"sun_zenith_deg": 30.0}, "surface": {"model": "flat"},
              "water": {"layers": [{"thickness_m": math.inf, "components": [
                  {"model": "pure_water", "absorption_file": "aw.csv"}]}]},
              "bottom": {"model": "none"}}
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(config))
    loaded = oceanmc.load_config(path)
    assert loaded.water.layers[0].components[0].absorption_file == str(tmp_path / "aw.csv")
    assert str(tmp_path / "aw.csv") in data_file_hashes(loaded)
    # Raman light at 450 nm is excited near 390 nm, which the run adds: outside a file that
    # starts at 420 nm
    (tmp_path / "aw.csv").write_text("wavelength_nm,a\n420,0.005\n700,0.63\n")
    config["water"]["inelastic"] = {"raman": {}}
    path.write_text(yaml.safe_dump(config))
    with pytest.raises(ConfigError) as info:
        prepare(oceanmc.load_config(path))
    message = str(info.value)
    assert "water.layers[0].components[0].absorption_file: wavelength " in message, message
    assert "is outside the" in message and "(traced for the excitation of water.inelastic" \
        in message, message
    (tmp_path / "aw.csv").write_text("wavelength_nm,a\n380,-0.01\n700,0.63\n")
    with pytest.raises(ConfigError, match=r"components\[0\]\.absorption_file: .*-0\.01"):
        layer([{"model": "pure_water", "absorption_file": str(tmp_path / "aw.csv")}], [400.0])
    with pytest.raises(ConfigError, match=r"components\[0\]\.absorption_file: .*no such file"):
        layer([{"model": "pure_water", "absorption_file": str(tmp_path / "none.csv")}], [400.0])


def test_table_component_and_its_errors(tmp_path):
    good = tmp_path / "iops.csv"
    good.write_text("# measured\nwavelength_nm,a,b,bb_ratio\n400,0.4,1.0,0.01\n700,0.7,0.5,0.02\n")
    iop = layer([{"model": "table", "file": str(good)}], [400.0, 550.0])
    assert iop.a == pytest.approx([0.4, 0.55])
    assert iop.b == pytest.approx([1.0, 0.75])
    assert iop.bb == pytest.approx([0.01, 0.75 * 0.015])
    missing = tmp_path / "short.csv"
    missing.write_text("wavelength_nm,a,b\n400,0.4,1.0\n700,0.7,0.5\n")
    with pytest.raises(ConfigError, match=r"components\[0\]\.file: .*short.csv lacks the "
                                          r"column\(s\) bb_ratio"):
        layer([{"model": "table", "file": str(missing)}], [500.0])
    with pytest.raises(ConfigError, match=r"wavelength 750 nm is outside the .*iops.csv table's "
                                          r"range 400-700 nm"):
        layer([{"model": "table", "file": str(good)}], [500.0, 750.0])


@pytest.mark.parametrize("data, message", [
    ({"wavelengths_nm": [500, 450]}, r"wavelengths_nm = \[500, 450\]: must be strictly "
                                     r"increasing"),
    ({"wavelengths_nm": {"start": 700, "stop": 400, "step": 10}},
     r"wavelengths_nm: stop = 400.0 is below start = 700.0"),
    ({"layer": {"components": [{"model": "cdom", "a440": {
        "profile": "linear", "depths_m": [0, 10], "values": [0.1, -0.1]}}]}},
     r"components\[0\]\.a440\.values\[1\] = -0\.1: allowed: a number >= 0$"),
    ({"layer": {"a": 0.1, "b": 0.1, "components": [{"model": "pure_water"}]}},
     r"a, b given with components"),
    ({"layer": {"a": [0.1, 0.2], "b": 0.1}, "wavelengths_nm": [400, 500, 600]},
     r"water.layers\[0\].a has 2 values; allowed: one number or one value per wavelength \(3"),
    ({"layer": {"components": [{"model": "pure_water"}]}, "wavelengths_nm": None},
     r"components: constituents need wavelengths_nm"),
])
def test_bad_input_is_one_line_naming_the_key(data, message):
    layer_cfg = {"thickness_m": math.inf, "components": [{"model": "pure_water"}]}
    layer_cfg = data.pop("layer", layer_cfg) | {"thickness_m": math.inf}
    raw = {"wavelengths_nm": [400, 500], "water": {"layers": [layer_cfg]},
           "bottom": {"model": "none"}} | data
    if raw["wavelengths_nm"] is None:
        del raw["wavelengths_nm"]
    with pytest.raises(ConfigError, match=message) as err:
        oceanmc.load_config(raw)
    assert "\n" not in str(err.value)


def test_profile_table_with_negative_values_names_the_file(tmp_path):
    path = tmp_path / "chl.csv"
    path.write_text("depth_m,value\n0,0.1\n10,-0.2\n")
    with pytest.raises(ConfigError, match=r"chl_mg_m3\.file: .*chl.csv: value = -0.2 at "
                                          r"depth_m = 10; allowed: 0 \.\. 100 mg/m3"):
        optics.column_iops(scene([{"model": "chlorophyll", "chl_mg_m3": {
            "profile": "table", "file": str(path)}}]))


def test_per_wavelength_lists_without_components():
    config = oceanmc.load_config({"wavelengths_nm": [450, 550], "water": {"layers": [
        {"thickness_m": 3, "a": [0.1, 0.2], "b": 0.5, "bb_ratio": [0.01, 0.03]},
        {"thickness_m": math.inf, "a": 0.3, "b": [0.2, 0.1],
         "phase": {"model": "henyey_greenstein", "g": 0.8}}]}, "bottom": {"model": "none"}})
    top, deep = optics.column_iops(config)
    assert top.a == pytest.approx([0.1, 0.2]) and top.bb == pytest.approx([0.005, 0.015])
    g = 0.8   # HG backscatter fraction (1 - g)/(2 g) ((1 + g)/sqrt(1 + g^2) - 1)
    assert deep.bb / deep.b == pytest.approx((1 - g) / (2 * g) * ((1 + g) / math.hypot(1, g) - 1))
    assert deep.top_m == 3.0 and math.isinf(deep.thickness_m)


def test_monochromatic_scene_has_one_nan_wavelength():
    config = oceanmc.load_config({"water": {"layers": [{"thickness_m": math.inf, "a": 0.1,
                                                        "b": 0.2}]}, "bottom": {"model": "none"}})
    assert np.isnan(optics.wavelengths(config)).all() and len(optics.wavelengths(config)) == 1
    ed0, diffuse, zenith = optics.illumination_spectrum(config)
    assert ed0.tolist() == [1.0] and diffuse.tolist() == [0.0] and zenith == 30.0
