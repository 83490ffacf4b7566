"""The photon loop's variants (kernel/variants.py): a scene compiles only the optional parts of
the loop it uses, and runs on any variant that holds them with the same results bit for bit."""
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from oceanmc.config import load_config
from oceanmc.kernel.variants import EVERYTHING, PARTS, REFINES, Variant, union
from oceanmc.scene import predicted_variant

REPO = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(REPO))
TIMING = {"wall_time_s", "startup_time_s", "photons_per_s", "threads"}


def test_supersets_are_the_variants_that_hold_it_nearest_first():
    plain = Variant(*(False,) * len(PARTS))
    # each refinement and the part it refines: off, the part alone, or both
    consistent = 2 ** (len(PARTS) - 2 * len(REFINES)) * 3 ** len(REFINES)
    assert len(plain.supersets()) == consistent
    assert all(v.consistent for v in plain.supersets())
    assert plain.supersets()[0] == plain and plain.supersets()[-1] == EVERYTHING
    walk = plain._replace(rough_surface=True, facet_walk=True)
    assert not plain._replace(facet_walk=True).consistent and walk.consistent
    assert all(v.rough_surface and v.facet_walk for v in walk.supersets())
    assert walk in plain._replace(rough_surface=True).supersets()
    spectral = plain._replace(spectral=True)
    found = spectral.supersets()
    assert found[0] == spectral and len(found) == consistent // 2
    assert all(v.holds(spectral) for v in found)
    assert [sum(v) for v in found] == sorted(sum(v) for v in found)
    assert not plain.holds(spectral) and EVERYTHING.holds(plain)
    assert union([]) == plain
    assert union([spectral, plain._replace(local_estimates=True)]) == \
        plain._replace(spectral=True, local_estimates=True)
    assert plain.label == "plain" and spectral.kernel_args()[0] is True
    assert spectral.kernel_args()[1:] == (None,) * (len(PARTS) - 1)


@pytest.mark.long(cpu_s=25)
def test_a_scene_on_its_own_variant_gives_the_same_file_as_on_the_whole_loop(tmp_path,
                                                                             small_scene):
    """The small scene made plain (one wavelength, flat sea, black bottom, the crossing
    estimate at nadir: no optional part, the variant that leaves the most out) compiled cold
    with only its parts (the notice says so), and run again here on the whole loop (the
    session's): every dataset and attribute the same, bit for bit, but the timings. (The
    plain variant compiles in about half the time of one with a reflecting bottom and local
    estimates: 25 against 48 CPU seconds in the tests.)"""
    import oceanmc
    from oceanmc.run.compiling import ready
    small_scene["bottom"] = {"model": "black"}
    small_scene["tallies"]["nadir_estimator"] = "crossing"
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(small_scene))
    own = subprocess.run([sys.executable, "-m", "oceanmc", "run", str(scene), "-o", "own.h5"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=900,
                         env=dict(ENV, OCEANMC_CACHE_DIR=str(tmp_path / "empty-cache")))
    assert own.returncode == 0, own.stderr
    assert "compiling the photon loop with its parts for this scene (plain;" in own.stderr
    assert ready(predicted_variant(load_config(scene)))[1] == EVERYTHING
    oceanmc.simulate(scene).save(tmp_path / "whole.h5")
    with h5py.File(tmp_path / "own.h5") as a, h5py.File(tmp_path / "whole.h5") as b:
        mine = {k: a.attrs[k] for k in a.attrs if k not in TIMING | {"config_file"}}
        assert mine == {k: b.attrs[k] for k in b.attrs if k not in TIMING | {"config_file"}}
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert len(names) > 50
        for name in names:
            assert np.array_equal(a[name][()], b[name][()], equal_nan=True), name


def test_own_variant_setting_admits_only_the_scenes_own(monkeypatch):
    """OCEANMC_OWN_VARIANT=1 (the bench's): a scene runs on its own variant only, never on a
    larger one that the process or the cache holds."""
    from oceanmc.run import compiling
    spectral = Variant(*(False,) * len(PARTS))._replace(spectral=True)
    monkeypatch.delenv(compiling.OWN_VARIANT_ENV, raising=False)
    assert compiling._candidates(spectral) == spectral.supersets()
    assert compiling._here(spectral) == EVERYTHING   # the session's whole loop
    monkeypatch.setenv(compiling.OWN_VARIANT_ENV, "1")
    assert compiling._candidates(spectral) == [spectral]
    assert compiling._here(spectral) is None


@pytest.mark.parametrize("changes, parts", [
    ({"surface": {"model": "cox_munk", "wind_speed_m_s": 7.0, "method": "walk"}},
     {"rough_surface", "facet_walk"}),
    ({"surface": {"model": "cox_munk", "wind_speed_m_s": 7.0, "method": "table"}},
     {"rough_surface"}),
    ({"bottom": {"model": "lambertian", "reflectance": 0.2}}, {"reflecting_bottom"}),
    ({"bottom": {"model": "lambertian", "reflectance": 0.2, "sampling": "tabulated"}},
     {"reflecting_bottom", "detailed_bottom"}),
    ({"bottom": {"model": "mixture", "components": [
        {"model": "minnaert", "k": 0.8, "fraction": 0.5, "reflectance": 0.1},
        {"model": "minnaert", "k": 0.8, "fraction": 0.5, "reflectance": 0.3}]}},
     {"reflecting_bottom"}),
    ({"bottom": {"model": "ggx", "roughness": 0.3}},
     {"reflecting_bottom", "detailed_bottom"}),
    ({"tallies": {"local_directions_deg": [[180, 0]]}}, {"local_estimates", "exact_directions"}),
])
def test_each_refinement_is_predicted_from_the_config_as_the_packed_scene_uses_it(changes,
                                                                                 parts):
    """The facet walk (surface.method: walk), bottoms beyond the closed-form four (or sampled by
    table) and the exact directions are parts of their own: the config's prediction, which the
    cold start compiles, is the packed scene's own variant."""
    from oceanmc.scene import build
    base = {"water": {"layers": [{"thickness_m": 5.0, "a": 0.1, "b": 0.5}]},
            "bottom": {"model": "black"},
            "tallies": {"depths_m": [0], "nadir_estimator": "crossing"}}
    for key, value in changes.items():
        base[key] = {**base[key], **value} if key == "tallies" else value
    config = load_config(base)
    predicted = predicted_variant(config)
    assert predicted == build(config).variant
    assert {part for part, on in zip(PARTS, predicted) if on} == parts
