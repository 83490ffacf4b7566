"""Every numeric key of the scene schema with NaN, +-inf, 1e308, 1e-308, -1, 0 and its own
bounds (issue 29, section 6): each value loads or is refused in one line (ConfigError) that names
the key or the value; a scene that loads runs (200 photons, 2 batches) to finite estimates and
standard errors, or is refused in one line by the scene build, never NaN with success.

The keys are not listed here: they are found by walking the pydantic models of oceanmc/config
(every field whose type holds a number, in every model a template scene reaches, lists entry by
entry), so a key added to a model is fuzzed without a change here; a model no template reaches
fails test_every_numeric_key_of_the_schema_is_reached (add it to a template). Below them, one
named test per class of failure the fuzzing found."""
import copy
import math
import warnings
from typing import get_args

import numpy as np
import pytest
from pydantic import BaseModel

import oceanmc
from oceanmc.config import ConfigError, SceneConfig, load_config

VALUES = (math.nan, math.inf, -math.inf, 1e308, 1e-308, -1, 0)
TINY_RUN = {"photons": 200, "batches": 2}


def _mono(**changes):
    scene = {"photons": 200, "batches": 2, "seed": 3,
             "illumination": {"Ed0": 1.0, "sun_zenith_deg": 30, "diffuse_fraction": 0.2},
             "surface": {"model": "flat", "n_water": 1.34},
             "water": {"layers": [{"thickness_m": 2.0, "a": 0.1, "b": 0.4,
                                   "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
             "bottom": {"model": "lambertian", "reflectance": 0.3},
             "tallies": {"depths_m": [0, 1, 2], "phi_bands": 12, "grazing_mu_cut": 0.01,
                         "theta_edges_deg": [0, 10, 90, 170, 180],
                         "local_directions_deg": [[180, 0]]},
             "estimator": {"roulette_weight": 1e-3, "roulette_survival": 0.1,
                           "max_events": 10000, "split_weight": 2.0, "upward_fraction": 0.1,
                           "upward_cone_deg": 15}}
    scene.update(changes)
    return scene


SMALL_TALLIES = {"depths_m": [0, 1]}


def templates(folder):
    """{name: scene} reaching every model of the schema; data files written in folder."""
    (folder / "iops.csv").write_text("wavelength_nm,a,b,bb_ratio\n350,0.1,0.2,0.02\n"
                                     "800,0.2,0.1,0.01\n")
    (folder / "profile.csv").write_text("depth_m,value\n0,0.5\n1,0.6\n")
    (folder / "spectrum.csv").write_text("wavelength_nm,Ed0,diffuse_fraction\n350,1,0.2\n"
                                         "800,1.5,0.1\n")
    (folder / "phase.csv").write_text("0,10\n10,1\n90,0.1\n180,0.1\n")
    (folder / "bottom.csv").write_text("wavelength_nm,reflectance\n350,0.05\n800,0.2\n")
    angles = np.arange(0.0, 90.1, 10.0)
    np.savez(folder / "brdf.npz", theta_i_deg=angles, theta_r_deg=angles,
             phi_deg=np.arange(0.0, 180.1, 30.0), brdf=np.full((10, 10, 7), 0.3 / np.pi))
    np.save(folder / "sky.npy", np.ones((9, 36)))
    f = {name: str(folder / name) for name in ("iops.csv", "profile.csv", "spectrum.csv",
                                                  "phase.csv", "brdf.npz", "sky.npy",
                                                  "bottom.csv")}
    return {
        "hg_lambertian": _mono(),
        "constituents_minnaert": _mono(
            wavelengths_nm=[400, 500, 600],
            water={"layers": [{"thickness_m": 1.0, "components": [
                {"model": "pure_water"},
                {"model": "chlorophyll", "chl_mg_m3": {"profile": "gaussian", "background": 0.1,
                                                       "peak_depth_m": 0.5, "width_m": 2.0,
                                                       "integral": 0.1}},
                {"model": "cdom", "a440": {"profile": "linear", "depths_m": [0, 1],
                                           "values": [0.05, 0.06]}, "slope": 0.014},
                {"model": "particles", "b550": 0.5, "exponent": 1.0, "bb_ratio": 0.0183,
                 "a443": 0.02, "slope": 0.011, "concentration": 1.0},
                {"model": "constant", "a": 0.01, "b": 0.02, "bb_ratio": 0.02,
                 "concentration": 1.0},
                {"model": "table", "file": f["iops.csv"]},
                {"model": "chlorophyll", "chl_mg_m3": {"profile": "table",
                                                       "file": f["profile.csv"]}},
                {"model": "case1", "chl_mg_m3": 0.3}]}]},
            bottom={"model": "minnaert", "reflectance": 0.2, "k": 0.5}, tallies=SMALL_TALLIES),
        "sun_spectrl2": _mono(   # pvlib's solar position: 80 ms a load
            wavelengths_nm=[400, 600], tallies=SMALL_TALLIES,
            illumination={"Ed0": 1.0, "spectrum": {"model": "spectrl2", "day_of_year": 100},
                          "sun_position": {"time": "2024-06-21T12:00:00Z", "latitude_deg": 40.0,
                                           "longitude_deg": 0.0}}),
        "lists_cox_munk_wind": _mono(
            wavelengths_nm={"start": 400, "stop": 600, "step": 100},
            illumination={"Ed0": 2.0, "sun_zenith_deg": 40,
                          "spectrum": {"model": "table", "file": f["spectrum.csv"]}},
            surface={"model": "cox_munk", "n_water": 1.34, "wind_speed_m_s": 5.0,
                     "wind_direction_deg": 30.0},
            water={"layers": [{"thickness_m": 3.0, "a": [0.1, 0.2, 0.3], "b": [0.3, 0.2, 0.1],
                               "bb_ratio": [0.01, 0.02, 0.03]}]},
            bottom={"model": "black"},
            tallies={"depths_m": [0, 1], "phi_bands": 12, "local_directions_deg": [[170, 30]]}),
        "ggx": _mono(bottom={"model": "ggx", "roughness": 0.3, "n_ratio": 1.15,
                             "diffuse_reflectance": 0.1}, tallies=SMALL_TALLIES),
        "ff_hapke_slope": _mono(
            surface={"model": "cox_munk", "mean_square_slope": 0.02},
            water={"layers": [{"thickness_m": 1.0, "a": 0.2, "b": 0.5,
                               "phase": {"model": "fournier_forand", "bb_ratio": 0.02}},
                              {"thickness_m": 1.0, "a": 0.1, "b": 0.3,
                               "phase": {"model": "two_term_hg", "g1": 0.9, "g2": -0.3,
                                         "alpha": 0.9}}]},
            bottom={"model": "hapke", "albedo": 0.5, "asymmetry": 0.1,
                    "opposition_amplitude": 0.5, "opposition_width": 0.06},
            tallies=SMALL_TALLIES),
        "mixture_lambertian_specular": _mono(
            water={"layers": [{"thickness_m": 2.0, "a": 0.1, "phase": {
                "model": "mixture", "components": [{"b": 0.1, "phase": {"model": "pure_water"}},
                                                   {"b": 0.3, "phase": {"model": "petzold"}}]}}]},
            bottom={"model": "lambertian_specular", "diffuse_reflectance": 0.2,
                    "specular_reflectance": 0.1},
            tallies={"depths_m": [0, 1], "nadir_estimator": "crossing"}),
        "files": _mono(
            illumination={"Ed0": 1.0, "sun_zenith_deg": 30, "diffuse_fraction": 0.3,
                          "sky": {"map": f["sky.npy"]}},
            water={"layers": [{"thickness_m": 2.0, "a": 0.1, "b": 0.4,
                               "phase": {"model": "table", "file": f["phase.csv"]}}]},
            bottom={"model": "table", "file": f["brdf.npz"], "reciprocity_tolerance": 0.05},
            tallies=SMALL_TALLIES),
        "deep": _mono(water={"layers": [{"thickness_m": 1.0, "a": 0.1, "b": 0.2,
                                         "phase": {"model": "rayleigh"}},
                                        {"thickness_m": math.inf, "a": 0.2, "b": 0.1}]},
                      bottom={"model": "none"}, tallies=SMALL_TALLIES),
        "specular": _mono(bottom={"model": "specular", "reflectance": 0.5},
                          tallies=SMALL_TALLIES),
        # the grid is extended for the excitation (config/inelastic.py): 500-700 nm traced
        "inelastic": _mono(
            wavelengths_nm={"start": 660, "stop": 700, "step": 20}, tallies=SMALL_TALLIES,
            water={"layers": [{"thickness_m": 2.0, "components": [
                {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": 1.0},
                {"model": "cdom", "a440": 0.1, "slope": 0.014}]}],
                "inelastic": {"raman": {"b488_per_m": 2.6e-4, "exponent": 5.5,
                                        "phase_beta": 0.55},
                              "chlorophyll_fluorescence": {
                                  "quantum_yield": 0.02, "peak_nm": 685, "sigma_nm": 10.6,
                                  "excitation_range_nm": [600, 690]},
                              "cdom_fluorescence": {"a0_scale": 1.0,
                                                    "excitation_range_nm": [500, 550]},
                              "max_step_nm": 10}},
            estimator={"emission_weight": 0.01}),
        "bottom_mixture_spectra": _mono(
            wavelengths_nm=[400, 500, 600], tallies=SMALL_TALLIES,
            bottom={"model": "mixture", "components": [
                {"model": "lambertian", "fraction": 0.6, "reflectance": [0.05, 0.3, 0.15]},
                {"model": "lambertian", "fraction": 0.4,
                 "reflectance": {"file": f["bottom.csv"]}}]}),
    }


# templates whose scene build costs 0.1-1 s (a BRDF's tabulated sampler): only the first
# accepted extreme value of each of their keys is run
COSTLY = {"ggx", "ff_hapke_slope", "files"}

# accepted values whose run fails (NaN results or a traceback) for a reason outside the schema
# and the readers, each the subject of a strict xfail test (none left: the kernel's spectral
# NaNs of b = 1e-308 or 1e6 at one wavelength and of particles at b550 = 1000 are fixed, tests
# below)
KNOWN: dict = {}


# --- walking the schema -----------------------------------------------------------------------

def holds_number(annotation) -> bool:
    if annotation in (int, float):
        return True
    if isinstance(annotation, type):
        return False
    return any(holds_number(arg) for arg in get_args(annotation) if not isinstance(arg, str))


def schema_models(tp=SceneConfig, found=None) -> set:
    found = set() if found is None else found
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        if tp not in found:
            found.add(tp)
            for field in tp.model_fields.values():
                schema_models(field.annotation, found)
        return found
    for arg in get_args(tp):
        schema_models(arg, found)
    return found


def numeric_fields() -> set[tuple[str, str]]:
    return {(model.__name__, name) for model in schema_models()
            for name, field in model.model_fields.items() if holds_number(field.annotation)}


def leaves(obj, path=()):
    """(path, model class, field name) of every numeric value under a validated model: scalars,
    and the first and last entries of lists (each number of a pair)."""
    for name, field in type(obj).model_fields.items():
        value = getattr(obj, name)
        here = path + (name,)
        if isinstance(value, BaseModel):
            yield from leaves(value, here)
        elif isinstance(value, list) and value and isinstance(value[0], BaseModel):
            for i, item in enumerate(value):
                yield from leaves(item, here + (i,))
        elif holds_number(field.annotation):
            if not isinstance(value, (list, tuple)):
                yield here, type(obj), name
                continue
            for i in sorted({0, len(value) - 1} if value else ()):
                if isinstance(value[i], (list, tuple)):
                    yield from ((here + (i, j), type(obj), name) for j in range(len(value[i])))
                else:
                    yield here + (i,), type(obj), name


def models_reached(obj, found=None) -> set:
    found = set() if found is None else found
    found.add(type(obj))
    for name in type(obj).model_fields:
        value = getattr(obj, name)
        for item in value if isinstance(value, list) else [value]:
            if isinstance(item, BaseModel):
                models_reached(item, found)
    return found


def edges(constraints) -> set[float]:
    """The values at the edges of the ranges the constraints allow (ge, le themselves; the
    next float inside gt, lt)."""
    out = set()
    for constraint in constraints:
        for kind, step in (("ge", None), ("le", None), ("gt", math.inf), ("lt", -math.inf)):
            edge = getattr(constraint, kind, None)
            if isinstance(edge, (int, float)) and math.isfinite(edge) and abs(edge) < 1e300:
                out.add(float(edge) if step is None else math.nextafter(edge, step))
    return out


def bounds(annotation) -> set[float]:
    """The range edges anywhere in an annotation (Annotated[..., Field(...)], in unions and
    lists too)."""
    out = set()
    for meta in getattr(annotation, "__metadata__", ()):
        out |= edges([meta] + list(getattr(meta, "metadata", ())))
    for arg in get_args(annotation):
        if not isinstance(arg, (str, int, float)):
            out |= bounds(arg)
    return out


def field_bounds(field) -> set[float]:
    """A field's range edges: pydantic keeps a plain Annotated field's constraints in its
    metadata, not in its annotation."""
    return edges(field.metadata) | bounds(field.annotation)


def with_value(scene: dict, path: tuple, value) -> dict:
    """A copy of the scene with the value at path (mappings on the way created)."""
    scene = copy.deepcopy(scene)
    node = scene
    for key in path[:-1]:
        if isinstance(key, str) and node.get(key) is None:
            node[key] = {}
        node = node[key]
    node[path[-1]] = value
    return scene


def render(path: tuple) -> str:
    text = ""
    for key in path:
        text += f"[{key}]" if isinstance(key, int) else ("." if text else "") + key
    return text


def shown(value) -> tuple[str, ...]:
    """How a message may write the value."""
    return (repr(value), f"{value:g}", str(value), repr(float(value)))


def finite(result) -> list[str]:
    return [name for name, q in result.quantities.items()
            if not (np.all(np.isfinite(q.mean)) and np.all(np.isfinite(q.stderr)))]


def one_line(message: str) -> None:
    assert message and "\n" not in message.strip() and "Traceback" not in message, message


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    return templates(tmp_path_factory.mktemp("fuzz_numeric"))


def test_every_numeric_key_of_the_schema_is_reached(scenes):
    """Every model of the schema appears in a template, so every numeric field is fuzzed."""
    reached = set()
    for scene in scenes.values():
        reached |= {m.__name__ for m in models_reached(load_config(copy.deepcopy(scene)))}
    missing = {model for model, _ in numeric_fields()} - reached
    assert not missing, f"add these models to a template of tests/test_fuzz_numeric_keys.py: " \
                        f"{sorted(missing)}"
    assert len(numeric_fields()) >= 79


# (model, field, list indices) fuzzed by an earlier template: each key is fuzzed in the first
# template that reaches it (the templates run in this order)
FUZZED: set = set()
TEMPLATES = ["hg_lambertian", "constituents_minnaert", "sun_spectrl2", "lists_cox_munk_wind",
             "ggx", "ff_hapke_slope", "mixture_lambertian_specular", "files", "deep",
             "specular", "bottom_mixture_spectra", "inelastic"]


@pytest.mark.parametrize("template", TEMPLATES)
def test_numeric_keys_load_or_are_refused_in_one_line_and_run_finite(scenes, template):
    scene = scenes[template]
    base = load_config(copy.deepcopy(scene))
    assert not finite(oceanmc.simulate(base, threads=1))
    problems = []
    refused = ran = 0
    for path, model, name in leaves(base):
        indices = tuple(k for k in path[path.index(name) + 1:])
        if (model.__name__, name, indices) in FUZZED:
            continue
        FUZZED.add((model.__name__, name, indices))
        field = model.model_fields[name]
        first_accepted = True
        for value in sorted(set(VALUES) | field_bounds(field), key=repr):
            if name in ("photons", "seed", "batches", "max_events", "phi_bands",
                        "day_of_year") and math.isfinite(value) and value == int(value):
                value = int(value)
            where = (template, render(path), value)
            try:
                with warnings.catch_warnings():   # a warning would print lines of its own
                    warnings.simplefilter("error", RuntimeWarning)
                    config = load_config(with_value(scene, path, value))
            except ConfigError as exc:
                message = str(exc)
                refused += 1
                keys = [k for k in path if isinstance(k, str) and k not in ("water", "layers")]
                if "\n" in message.strip() or not (
                        any(k in message for k in keys) or any(s in message for s in shown(value))):
                    problems.append((*where, "refused without naming the key or value",
                                     message))
                continue
            except Exception as exc:   # noqa: BLE001 - any other exception is the failure
                problems.append((*where, "traceback", repr(exc)))
                continue
            if template in COSTLY and not first_accepted:
                continue
            first_accepted = False
            if name not in ("photons", "batches"):
                config = config.model_copy(update=TINY_RUN)
            if config.photons > 10_000:
                continue
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("error", RuntimeWarning)
                    result = oceanmc.simulate(config, threads=1)
            except ConfigError as exc:
                one_line(str(exc))
                continue
            except Exception as exc:   # noqa: BLE001
                if where not in KNOWN:
                    problems.append((*where, "traceback in the run", repr(exc)))
                continue
            ran += 1
            bad = finite(result)
            if bad and where not in KNOWN:
                problems.append((*where, "non-finite results with success", bad[:4]))
    assert not problems, "\n".join(map(str, problems))


# --- the classes found, one test each -------------------------------------------------------

def refused(config, *words):
    with pytest.raises(ConfigError) as info:
        load_config(config)
    message = str(info.value)
    one_line(message)
    for word in words:
        assert word in message, (word, message)
    return message


def test_mixture_components_b_is_bounded_as_a_layers_b():
    """A mixture component's b had no upper bound: b = 1e308 ran (the layer's b, their sum,
    escaped the layer's 0 .. 1e6 1/m) with overflows in the phase tables."""
    petzold = {"model": "petzold"}
    layer = {"thickness_m": 2.0, "a": 0.1, "phase": {"model": "mixture", "components": [
        {"b": 1e308, "phase": petzold}]}}
    refused(_mono(water={"layers": [layer]}), "water.layers[0].phase.components[0].b = 1e+308",
            "allowed: a number 0 .. 1e+06")
    layer["phase"]["components"] = [{"b": 1e6, "phase": petzold}, {"b": 1e6, "phase": petzold}]
    refused(_mono(water={"layers": [layer]}), "water.layers[0]",
            "their b add up to 2e+06 1/m", "allowed: at most 1e+06 1/m")


def test_ed0_below_1e_minus_100_is_refused_its_variances_would_underflow(tmp_path):
    """Ed0 = 1e-300 ran with every standard error 0 (the squared deviations of the batches fell
    below the smallest double): refused below 1e-100, as is a spectrum that brings it there."""
    for ed0 in (1e-101, 1e-300, 1e-308):
        refused(_mono(illumination={"Ed0": ed0}), f"illumination.Ed0 = {ed0:g}",
                "allowed: a number 1e-100 .. 1e+100")
    result = oceanmc.simulate(_mono(illumination={"Ed0": 1e-100}, photons=400), threads=1)
    assert np.all(result.stderr("Ed") > 0.0) and np.all(result.stderr("Lu") > 0.0)
    (tmp_path / "s.csv").write_text("wavelength_nm,Ed0,diffuse_fraction\n400,1e-60,0.1\n"
                                    "700,1,0.1\n")
    config = load_config(_mono(wavelengths_nm=[400, 500], illumination={
        "Ed0": 1e-50, "spectrum": {"model": "table", "file": str(tmp_path / "s.csv")}}))
    with pytest.raises(ConfigError) as info:
        oceanmc.simulate(config)
    one_line(str(info.value))
    assert "illumination.Ed0 = 1e-50 times the spectrum's Ed0 falls to 1e-110 at 400 nm; " \
           "allowed: at least 1e-100" in str(info.value)


def test_emission_weight_below_1e_minus_100_is_refused(scenes):
    """emission_weight = 5e-324 gave NaN results in the inelastic template once it had three
    processes (an emitted packet's spectral weights divide by what it carries, at least
    emission_weight per wavelength, which overflowed): refused below 1e-100."""
    scene = copy.deepcopy(scenes["inelastic"])
    for weight, shown in ((5e-324, "5e-324"), (1e-300, "1e-300"), (1e-101, "1e-101")):
        scene["estimator"]["emission_weight"] = weight
        refused(scene, f"estimator.emission_weight = {shown}", "allowed: a number 1e-100 .. 1")
    scene["estimator"]["emission_weight"] = 1e-100
    assert not finite(oceanmc.simulate(scene, threads=1))


def test_an_infinitely_deep_layer_over_a_bottom_is_refused_naming_its_thickness():
    """thickness_m: .inf over a bottom was refused without naming thickness_m."""
    layers = [{"thickness_m": 1.0, "a": 0.1, "b": 0.1}, {"thickness_m": math.inf, "a": 0.1,
                                                          "b": 0.1}]
    refused(_mono(water={"layers": layers}, tallies=SMALL_TALLIES),
            "water.layers[1].thickness_m = .inf with bottom.model = 'lambertian'",
            "use bottom.model = 'none' or a finite thickness_m")


def test_photons_beyond_their_range_are_shown_as_written():
    """photons: 1e308 was refused as '10000000000000000109790636294404554174049230967731184...'
    (the 309 digits of int(1e308), cut): the value is now shown as given."""
    for value, text in ((1e308, "photons = 1e+308"), ("1e308", "photons = '1e308'"),
                        (-1e20, "photons = -1e+20")):
        refused(_mono(photons=value), text, "allowed: an integer 1 .. 1e+13")
    assert load_config(_mono(photons="2e3")).photons == 2000


def test_a_profile_needing_more_than_1e308_sublayers_is_refused_without_a_warning(capfd):
    """Linear profile depths 1e-308 m apart over 5 m: numpy's 'overflow encountered in scalar
    divide' (two lines on stderr) came before the one-line refusal, which counted 'inf
    sublayers'."""
    scene = _mono(wavelengths_nm=[400, 500], tallies=SMALL_TALLIES, water={"layers": [
        {"thickness_m": 5.0, "components": [{"model": "pure_water"}, {
            "model": "cdom", "a440": {"profile": "linear", "depths_m": [0, 1e-308, 5],
                                      "values": [0.05, 0.06, 0.07]}}]}]})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ConfigError) as info:
            oceanmc.simulate(scene, threads=1)
    one_line(str(info.value))
    assert "its length scale of 1e-308 m" in str(info.value)
    assert "needs more than 1e+308 sublayers; allowed: at most 5000" in str(info.value)


@pytest.mark.parametrize("change, key", [
    ({"water": {"layers": [{"thickness_m": 2.0, "a": 0.1, "b": 0.4, "phase": {
        "model": "henyey_greenstein", "g": 1 - 1e-10}}]}}, "water.layers[0].phase.g"),
    ({"water": {"layers": [{"thickness_m": 2.0, "a": 0.1, "b": 0.4, "phase": {
        "model": "two_term_hg", "g1": 0.9, "g2": -1 + 1e-10}}]}}, "water.layers[0].phase.g2"),
    ({"bottom": {"model": "hapke", "albedo": 0.5, "asymmetry": -1 + 1e-12}}, "bottom.asymmetry"),
    ({"wavelengths_nm": [400, 600], "tallies": SMALL_TALLIES, "illumination": {
        "spectrum": {"model": "spectrl2", "aerosol_asymmetry_factor": 1 - 1e-8}}},
     "illumination.spectrum.aerosol_asymmetry_factor"),
])
def test_an_asymmetry_within_1e_minus_6_of_one_is_refused(change, key):
    """Asymmetry parameters were allowed up to the float next to +-1: a Henyey-Greenstein g of
    1 - 1e-10 gave NaN Lu, Lw_nadir and Rrs_nadir (the local estimate's cap tables) with exit 0,
    a Hapke asymmetry of -1 + 1e-12 made the reciprocity check compare NaN (so it passed, with
    numpy's warning printed), SPECTRL2's aerosol factor of 1 - 1e-8 gave NaN irradiances (and
    pvlib's overflow warning). Allowed: -0.999999 .. 0.999999."""
    scene = _mono(**change)
    refused(scene, f"{key} = ", "allowed: a number -0.999999 .. 0.999999")
    edge = copy.deepcopy(scene)
    node = edge
    parts = key.replace("[0]", ".0").split(".")
    for part in parts[:-1]:
        node = node[int(part)] if part.isdigit() else node[part]
    node[parts[-1]] = math.copysign(0.999999, node[parts[-1]])
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert not finite(oceanmc.simulate(edge, threads=1))


# --- found here, outside the schema and the readers: strict xfail until fixed ------------------

SPECTRAL_TURBID = {"photons": 200, "batches": 2, "seed": 1, "wavelengths_nm": [400, 550, 700],
                   "water": {"layers": [{"thickness_m": math.inf, "a": [0.03, 0.06, 0.6],
                                         "b": [10.0, 5.0, 2.0], "phase": {"model": "petzold"}}]},
                   "bottom": {"model": "none"}, "tallies": {"depths_m": [0]}}


def test_spectral_walk_in_turbid_water_gives_finite_results():
    """A turbid coastal water (b 10, 5, 2 1/m at 400, 550, 700 nm, a 0.03-0.6 1/m, Petzold) gave
    NaN for every quantity with exit status 0: a hero of the largest c shrank every other K_j by
    c_j / c_h per collision while the deferred exp((c_h - c_j) D) grew (0 x inf). Particles at
    b550 = 1000 1/m and b = 1e6 1/m at one wavelength did the same (the numeric-key fuzz)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        result = oceanmc.simulate(SPECTRAL_TURBID, threads=1)
    assert not finite(result)
    assert np.all(result["Ed"] > 0.0)


def test_spectral_layer_with_a_subnormal_b_at_one_wavelength_is_refused():
    """b = 1e-308 1/m at one wavelength and 0.2 at another overflowed 1 / beta_h (NaN with exit
    status 0): the spectral walk's ratios of scattering need b within 12 orders of magnitude."""
    scene = _mono(wavelengths_nm=[400, 500, 600], tallies=SMALL_TALLIES, estimator={},
                  water={"layers": [{"thickness_m": 3.0, "a": [0.1, 0.2, 0.1],
                                     "b": [1e-308, 0.2, 0.1]}]})
    with pytest.raises(ConfigError) as info:
        oceanmc.simulate(scene, threads=1)
    one_line(str(info.value))
    assert "water.layers[0].b" in str(info.value) and "400 nm" in str(info.value)


def test_spectral_layer_with_a_subnormal_b_at_every_wavelength_runs_finite():
    """b = 1e-308 1/m at every wavelength (found by the spectral-bottom fuzz template) gave NaN:
    such a layer is packed as not scattering (scene/medium.py B_FLOOR)."""
    scene = _mono(wavelengths_nm=[400, 500, 600], tallies=SMALL_TALLIES, estimator={},
                  water={"layers": [{"thickness_m": 2.0, "a": [0.1, 0.2, 0.1], "b": 1e-308}]},
                  bottom={"model": "lambertian", "reflectance": 0.3})
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        result = oceanmc.simulate(scene, threads=1)
    assert not finite(result)
    assert np.all(result["Eu"] > 0.0)


def test_spectral_scene_with_no_upwelling_light_at_one_wavelength_runs():
    """Clear water (b = 0) over a bottom, absorbing 1000 1/m at one of two wavelengths: a
    KeyError traceback ('air/t_up'): from_tallies left the ratio Eu_water_leaving / Eu(0-)
    out of a wavelength where a batch had no upwelling light (0/0), and stack_wavelengths
    looked it up in every wavelength. The ratio is now derived from the batch means
    (run/derived.py t_up): defined where there is upwelling light, NaN where there is none;
    everything else is there."""
    from oceanmc.run.derived import derive
    scene = _mono(wavelengths_nm=[400, 500], tallies={"depths_m": [0]}, estimator={},
                  water={"layers": [{"thickness_m": 1.0, "a": [0.1, 1000.0], "b": 0.0}]})
    result = oceanmc.simulate(scene, threads=1)
    assert not finite(result)
    assert "air/Eu_water_leaving" in result
    assert result["Eu"][1, 0] == 0.0 and result["Eu"][0, 0] > 0.0
    t_up = derive(result)["t_up"]
    assert 0.0 < t_up.value[0] < 1.0 and np.isnan(t_up.value[1])


def test_runs_differing_only_in_an_undefined_ratio_merge_without_it():
    """The same class in merge_results: a file written before 2026-11-29 holds air/t_up per
    batch, and one of its batches without upwelling light left it out; merging a run that has
    it with one that lacks it was refused ('different quantities') or, on resume, a KeyError.
    The merge keeps the quantities both hold; any other difference is still refused, naming
    the quantity."""
    from oceanmc.run.results import MergeError, merge_results
    scene = _mono(tallies={"depths_m": [0]}, estimator={}, batches=2, photons=200,
                  water={"layers": [{"thickness_m": 1.0, "a": 0.5, "b": 0.0}]})
    first = oceanmc.simulate(scene, threads=1)
    second = oceanmc.simulate(dict(scene, seed=4), threads=1)
    old = first.quantities["air/Eu"]   # an older file's per-batch ratio, in the first run only
    first.quantities["air/t_up"] = type(old)("air/t_up", (), old.batches / 2.0, "1", "t_up")
    merged = merge_results([first, second])
    assert "air/t_up" not in merged and merged.attrs["batches"] == 4
    assert merged["air/Eu"].shape == ()
    del second.quantities["air/Eu"]
    with pytest.raises(MergeError, match=r"different quantities \(air/Eu\)"):
        merge_results([first, second])


def test_tiny_quantities_keep_their_standard_errors():
    """A bottom of reflectance 1e-200 under non-scattering water: Eu ~ 1e-200 had a standard
    error of exactly 0 (Quantity.stderr squared the deviations of the batches unscaled: below
    about 1e-154 they underflow to 0); they are now scaled by their largest first, and equal
    numpy's standard error of the batches brought near 1."""
    scene = _mono(photons=2000, batches=4, tallies=SMALL_TALLIES, estimator={},
                  water={"layers": [{"thickness_m": 1.0, "a": 0.1, "b": 0.0}]},
                  bottom={"model": "lambertian", "reflectance": 1e-200})
    result = oceanmc.simulate(scene, threads=1)
    assert np.all(result["Eu"] > 0.0)
    assert np.all(result.stderr("Eu") > 0.0)
    batches = result.quantities["Eu"].batches * 1e200
    np.testing.assert_allclose(result.stderr("Eu") * 1e200,
                               batches.std(axis=0, ddof=1) / np.sqrt(4), rtol=1e-12)


def test_carried_inelastic_light_over_a_1e_minus_308_bottom_stays_finite(scenes):
    """bottom.reflectance 1e-308 in the inelastic template gave NaN once the emitting packet
    carried the emitted light on (1 / p.w overflowed); such light is now left out."""
    scene = copy.deepcopy(scenes["inelastic"])
    scene["bottom"] = {"model": "lambertian", "reflectance": 1e-308}
    result = oceanmc.simulate(load_config(scene).model_copy(update=TINY_RUN), threads=1)
    assert not finite(result)
