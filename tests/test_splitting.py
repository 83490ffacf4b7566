"""Splitting by weight (estimator.split_weight): unbiased against the plain estimator, and a
no-op when no packet reaches the threshold. The scene has weights well above 1: sky photons of a
cosine-sampled map with a bright spot (weight L pi / E, up to ~20 here) over shallow water and a
Hapke bottom sampled by the general tabulated sampler (weight f cos / pdf)."""
import numpy as np

import oceanmc

from stats_helpers import assert_same, dof_of

NAMES = ["Ed", "Eu", "Eod", "Eou", "air/Eu", "budget/surface_reflection",
         "budget/water_leaving", "budget/absorbed_bottom", "budget/absorbed_layer_1"]


def scene(tmp_path, split_weight, seed, photons=300_000):
    sky = np.ones((45, 90))
    sky[19:22, 36:39] = 30.0
    np.save(tmp_path / "spot.npy", sky)
    return {
        "photons": photons, "batches": 20, "seed": seed,
        "illumination": {"sun_zenith_deg": 30.0, "diffuse_fraction": 1.0,
                         "sky": {"map": str(tmp_path / "spot.npy"), "sampling": "cosine"}},
        "water": {"layers": [{"thickness_m": 2.0, "a": 0.1, "b": 0.5,
                              "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
        "bottom": {"model": "hapke", "albedo": 0.7, "asymmetry": -0.3,
                   "opposition_amplitude": 0.8, "opposition_width": 0.06},
        "tallies": {"depths_m": [0.0, 1.0, 2.0], "radiance": False,
                    "nadir_estimator": "crossing"},
        "estimator": {"split_weight": split_weight},
    }


def test_splitting_is_unbiased(tmp_path):
    """Every flux and budget term of the split run against the plain run (independent seeds):
    |z| under the Bonferroni-t bound for all compared values; and the split run followed more
    packets (more scattering events per photon), so splitting did happen."""
    plain = oceanmc.simulate(scene(tmp_path, None, seed=1), threads=2)
    split = oceanmc.simulate(scene(tmp_path, 1.5, seed=2), threads=2)
    compared = 0
    for name in NAMES:
        assert_same(split[name], split.stderr(name), plain[name], plain.stderr(name),
                    dof=dof_of(plain), n_compared=len(NAMES) * 3, rel_max=0.05,
                    what=f"{name}: split vs plain")
        compared += np.size(plain[name])
    assert compared >= 15
    plain_events, split_events = (r.attrs["scattering_events"] / r.attrs["photons"]
                                  for r in (plain, split))
    assert split_events > 1.03 * plain_events   # +6% measured; the mean is good to ~0.5%


def test_threshold_never_reached_changes_nothing(tmp_path):
    """A threshold above every weight: the loop with splitting compiled in gives the plain run
    bit for bit (the same random numbers, no copies)."""
    plain = oceanmc.simulate(scene(tmp_path, None, seed=3, photons=20_000), threads=1)
    idle = oceanmc.simulate(scene(tmp_path, 1e9, seed=3, photons=20_000), threads=1)
    for name in NAMES:
        assert np.array_equal(idle.quantities[name].batches, plain.quantities[name].batches), name
