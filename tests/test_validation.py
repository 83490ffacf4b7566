"""The validation suite: the quick run passes and writes a well-formed report, and deliberately
broken physics (Schlick's approximation instead of the exact Fresnel formula) makes the Fresnel
and optical-manhole cases fail."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import oceanmc.validation as v
from oceanmc.validation import references as ref
from oceanmc.validation.stats import JK, z_tolerance

RECORD_KEYS = {"case", "quantity", "value", "stderr", "reference", "z", "tolerance", "pass"}


def _check_records(records, cases):
    assert isinstance(records, list) and records
    for r in records:
        assert RECORD_KEYS <= set(r), r
        assert r["case"] in cases
        assert isinstance(r["quantity"], str) and r["quantity"]
        assert isinstance(r["pass"], bool)
        for key in ("value", "stderr", "reference", "z", "tolerance"):
            assert r[key] is None or (isinstance(r[key], (int, float)) and math.isfinite(r[key]))
        if r["kind"] in ("z", "chi2") and r["pass"]:
            assert r["z"] is not None and r["tolerance"] >= 4.0
            if r["kind"] == "z":
                assert abs(r["z"]) <= r["tolerance"]


# cases whose quick run another test makes and asserts passing (with more of its checks):
# test_case_bounds_are_bonferroni_over_the_case, tests/test_validation_brdf_models.py
RUN_ON_THEIR_OWN = {"chandrasekhar", "brdf_models"}


@pytest.mark.long(cpu_s=270)
def test_quick_validation_passes(tmp_path, capsys):
    names = {c.name for c in v.CASES} - RUN_ON_THEIR_OWN
    status = v.main(tmp_path, quick=True, cases=[c.name for c in v.CASES if c.name in names])
    out = capsys.readouterr().out
    records = json.loads((tmp_path / "results.json").read_text())
    _check_records(records, names)
    failing = [r for r in records if not r["pass"]]
    assert status == 0, failing[:10]
    assert {r["case"] for r in records} == names
    for name in names:   # one stdout line per case
        assert any(line.startswith(name) and "PASS" in line for line in out.splitlines())
    report = (tmp_path / "report.md").read_text()
    assert "Overall: PASS" in report
    figures = sorted((tmp_path / "figures").glob("*.png"))
    assert len(figures) >= len(names)
    for fig in figures:
        assert f"figures/{fig.name}" in report
        assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


SCHLICK = {"surface": {"fresnel": "schlick"}}


@pytest.mark.parametrize("case", ["fresnel", "optical_manhole"])
def test_schlick_fresnel_makes_the_surface_cases_fail(case):
    outcome = v.run_case(case, quick=True, override=SCHLICK)
    assert outcome.error is None, outcome.error
    failing = [c for c in outcome.ctx.checks if not c.passed]
    # the Monte Carlo checks fail, not the references' own checks
    assert any(not c.quantity.startswith("reference:") for c in failing)
    assert all(not c.quantity.startswith("reference:") for c in failing)
    assert not outcome.passed


def test_override_through_the_environment(tmp_path, monkeypatch):
    monkeypatch.setenv(v.ENV_OVERRIDE, json.dumps(SCHLICK))
    monkeypatch.setenv(v.ENV_CASES, "fresnel")
    assert v.main(tmp_path, quick=True) == 1
    records = json.loads((tmp_path / "results.json").read_text())
    _check_records(records, {"fresnel"})
    assert any(not r["pass"] for r in records)
    assert "override" in (tmp_path / "report.md").read_text()


def test_references_reproduce_the_design_numbers():
    n = 1.34
    assert ref.fresnel(1.0, n, 1.0) == pytest.approx(0.02111, abs=5e-6)
    assert ref.sky_reflectance(n, "uniform") == pytest.approx(0.0675, abs=5e-5)
    assert ref.sky_reflectance(n, "cardioidal") == pytest.approx(0.0522, abs=5e-5)
    assert ref.uniform_upwelling_reflectance(n) == pytest.approx(0.4807, abs=5e-5)
    assert ref.critical_angle_deg(n) == pytest.approx(48.27, abs=5e-3)
    assert ref.chandrasekhar_albedo(0.8, 0.5) == pytest.approx(0.36797, abs=5e-6)
    assert ref.chandrasekhar_radiance(0.8, 0.5, 1.0) == pytest.approx(0.09586, abs=5e-6)


def test_jackknife_matches_the_batch_standard_error():
    rng = np.random.default_rng(1)
    x = rng.normal(size=(40, 3))
    est = JK.from_batches(x)
    assert np.allclose(est.value, x.mean(axis=0))
    assert np.allclose(est.stderr, x.std(axis=0, ddof=1) / math.sqrt(40))
    ratio = est[0] / est[1]
    assert ratio.value == pytest.approx(x[:, 0].mean() / x[:, 1].mean())
    assert z_tolerance(1, 64) == 4.0 and z_tolerance(400, 64) > 4.0


def test_group_summaries_hold_their_false_alarm_rate():
    """chi2_z and hotelling_z of groups of Student-t z (32 batches, normal batch values) exceed
    the normal quantile of p with probability close to p; the standardised sum of z^2 they
    replace exceeded 4 (p = 3e-5 for a normal z) about 50 times too often for 8 members."""
    from scipy import stats as st
    from oceanmc.validation.stats import chi2_z, hotelling_z
    rng = np.random.default_rng(7)
    n_batches, trials, p = 32, 4000, 0.01
    bound = st.norm.isf(p)
    for members in (3, 8, 54):
        x = rng.normal(size=(trials, n_batches, members))
        z = x.mean(axis=1) / (x.std(axis=1, ddof=1) / math.sqrt(n_batches))
        rate = np.mean([chi2_z(zz, n_batches) > bound for zz in z])
        assert abs(rate - p) < 4 * math.sqrt(p / trials), (members, rate)
    hz = [hotelling_z(b.mean(axis=0), JK.from_batches(b).loo) for b in x[:2000, :, :8]]
    rate = np.mean(np.array(hz) > bound)
    assert abs(rate - p) < 4 * math.sqrt(p / 2000), rate


def test_hotelling_of_proportional_estimates_has_their_rank():
    """Eight estimates that are fixed multiples of one (local estimates of an isotropic radiance
    in eight directions score the same events) are one test with one degree of freedom: their
    Hotelling z equals that of the single estimate, whatever the rounding of the copies."""
    from scipy import stats as st
    from oceanmc.validation.stats import hotelling_z
    rng = np.random.default_rng(3)
    x = 1.0 + 0.1 * rng.normal(size=32)
    scale = np.linspace(1.0, 2.0, 8)
    est = JK.from_batches(x[:, None] * scale[None, :])
    one = JK.from_batches(x)
    diff = est.value - 0.99 * scale
    z1 = float((one.value - 0.99) / one.stderr)
    expected = st.norm.isf(st.f.sf(z1 * z1, 1, 31))
    assert hotelling_z(diff, est.loo, ref_error=1e-9 * scale) == pytest.approx(expected, rel=1e-6)
    assert hotelling_z(diff, est.loo) == pytest.approx(expected, rel=1e-6)


def test_hotelling_leaves_out_directions_of_negligible_variance():
    """Six members that are one shape up to a fine structure holding about 1e-7 of the variance
    (stats.RANK_RTOL 1e-5) are one test, as exact multiples are; a contrast between them holding
    about 1e-3 of it is kept, and a bias of 8 of its standard errors along it is found although
    it moves no member's own z by more than 0.3."""
    from scipy import stats as st
    from oceanmc.validation.stats import hotelling_z
    rng = np.random.default_rng(5)
    x = 1.0 + 0.1 * rng.normal(size=32)
    scale = np.linspace(1.0, 2.0, 6)
    one = JK.from_batches(x)
    z1 = float((one.value - 0.99) / one.stderr)
    expected = st.norm.isf(st.f.sf(z1 * z1, 1, 31))
    fine = JK.from_batches(x[:, None] * scale + 0.1 * 3e-4 * rng.normal(size=(32, 6)))
    lam = np.linalg.eigvalsh(np.corrcoef(fine.loo.T))
    assert 1e-9 < lam[-2] / lam[-1] < 1e-6
    assert hotelling_z(fine.value - 0.99 * scale, fine.loo) == pytest.approx(expected, rel=1e-3)
    # a contrast orthogonal to the shape (each member's deviation from the mean, less its
    # projection on the shape)
    contrast = scale - scale.mean()
    contrast -= (contrast @ scale) / (scale @ scale) * scale
    contrast /= np.linalg.norm(contrast)
    y = rng.normal(size=32)
    kept = JK.from_batches(x[:, None] * scale + 0.1 * 0.05 * y[:, None] * contrast)
    lam = np.linalg.eigvalsh(np.corrcoef(kept.loo.T))
    assert 1e-4 < lam[-2] / lam[-1] < 1e-2
    along = kept.apply(lambda v: v @ contrast)
    diff = kept.value - 0.99 * scale + 8.0 * float(along.stderr) * contrast
    assert np.max(np.abs(8.0 * float(along.stderr) * contrast / kept.stderr)) < 0.3
    assert hotelling_z(diff, kept.loo) > 4.0


def test_case_bounds_are_bonferroni_over_the_case():
    """After run_case, the bounds of a case's checks split the family-wise false alarm
    FAMILY_ALPHA over all its statistical checks: the members of groups get t quantiles for
    their count, the single quantities and summaries theirs."""
    from scipy import stats as st
    from oceanmc.validation.stats import FAMILY_ALPHA
    outcome = v.run_case("chandrasekhar", quick=True)
    stat = [c for c in outcome.ctx.checks if c.kind in ("z", "chi2")]
    members = [c for c in stat if c.kind == "z" and c.group]
    heads = [c for c in stat if c not in members]
    assert members and heads
    share = FAMILY_ALPHA / 2
    for c in members:
        assert c.tolerance == pytest.approx(max(4.0, st.t.isf(share / 2 / len(members),
                                                              c.n_batches - 1)))
    for c in heads:
        assert c.tolerance == pytest.approx(max(4.0, st.t.isf(share / 2 / len(heads), c.n_batches
                                                              - 1) if c.kind == "z"
                                                else st.norm.isf(share / len(heads))))
    assert outcome.passed, [c.quantity for c in stat if not c.passed][:5]


@pytest.mark.parametrize("factor", [1.05, 0.95])
def test_a_five_percent_error_in_a_reference_fails_its_case(monkeypatch, factor):
    """The wider per-check bounds keep their power: Chandrasekhar's reflected radiance off by
    5% fails the case (the quads' and bands' summaries and the local estimates)."""
    true_radiance = ref.chandrasekhar_radiance
    monkeypatch.setattr(ref, "chandrasekhar_radiance",
                        lambda *a, **k: factor * true_radiance(*a, **k))
    outcome = v.run_case("chandrasekhar", quick=True)
    failing = [c for c in outcome.ctx.checks if not c.passed]
    assert not outcome.passed
    assert any("quad reflected radiance [" in c.quantity for c in failing)
    assert any("exact directions" in c.quantity for c in failing)
