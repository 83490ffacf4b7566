"""What a scene uses is read from its records at run time (one compiled loop for every scene):
the packers set each component's switches right, and a switched-off feature changes nothing
else. Tallies that use no
random numbers (radiance quads, the cap estimate without a bottom) are switched on and off in
scenes that are otherwise the same: every other tally must stay bit-identical, since the random
streams are the same."""
import numpy as np
import pytest

import oceanmc
from oceanmc import scene

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


def switches(sc) -> set[str]:
    """The features a packed scene switches on, read from its records."""
    on = {"radiance": sc.grid[0]["radiance_on"], "sky": sc.sky[0]["diffuse_fraction"] > 0.0,
          "bottom": sc.bottom[0]["reflects"], "cap": sc.estimates[0]["cap_on"],
          "directions": sc.estimates[0]["directions_on"],
          "splitting": sc.estimator[0]["splitting"], "upward": sc.estimator[0]["upward"]}
    return {name for name, value in on.items() if value}


@pytest.mark.parametrize("changes, expected", [
    ({"tallies.radiance": False}, set()),
    ({}, {"radiance"}),
    ({"illumination.diffuse_fraction": 0.3}, {"radiance", "sky"}),
    ({"bottom": {"model": "lambertian", "reflectance": 0.2}}, {"radiance", "bottom"}),
    ({"bottom": {"model": "black"}, "tallies.nadir_estimator": "local"}, {"radiance", "cap"}),
    ({"tallies.radiance": False, "tallies.local_directions_deg": [[180.0, 0.0]]},
     {"directions"}),
    ({"estimator": {"split_weight": 2.0}}, {"radiance", "splitting"}),
    ({"estimator": {"upward_fraction": 0.1}}, {"radiance", "upward"}),
])
def test_switches_follow_the_scene(changes, expected):
    assert switches(scene.build(config(**changes))) == expected


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
