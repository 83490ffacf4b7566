"""The scene's two pools (kernel/records.py merge): every component's tables, packed with
offsets from 0 into pools of its own, are found at the merged record's offsets in the scene's
one float pool and one int pool; scalars are left alone."""
import numpy as np

import oceanmc
from oceanmc import scene
from oceanmc.kernel import records
from oceanmc.scene import medium, sky


def test_merge_moves_each_records_offsets_with_its_pools():
    a = records.record(records.BOTTOM, model=2, reflects=1, mirror=0, params=0)
    s = records.record(records.SKY, sun_mu=0.5, sun_sin=0.8, diffuse_fraction=0.2, model=0,
                       n_rows=1, n_cols=1, s_edges=0, phi_edges=2, row_cdf=4, cell_cdf=5,
                       cell_l=6, params=7)
    a_floats = np.arange(3.0)
    s_floats = 10.0 + np.arange(15.0)
    (a2, s2), floats, ints = records.merge([(a, a_floats, np.zeros(0, np.int64)),
                                            (s, s_floats, np.arange(2, dtype=np.int64))])
    np.testing.assert_array_equal(floats[a2[0]["params"]:a2[0]["params"] + 3], a_floats)
    for name in records.POOL_OFFSETS[records.SKY][0]:
        assert floats[s2[0][name]] == s_floats[s[0][name]], name
    assert (s2[0]["sun_mu"], s2[0]["n_rows"], a2[0]["model"]) == (0.5, 1, 2)
    assert a[0]["params"] == 0   # the packer's record is not changed


def test_every_offset_field_is_an_int64():
    for dtype, (floats_at, ints_at) in records.POOL_OFFSETS.items():
        for name in floats_at + ints_at:
            assert dtype.fields[name][0] == np.int64, name


def test_a_built_scene_finds_each_components_tables():
    config = oceanmc.load_config({
        "illumination": {"sun_zenith_deg": 30, "diffuse_fraction": 0.3},
        "water": {"layers": [{"thickness_m": 2.0, "a": 0.1, "b": 0.5},
                             {"thickness_m": 3.0, "a": 0.2, "b": 1.0,
                              "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
        "bottom": {"model": "lambertian", "reflectance": 0.25}})
    sc = scene.build(config)
    own, own_floats, own_ints, _ = medium.pack(config)
    for name in records.POOL_OFFSETS[records.MEDIUM][0]:
        assert sc.floats[sc.medium[0][name]] == own_floats[own[0][name]], name
    for name in records.POOL_OFFSETS[records.MEDIUM][1]:
        assert sc.ints[sc.medium[0][name]] == own_ints[own[0][name]], name
    sky_rec, sky_floats = sky.pack(config.illumination)
    for name in records.POOL_OFFSETS[records.SKY][0]:
        assert sc.floats[sc.sky[0][name]] == sky_floats[sky_rec[0][name]], name
    assert sc.floats[sc.bottom[0]["params"]] == 0.25    # the BRDF's first parameter: rho
