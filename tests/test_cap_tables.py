"""The nadir cap's moment tables (scene/cap_tables.py): the sparse matrices that take over from
the direct evaluation once many phase functions share an angle grid (a chlorophyll profile's
Fournier-Forand components) give the same moments, for the flat sea's caps and the rough sea's
air cap, and are built only for a grid asked for often."""
import math

import numpy as np
import pytest

from oceanmc.scene import cap_tables, phase_tables

N_WATER = 1.34
BETA = math.radians(5.0)


def ff_table(bb_ratio: float):
    psi, q = phase_tables.fournier_forand_table(bb_ratio)[:2]
    return cap_tables.cumulative(lambda angles: np.interp(angles, psi, q), psi)


def caps():
    alphas = cap_tables.alpha_nodes(BETA)
    beta_w = math.asin(math.sin(BETA) / N_WATER)
    return {"water": cap_tables.cap_geometry(BETA, 0.5 * (1.0 + math.cos(BETA)), alphas),
            "air (flat)": cap_tables.cap_geometry(beta_w, 0.5 * (1.0 + math.cos(beta_w)), alphas),
            "air (7 m/s)": cap_tables.rough_cap_geometry(alphas, math.sqrt(0.0388), N_WATER,
                                                         BETA)}


@pytest.mark.parametrize("cap", ["water", "air (flat)", "air (7 m/s)"])
def test_the_grids_matrices_give_the_direct_moments(cap):
    """Phase functions on one grid (FF at bb/b 0.005-0.03): the first OPERATOR_AFTER - 1 are
    evaluated directly and build nothing; from the OPERATOR_AFTER-th on the grid's matrices give
    M0 and M1 within 1e-13 of the direct evaluation's largest M0 (the same sums in another
    order: 2e-15 to 5e-15 measured), and a phase function on another grid (an isotropic one)
    is evaluated directly."""
    geometry = caps()[cap]
    ratios = np.linspace(0.005, 0.03, cap_tables.OPERATOR_AFTER + 2)
    tables = [ff_table(float(r)) for r in ratios]
    for table in tables[:cap_tables.OPERATOR_AFTER - 1]:
        geometry.moments(table)
    assert not geometry._operators
    for table in tables[cap_tables.OPERATOR_AFTER - 1:]:
        m0, m1 = geometry.moments(table)
        d0, d1 = geometry.direct(table)
        assert np.abs(m0 - d0).max() <= 1e-13 * np.abs(d0).max()
        assert np.abs(m1 - d1).max() <= 1e-13 * np.abs(d0).max()
    assert len(geometry._operators) == 1
    isotropic = cap_tables.cumulative(lambda psi: 0.5 * np.sin(psi), np.zeros(0))
    assert np.array_equal(np.array(geometry.moments(isotropic)),
                          np.array(geometry.direct(isotropic)))
    assert len(geometry._operators) == 1


@pytest.mark.parametrize("cap", ["water", "air (flat)", "air (7 m/s)"])
def test_a_scenes_cap_shares_the_arrays_but_counts_its_own_phase_functions(cap):
    """The geometry's arrays are built once per process and shared, read-only, by the scenes
    that follow; each scene's geometry counts its own phase functions from 0 (when the sparse
    matrices take over: LinearInCdf), so the moments of a scene do not depend on the scenes
    packed before it in the process: a geometry that has taken over gives, in a new one, the
    direct evaluation bit for bit."""
    first = caps()[cap]
    tables = [ff_table(float(r)) for r in np.linspace(0.005, 0.03, cap_tables.OPERATOR_AFTER)]
    for table in tables:
        first.moments(table)
    assert first._operators   # the matrices took over
    second = caps()[cap]
    assert second is not first and not second._operators and not second._asked
    assert second.psi is first.psi and not second.psi.flags.writeable
    m0, m1 = second.moments(tables[-1])
    direct = first.direct(tables[-1])
    assert np.array_equal(m0, direct[0]) and np.array_equal(m1, direct[1])
    with pytest.raises(ValueError):
        second.psi[0, 0] = 1.0


def test_an_emissions_cap_moments_come_back_from_disk_without_the_geometry(tmp_path,
                                                                           monkeypatch):
    """An inelastic emission's cap moments (scene/estimates.py emission_moments) are kept on
    disk beside a layer's: a later process finds them there, the same bit for bit, without
    building the caps' geometry (0.5 s of every start of an inelastic scene otherwise)."""
    from oceanmc.scene import estimates
    monkeypatch.setattr(estimates, "_CAP_DIR", tmp_path)
    monkeypatch.setattr(estimates, "_COMPONENT_MOMENTS", {})
    beta = math.radians(5.0)
    alphas = cap_tables.alpha_nodes(beta)
    geometry_key = estimates._CAP_SOURCE + np.array([beta, 0.9]).tobytes() + alphas.tobytes()
    mu = 0.5 * (1.0 + math.cos(beta))

    def caps():
        return cap_tables.cap_geometry(beta, mu, alphas), cap_tables.cap_geometry(beta, mu, alphas)

    built = estimates.emission_moments(0.55, caps, geometry_key)
    assert built.shape == (4, len(alphas)) and np.all(np.isfinite(built))
    assert len(list(tmp_path.glob("emission-*.npy"))) == 1
    monkeypatch.setattr(estimates, "_COMPONENT_MOMENTS", {})   # as in a new process

    def no_geometry():
        raise AssertionError("the caps' geometry was built again")

    assert np.array_equal(estimates.emission_moments(0.55, no_geometry, geometry_key), built)
    # another phase function is another table
    assert not np.array_equal(estimates.emission_moments(0.0, caps, geometry_key), built)
