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


def test_a_table_of_part_of_the_angles_is_refused(tmp_path):
    """A phase table's ends are extrapolated (2 pi p sin psi linear to 0 at 0 and 180 deg):
    one that stops short of 10 or 170 deg (a forward hemisphere, say) is refused in one line
    naming the file and its range, where its backscatter was invented with exit status 0."""
    from oceanmc.scene.phase_tables import TableError, user_table
    half = tmp_path / "half.csv"
    half.write_text("angle,value\n0,10\n90,1\n")
    try:
        user_table(half)
    except TableError as exc:
        message = str(exc)
    else:
        raise AssertionError("a table of 0..90 deg was accepted")
    assert message == (f"phase table {half}: its angles run 0..90 deg; a phase function table "
                       "must reach from at most 10 deg to at least 170 deg (beyond its ends "
                       "2 pi p sin(psi) goes linearly to 0 at 0 and 180 deg)")
    near = tmp_path / "near.csv"
    near.write_text("angle,value\n10,1\n90,0.1\n170,0.05\n")
    psi = user_table(near)[0]
    assert psi[0] == 0.0 and psi[-1] == np.pi
