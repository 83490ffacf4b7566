"""The brdf_models validation case: its quick run passes with a flux check and radiance groups for
every model, and a slightly absorbing water layer (the bottom then looks about 3% darker) makes
the flux check of every model fail, while the references' own checks still pass."""
from __future__ import annotations

import oceanmc.validation as v

N_MODELS = 8     # GGX rough and glossy, Hapke, Lambertian + mirror, two tables, two general-path
ABSORBING_WATER = {"water": {"layers": [{"thickness_m": 1.0, "a": 0.01, "b": 0.0}]}}


def flux_checks(outcome):
    return [c for c in outcome.ctx.checks if "Eu/Ed" in c.quantity and
            not c.quantity.startswith("reference:")]


def test_quick_brdf_models_passes(tmp_path):
    outcome = v.run_case("brdf_models", quick=True, fig_dir=tmp_path)
    assert outcome.error is None, outcome.error
    failing = [c for c in outcome.ctx.checks if not c.passed]
    assert outcome.passed, failing[:10]
    assert len(flux_checks(outcome)) == N_MODELS
    summaries = [c for c in outcome.ctx.checks
                 if c.kind == "chi2" and "quad radiance" in c.quantity]
    assert len(summaries) == N_MODELS
    assert {file for file, _ in outcome.ctx.figures} == {"brdf_models_f_cos.png",
                                                         "brdf_models_principal_plane.png"}
    for file, _ in outcome.ctx.figures:
        assert (tmp_path / file).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert any(c.quantity.startswith("reference:") for c in outcome.ctx.checks)


def test_absorbing_water_makes_every_flux_check_fail():
    outcome = v.run_case("brdf_models", quick=True, override=ABSORBING_WATER)
    assert outcome.error is None, outcome.error
    fluxes = flux_checks(outcome)
    assert len(fluxes) == N_MODELS
    assert not any(c.passed for c in fluxes), [c.quantity for c in fluxes if c.passed]
    assert all(c.passed for c in outcome.ctx.checks if c.quantity.startswith("reference:"))
    assert not outcome.passed
