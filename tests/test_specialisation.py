"""The photon loop compiled per scene features (kernel/driver.py): the features are read right
from the scene, and leaving a feature's code out changes nothing else. Tallies that use no
random numbers (radiance quads, the cap estimate without a bottom) are switched on and off in
scenes that are otherwise the same: every other tally must stay bit-identical, since the random
streams are the same."""
import numpy as np
import pytest

import oceanmc
from oceanmc import scene
from oceanmc.kernel.driver import features_of
from oceanmc.kernel.models import (FEATURE_BOTTOM, FEATURE_ESTIMATES, FEATURE_RADIANCE,
                                   FEATURE_SKY, FEATURE_SPLITTING, FEATURE_UPWARD)

BASE = {
    "photons": 20_000, "batches": 4, "seed": 5,
    "illumination": {"sun_zenith_deg": 30.0, "diffuse_fraction": 0.0},
    "water": {"layers": [{"thickness_m": 5.0, "a": 0.1, "b": 0.4,
                          "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
    "bottom": {"model": "black"},
    "tallies": {"depths_m": [0.0, 2.0], "nadir_estimator": "crossing"},
}


def config(**changes):
    data = {key: (dict(value) if isinstance(value, dict) else value) for key, value in BASE.items()}
    for path, value in changes.items():
        node = data
        *parents, last = path.split(".")
        for key in parents:
            node = node[key]
        node[last] = value
    return oceanmc.load_config(data)


@pytest.mark.parametrize("changes, expected", [
    ({"tallies.radiance": False}, 0),
    ({}, FEATURE_RADIANCE),
    ({"illumination.diffuse_fraction": 0.3}, FEATURE_RADIANCE | FEATURE_SKY),
    ({"bottom": {"model": "lambertian", "reflectance": 0.2}}, FEATURE_RADIANCE | FEATURE_BOTTOM),
    ({"bottom": {"model": "black"}, "tallies.nadir_estimator": "local"},
     FEATURE_RADIANCE | FEATURE_ESTIMATES),
    ({"tallies.radiance": False, "tallies.local_directions_deg": [[180.0, 0.0]]},
     FEATURE_ESTIMATES),
    ({"estimator": {"split_weight": 2.0}}, FEATURE_RADIANCE | FEATURE_SPLITTING),
    ({"estimator": {"upward_fraction": 0.1}}, FEATURE_RADIANCE | FEATURE_UPWARD),
])
def test_features_follow_the_scene(changes, expected):
    sc, _ = scene.build(config(**changes))
    assert features_of(sc) == expected


def _same_except(a, b, skip):
    names = set(a.quantities) & set(b.quantities)
    compared = 0
    for name in sorted(names):
        if name in skip or name.startswith("radiance") or name.endswith("_crossing"):
            continue
        assert np.array_equal(np.asarray(a[name]), np.asarray(b[name]), equal_nan=True), name
        compared += 1
    assert compared >= 8


def test_radiance_code_left_out_changes_nothing_else():
    with_quads = oceanmc.simulate(config(), threads=1)
    without = oceanmc.simulate(config(**{"tallies.radiance": False}), threads=1)
    assert "radiance" in with_quads.quantities and "radiance" not in without.quantities
    _same_except(with_quads, without, skip=("Lu", "air/Lw_nadir", "air/Rrs_nadir"))


def test_local_estimate_code_left_out_changes_nothing_else():
    local = oceanmc.simulate(config(**{"tallies.nadir_estimator": "local"}), threads=1)
    plain = oceanmc.simulate(config(), threads=1)
    assert np.array_equal(local["Lu_crossing"], plain["Lu"])
    _same_except(local, plain, skip=("Lu", "air/Lw_nadir", "air/Rrs_nadir"))
