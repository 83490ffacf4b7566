"""The phase tables in the scene's pool (scene/medium.py): each distinct table once, found by its
content, so that a scene packs the same pool at every build. Found by id() of their angle
array, as before, configs/deep_chlorophyll_maximum.yaml packed a table more or less from one
build to the next in one process (Fournier-Forand's tables leave phase_tables' cache after
64, and addresses are reused), and with depth windows the same seed gave other results. Every
component's table is its own (it was before too)."""
from pathlib import Path

import numpy as np

import oceanmc
from oceanmc import optics
from oceanmc.scene import medium

# 150 layers of Case-1 water at 6 wavelengths: several hundred Fournier-Forand tables, more
# than phase_tables keeps
SCENE = Path(__file__).resolve().parent.parent / "configs" / "deep_chlorophyll_maximum.yaml"


def pack():
    config = oceanmc.load_config(SCENE)
    layers = optics.column_iops(config)
    rec, floats, ints, _ = medium.pack(config, optics.illumination_spectrum(config)[0])
    return layers, rec[0], floats, ints


def test_every_component_reads_its_own_table():
    layers, m, floats, ints = pack()
    k = 0
    checked = 0
    for layer in layers:   # the components in the order medium.pack lays them out
        for phase_k in (j for j in range(len(layer.phases)) if layer.weights[:, j].max() > 0):
            for _, _, _, table in medium.phase_components(layer.phases[phase_k]):
                if table is not None:
                    start = int(ints[m["comp_tab_start"] + k])
                    length = int(ints[m["comp_tab_len"] + k])
                    assert length == len(table[1])
                    np.testing.assert_array_equal(
                        floats[m["tab_q"] + start:m["tab_q"] + start + length], table[1],
                        err_msg=f"component {k}: {layer.phases[phase_k]}")
                    checked += 1
                k += 1
    assert k == int(m["n_comps"]) and checked > 300


def test_the_same_scene_packs_the_same_pool_each_time():
    _, *first = pack()
    _, *again = pack()
    assert first[0].tobytes() == again[0].tobytes()
    np.testing.assert_array_equal(first[1], again[1])
    np.testing.assert_array_equal(first[2], again[2])
