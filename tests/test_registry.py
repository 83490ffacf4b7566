"""Every model the schema accepts is in its kind's registry (oceanmc/registry.py), every
registered model is in the schema, and the kernel's dispatch reaches each registered kernel
module (not a default branch)."""
import importlib
import math
import typing

import numpy as np
import pytest

from oceanmc import config as cfg
from oceanmc import registry
from oceanmc.kernel import models
from oceanmc.kernel.brdf import dispatch as brdf_dispatch
from oceanmc.kernel.phase import henyey_greenstein, isotropic, quadratic
from oceanmc.kernel.surface import dispatch as surface_dispatch
from oceanmc.scene import medium


def schema_models(union) -> set[str]:
    """The `model` names of the members of a discriminated union of the schema."""
    members = typing.get_args(typing.get_args(union)[0])
    return {typing.get_args(m.model_fields["model"].annotation)[0] for m in members}


def test_phase_registry_matches_the_schema_and_the_packer():
    assert schema_models(cfg.Phase) == set(registry.PHASE) == set(medium.COMPONENTS)
    modules = {importlib.import_module(f"oceanmc.kernel.phase.{name}")
               for name in registry.PHASE_KERNEL.values()}
    assert len(modules) == len(registry.PHASE_KERNEL)


def test_bottom_registry_matches_the_schema():
    assert schema_models(cfg.Bottom) == set(registry.BOTTOM)
    for name, (_, module) in registry.BOTTOM.items():
        if module is not None:
            importlib.import_module(f"oceanmc.kernel.brdf.{module}")


def test_surface_registry_matches_the_schema():
    allowed = set(typing.get_args(cfg.Surface.model_fields["model"].annotation))
    assert allowed == set(registry.SURFACE)
    for _, module in registry.SURFACE.values():
        importlib.import_module(f"oceanmc.kernel.surface.{module}")


def test_sky_registry_matches_the_schema():
    named, _ = typing.get_args(cfg.Illumination.model_fields["sky"].annotation)
    names = set(typing.get_args(typing.get_args(named)[0]))   # Annotated[Literal[...], Tag]
    assert names == set(registry.SKY)
    sampling = set(typing.get_args(cfg.SkyMap.model_fields["sampling"].annotation))
    assert sampling == set(registry.SKY_MAP)


@pytest.mark.parametrize("name", sorted(registry.PHASE))
def test_every_phase_model_packs_into_registered_kernel_models(name, tmp_path):
    table = tmp_path / "phase.csv"
    table.write_text("0,10\n90,1\n180,1\n")
    built = {"henyey_greenstein": {"g": 0.5}, "table": {"file": str(table)},
             "mixture": {"components": [{"b": 1.0, "phase": {"model": "isotropic"}}]}}
    phase = cfg.Layer.model_validate({"thickness_m": 1.0, "a": 0.1, "b": 1.0,
                                      "phase": dict(model=name, **built.get(name, {}))}).phase
    kernel_ids = {m for _, m, _, _ in medium.phase_components(phase)}
    expected = set(registry.PHASE[name]) or {models.PHASE_ISOTROPIC}   # the mixture above
    assert kernel_ids == expected


def test_phase_dispatch_reaches_each_kernel_module():
    """The scene's component of each analytic kernel model evaluates as its own module does."""
    import oceanmc
    from oceanmc import scene
    for phase, module, params in ((
            {"model": "isotropic"}, isotropic, (0.0, 0.0)),
            ({"model": "pure_water"}, quadratic, (medium.PURE_WATER_BETA, 0.0)),
            ({"model": "henyey_greenstein", "g": 0.7}, henyey_greenstein, (0.7, 0.0))):
        sc = scene.build(oceanmc.load_config({
            "water": {"layers": [{"thickness_m": 1.0, "a": 0.1, "b": 1.0, "phase": phase}]},
            "bottom": {"model": "black"}}))
        from oceanmc.kernel.phase import dispatch
        for mu in (-0.9, 0.0, 0.3, 0.99):
            assert dispatch.evaluate(sc.medium[0], sc.floats, sc.ints, 0, mu) == pytest.approx(
                module.evaluate(params, mu), rel=1e-14)


def test_brdf_dispatch_reaches_each_reflecting_model():
    """Each registered reflecting BRDF id evaluates to a positive f for a simple parameter set
    (a model id the dispatch does not know falls through to 0)."""
    params = np.zeros(models.BRDF_HEADER)
    params[:3] = (0.5, 0.5, 1.15)   # rho / k / ...: enough for a positive f in each model
    for name, (model_id, module) in registry.BOTTOM.items():
        if module in (None, "specular", "table", "hapke", "ggx"):
            continue   # tables, Hapke and GGX need packed parameters: tests/test_brdf_models.py
        f = brdf_dispatch.evaluate_local(model_id, params, 0.3, 0.0, math.sqrt(0.91),
                                         -0.2, 0.1, math.sqrt(0.95))
        assert f > 0.0, name


def test_surface_dispatch_reaches_each_model():
    """Flat reflects R > 0 of a photon from the air; index-matched reflects nothing and leaves
    the direction unchanged; cox_munk (sampled only) spreads transmitted light over directions."""
    from oceanmc.kernel.rng import batch_state
    from oceanmc.scene import surface as surface_packer
    for name in registry.SURFACE:
        extra = {"wind_speed_m_s": 10.0} if name == "cox_munk" else {}
        surface = surface_packer.pack(cfg.Surface(model=name, **extra), 1.34)[0]
        if name == "cox_munk":
            rng = batch_state(1, 0)
            tz = {round(surface_dispatch.sample(surface, 0.6, 0.0, 0.8, 0.5, rng)[2], 12)
                  for _ in range(20)}
            assert len(tz) > 1
            continue
        r, rx, ry, rz, tx, ty, tz = surface_dispatch.split(surface, 0.6, 0.0, 0.8)
        if name == "flat":
            assert 0.0 < r < 1.0 and tz > 0.8   # refracted toward the normal
        else:
            assert r == 0.0 and (tx, ty, tz) == (0.6, 0.0, 0.8)
        assert surface_dispatch.evaluate(surface, 0.6, 0.0, 0.8, rx, ry, rz) == 0.0
        assert surface_dispatch.pdf(surface, 0.6, 0.0, 0.8, rx, ry, rz) == 0.0




@pytest.mark.long(cpu_s=17)
def test_channel_registry_and_dispatch():
    """Every registered collision channel has its module, its id is packed for the scenes that
    use it, and the dispatch runs it: the elastic channel turns a packet and keeps its weight
    where the bias is off; the inelastic channels take their share of every wavelength and
    emit a packet of their own onto the stack, scored in their part of the tally row."""
    from numba import njit

    import oceanmc
    from oceanmc import scene
    from oceanmc.kernel import records, spectral
    from oceanmc.kernel.channels import dispatch as channels
    from oceanmc.kernel.rng import batch_state

    for _, module in registry.CHANNEL.values():
        importlib.import_module(f"oceanmc.kernel.channels.{module}")

    @njit(cache=False)
    def run(arrays, rng):
        medium, mf, mi, ctrl, grid, packet, ps, work, tally = arrays
        p = packet[0]
        p.w, p.ux, p.uy, p.uz = 1.0, 0.0, 0.0, 1.0
        channels.scatter(medium[0], mf, mi, ctrl[0], grid[0], tally, ps, work, p, 0, False,
                         rng, True)   # (with_spectral: compiled in; kernel/variants.py)
        return p.w, p.uz

    sc = scene.build(oceanmc.load_config({
        "water": {"layers": [{"thickness_m": 1.0, "a": 0.1, "b": 1.0,
                              "phase": {"model": "isotropic"}}]},
        "bottom": {"model": "black"}}))
    assert sc.ints[sc.medium[0]["channel_model"]] == registry.CHANNEL["elastic"][0]
    arrays = (sc.medium, sc.floats, sc.ints, sc.estimator, sc.grid, np.zeros(1, dtype=records.PACKET),
              np.zeros(1), np.zeros(4), np.zeros(sc.tally_size))
    rng = batch_state(3, 0)
    turned = [run(arrays, rng) for _ in range(20)]
    assert all(w == 1.0 for w, _ in turned) and len({uz for _, uz in turned}) == 20

    @njit(cache=False)
    def emit(sc_arrays, ps, stack, stack_ps, work, tally, rng):
        medium, surface, ctrl, grid, est, floats, ints, packet = sc_arrays
        p = packet[0]
        p.w, p.ux, p.uy, p.uz, p.z, p.seg = 1.0, 0.0, 0.0, 1.0, 0.5, 0
        spectral.collision_density(medium[0], floats, grid[0], ps, p, 0,
                                   work[:grid[0].n_wl], work[:0])
        # (with_rough_surface, with_facet_walk, with_local_estimates, with_exact_directions:
        # compiled in; kernel/variants.py)
        return channels.emit(medium[0], surface[0], ctrl[0], grid[0], est[0], floats, ints,
                             tally, work, stack, stack_ps, 0, p, ps, 0, False, rng, True, True,
                             True, True)

    inelastic = {"raman": {"b488_per_m": 0.05}, "chlorophyll_fluorescence": {}}
    sc = scene.build(oceanmc.load_config({
        "wavelengths_nm": {"start": 400, "stop": 700, "step": 10},
        "water": {"layers": [{"thickness_m": 1.0, "components": [
            {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": 5.0}]}],
            "inelastic": inelastic},
        "bottom": {"model": "black"}, "estimator": {"emission_weight": 1e-9}}))
    ids = sc.ints[sc.medium[0]["channel_model"]:][:3]
    assert list(ids) == [registry.CHANNEL[name][0] for name in
                         ("elastic", "raman", "chlorophyll_fluorescence")]
    n = int(sc.grid[0]["n_wl"])
    packet = np.zeros(1, dtype=records.PACKET)
    parts = int(sc.grid[0]["n_parts"])
    ps = np.zeros(records.packet_state_size(n, parts))
    ps[:n] = 1.0               # K
    ps[n:2 * n] = 1.0 / n      # G
    ps[3 * n + 1:4 * n + 1] = 1.0   # all of its light elastic (packet.shares)
    stack = np.zeros(4, dtype=records.PACKET)
    stack_ps = np.zeros((4, records.packet_state_size(n, parts)))
    tally = np.zeros(sc.tally_size)
    height = emit((sc.medium, sc.surface, sc.estimator, sc.grid, sc.estimates, sc.floats,
                   sc.ints, packet), ps, stack, stack_ps, np.zeros(records.work_size(n, parts)), tally,
                  batch_state(3, 1))
    assert height == 2 and list(stack["part"][:2]) == [1, 2]
    size = int(sc.grid[0]["part_size"])
    assert np.count_nonzero(tally[size:2 * size]) and np.count_nonzero(tally[2 * size:])
