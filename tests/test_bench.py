"""`oceanmc bench --quick` runs end to end and writes its report (numbers are meaningless at
these counts; the real run is committed in benchmarks/)."""
import json
import subprocess
import sys

import numpy as np
import pytest

from conftest import REPO


@pytest.mark.long(cpu_s=133)
def test_quick_bench_writes_report(tmp_path):
    bare_walk = REPO.parent / "shared" / "bench" / "bare_walk.py"
    args = [sys.executable, "-m", "oceanmc", "bench", "--quick", "-o", str(tmp_path / "b"),
            "--configs", str(REPO / "configs")]
    if bare_walk.is_file():
        args += ["--bare-walk", str(bare_walk)]
    # ~10 loop specialisations to compile on an empty cache, ~70 s each on 2 cores, and one
    # more for the cold start
    done = subprocess.run(args, capture_output=True, text=True, timeout=1800, cwd=REPO)
    assert done.returncode == 0, done.stderr[-3000:]
    data = json.loads((tmp_path / "b" / "bench.json").read_text())
    assert data["speed_ceiling"]["oceanmc_1t"] > 0
    assert {row["variant"] for row in data["features"]} >= {"no tallies at all",
                                                            "+ local nadir-cap estimate"}
    scenes = {curve["scene"] for curve in data["error_vs_time"]}
    assert scenes == {"bare walk", "clear ocean", "clear ocean, crossing estimator only",
                      "clear ocean, roulette at weight 1e-12",
                      "clear ocean, upward-biased scattering (fraction 0.1)",
                      "shallow sand", "shallow sand, upward-biased scattering (fraction 0.1)",
                      "Snell's window", "clear ocean (flat surface, exact nadir)",
                      "clear ocean (rough sea 5 m/s, exact nadir)",
                      "sky map with a small bright spot (importance sampling)",
                      "sky map with a small bright spot (cosine sampling)",
                      "sky map with a small bright spot (cosine sampling, split_weight 2)"}
    assert any(key.endswith("against a crossing-only run") for key in data["fom_ratios"])
    assert len(data["roulette_ratios"]) == 3
    # 5 + 3 quantities biased over plain, and Rrs and Lu(10 m) over the crossing-only run
    assert len(data["upward_ratios"]) == 10
    spot = {row["quantity"]: row for row in data["sky_sampling"]}
    assert len(spot) == 5 and "Ed(0-)" in spot
    assert all(row["ratio"] > 0 and row["ratio_split"] > 0 for row in spot.values())
    snell = next(c for c in data["error_vs_time"] if c["scene"] == "Snell's window")
    assert snell["reference"] == "analytic"
    assert all(abs(row["z"]) < 5 for row in snell["rows"]), snell["rows"]
    # --quick: one scene from an empty cache, all four again with a cache, --help, the CLI run
    rows = data["startup"]["rows"]
    assert [(r["row"], r["scene"]) for r in rows if r["row"].startswith("cold")] == [
        ("cold start (empty cache)", "bare_walk.yaml")]
    assert len([r for r in rows if r["row"] == "cached start"]) == 4
    assert [r["row"] for r in rows[-2:]] == [
        "`oceanmc --help`, median of 5",
        "`oceanmc run default.yaml --photons 20000`, cached, median of 3"]
    assert all(r["process_s"] > 0 and isinstance(r["pass"], bool) for r in rows)
    assert all(r["startup_time_s"] >= 0 for r in rows if "start" in r["row"])
    assert (tmp_path / "b" / "error_vs_time.png").stat().st_size > 10_000
    report = (tmp_path / "b" / "bench.md").read_text()
    assert "Speed ceiling" in report and "importance / cosine" in report
    assert "| cold start (empty cache) | bare_walk.yaml |" in report
    assert "| kernel <= 1 s |" in report and "| process <= 0.5 s |" in report


def test_upward_bias_gains_quoted_are_the_committed_bench():
    """configs/clear_ocean.yaml and the README quote the FOM gains of benchmarks/bench.md."""
    import re
    bench = (REPO / "benchmarks" / "bench.md").read_text()

    def gain(line, form):
        return format(float(re.search(re.escape(line) + r": ([0-9.]+)x", bench).group(1)),
                      form) + "x"
    with_local = gain("clear ocean, Rrs nadir: local estimate with upward-biased scattering over "
                      "a crossing-only run", ".0f")
    bias_alone = gain("clear ocean, Rrs nadir (local), biased over plain", ".0f")
    local_alone = gain("clear ocean, Rrs nadir, against a crossing-only run", "g")
    config = (REPO / "configs" / "clear_ocean.yaml").read_text()
    readme = " ".join((REPO / "README.md").read_text().split())
    assert f"FOM {bias_alone} that of" in config and f"{with_local} that of" in config
    assert f"{local_alone} with the local estimate alone, {with_local} with the bias" in readme
    assert f"the bias alone, same estimator: {bias_alone}" in readme


def test_surface_section_reports_rough_over_flat_ratios():
    """The rough-sea section's tables: speed and FOM ratios are each surface's over the flat
    one's, and the table's speed over the walk's (a swapped or inverted ratio fails)."""
    from oceanmc.bench import surface

    def fom_row(seconds, value, fom):
        return {"seconds": seconds, "quantities": {"Rrs": {"value": value, "fom": fom}}}
    data = {"photons": 10, "repeats": 1, "fom_photons": 10,
            "speed": {"flat": {"photons_per_s_1t": 4.0e6},
                      "rough, walk": {"photons_per_s_1t": 0.5e6},
                      "rough, table": {"photons_per_s_1t": 3.0e6}},
            "table_build": {"miss_s": 1.25, "hit_s": 0.002, "load_average": 2.0},
            "fom": {"flat": fom_row(1.0, 0.006, 100.0), "rough, walk": fom_row(5.0, 0.0065, 20.0),
                    "rough, table": fom_row(2.0, 0.0065, 60.0)}}
    text = "\n".join(surface.report_lines(data))
    assert "| rough, walk | 500,000 | 0.12 |" in text
    assert "| rough, table | 3,000,000 | 0.75 |" in text
    assert "6.0x as fast as the walk" in text
    assert "cache miss: 1.25 s" in text and "hit: 2.0 ms" in text
    assert "| Rrs | 0.00600 | 0.00650 | 0.00650 | 100 | 20 | 60 | 0.20 | 0.60 |" in text


def test_spectral_section_splits_the_worst_band_into_time_and_variance():
    """The spectral section's table: the worst band (lowest FOM ratio), and its FOM ratio as the
    time ratio per photon (31 runs' seconds over one run's photons, against the one history's
    seconds per photon) times the variance ratio; the target is met only if the worst band
    meets it; the ceiling: the events ratio (31 runs' events per photon over the one
    history's) times the same variance ratio."""
    from oceanmc.bench import spectral

    bands = {"fom_ratio": [12.0, 1.5, 20.0]}   # the worst band below the target 2
    data = {"spectral_photons": 1000, "single_photons": 500, "threads": 2, "scenes": [
        {"name": "scene A", "wavelengths": [400.0, 410.0, 420.0], "time_one_history_s": 2.0,
         "time_31_runs_s": 4.0, "events_one_history": 10.0, "events_31_runs": 80.0,
         "air/Rrs_nadir": bands,
         "budget/water_leaving": {"fom_ratio": [11.0, 15.0, 10.0],
                                  "fom_ratio_uniform_heroes": [3.0, 1.25, 9.0]}}]}
    text = "\n".join(spectral.report_lines(data))
    # time ratio (4 / 500) / (2 / 1000) = 4; worst band 410 nm, 1.5 = 4 x 0.375
    # events ratio 80 / 10 = 8: ceiling 8 x 0.375 = 3
    assert "| scene A | 2.0 | 4.0 | Rrs nadir | 1.5 (410 nm) | 4.0 x 0.38 | 12.0 | 20.0 | **no** " \
        "| - | 10.0 / 80 | 8.0 x 0.38 = 3.0 |" in text   # no uniform-hero run in this report
    assert "crossing" not in text.split("|---")[-1]   # a quantity the run did not measure
    # with uniform heroes the worst band is another (410 nm)
    assert "| water-leaving fraction | 10.0 (420 nm) | 4.0 x 2.50 | 11.0 | 15.0 | yes | " \
        "1.2 (410 nm) | 10.0 / 80 | 8.0 x 2.50 = 20.0 |" in text


def test_spectral_section_pools_rounds():
    """Rounds of the spectral section: each band's relative error is the root of the rounds'
    mean square (the mean of their variances), and the report says how many rounds and how
    uncertain each band's FOM ratio then is (sqrt(4 / (rounds (batches - 1))): 18% for one
    round of 128 batches, 10% for three)."""
    from oceanmc.bench import spectral

    assert spectral.pooled([[0.01, 0.03], [0.02, 0.04], [0.02, 0.00]]) == pytest.approx(
        [0.01732051, 0.02886751])
    assert spectral.ratio_uncertainty(1) == pytest.approx(0.1775, abs=1e-4)
    assert spectral.ratio_uncertainty(3) == pytest.approx(0.1025, abs=1e-4)
    data = {"spectral_photons": 1000, "single_photons": 500, "threads": 2, "rounds": 3,
            "scenes": []}
    text = "\n".join(spectral.report_lines(data))
    assert "128 batches each, 3 rounds of both, interleaved" in text
    assert "uncertain by about 10% per band" in text and "3 x 128 batches" in text


def test_speed_section_alone_writes_speed_report(tmp_path, monkeypatch, capsys):
    """`oceanmc bench --speed`: the speed ceiling, feature costs and start-up rows alone, in
    DIR/speed.md (what a change to the kernel reports), without the long error-vs-time runs.
    In this process, the start-up rows from a stand-in: test_quick_bench_writes_report times
    the real ones (a cold compilation, 25-40 s of both cores, which this test ran again)."""
    from oceanmc import bench, cli
    from oceanmc.bench.measure import target_row

    def startup_stand_in(configs_dir, quick, say):
        say("start-up ...")
        return {"photons": 20000, "rows": [
            target_row("cold start (empty cache)", "bare_walk.yaml", 99.0, 98.0, "process_s",
                       15.0, parts="plain"),
            target_row("cached start", "bare_walk.yaml", 1.5, 0.5, "startup_time_s", 1.0)]}

    monkeypatch.setattr(bench, "_startup", startup_stand_in)
    bare_walk = REPO.parent / "shared" / "bench" / "bare_walk.py"
    args = ["bench", "--speed", "--quick", "-o", str(tmp_path / "s"), "--configs",
            str(REPO / "configs")]
    if bare_walk.is_file():
        args += ["--bare-walk", str(bare_walk)]
    assert cli.main(args) == 0
    assert "wrote" in capsys.readouterr().out
    data = json.loads((tmp_path / "s" / "speed.json").read_text())
    assert set(data) >= {"speed_ceiling", "features", "startup"}
    assert "error_vs_time" not in data and "spectral" not in data
    assert "Petzold phase function (tabulated)" in {row["variant"] for row in data["features"]}
    report = (tmp_path / "s" / "speed.md").read_text()
    assert "## Speed ceiling" in report and "## Start-up" in report
    assert "| cold start (empty cache) | bare_walk.yaml | plain | 99.00 | 98.00 |" in report
    assert "FAIL" in report and "Error against run time" not in report
    # a quick report says so, and how to make it again (it read as a measurement)
    assert "**Mode: quick**" in report and "`oceanmc bench --speed --quick -o DIR`" in report
    assert not (tmp_path / "s" / "bench.md").exists()


def test_deep_section_reports_gains_and_the_target():
    """The deep-light section's table: the gain is the time to 1% without windows over the
    time with; the target is met only if every quantity at every depth down to 10 attenuation
    depths (and the first level below) reaches 1% within 60 s; a level no light reached shows
    '-'."""
    from oceanmc.bench import deep

    def times(ed, eou, lu):
        return {"photons_per_s": 1000.0, "events_per_photon": 10.0, "depth_splitting": "on",
                "Ed": ed, "Eou": eou, "Lu": lu, "time_s": 1.0}
    variant = {"variant": "v", "estimator": {}, "attenuation_depths": [0.0, 9.0, 10.5, 12.0],
               "off": times([1.0, 50.0, 900.0, float("inf")], [2.0, 60.0, 100.0, 1.0],
                            [1.0, 1.0, 1.0, 1.0]),
               "auto": times([2.0, 5.0, 9.0, 70.0], [4.0, 30.0, 59.0, 99.0],
                             [1.0, 1.0, 1.0, 1.0])}
    spread = {"seeds": 12, "photons": 10, "ratio_one_depth_sd": 0.21, **{
        q: {"rms_z": 1.0, "max_abs_z": 2.0, "ratio_median": 1.0, "ratio_min": 0.8,
            "ratio_max": 1.2} for q in ("Ed", "Eou", "Lu")}}
    data = {"photons": 10, "repeats": 1, "depths_m": [0.0, 50.0, 100.0, 120.0],
            "beam_optical_depths": [0.0, 30.0, 60.0, 80.0], "variants": [variant],
            "auto_rule": [], "shipped": None, "spread": spread}
    text = "\n".join(deep.report_lines(data, "abc1234"))
    assert "| 100 | 10.50 | 60.0 | 900.0 | 9.0 | 100.00x | 100.0 | 59.0 | 1.69x |" in text
    assert "| 120 | 12.00 | 80.0 | - | 70.0 | - |" in text
    assert "without windows: **not met**; the worst is Ed at 100 m, 900 s." in text
    # 120 m lies past the first level at or below 10 attenuation depths: not counted
    assert "with windows: **met**; the worst is Eou at 100 m, 59 s." in text
    assert "Kernel commit abc1234." in text


def test_inelastic_section_combines_the_repeats(monkeypatch):
    """Each row of the inelastic section (`oceanmc bench --inelastic`): the value is the mean
    over the repeats and the relative error the root of their mean square (it was the first
    repeat's alone), the time to 1% the median time times (rel / 1%)^2."""
    from oceanmc.bench import inelastic

    calls = []

    def run(config):
        calls.append(config)
        k = len(calls)   # 1, 2, 3 ... in the order the runs are made
        return 2.0 * k, {"Rrs(550)": (0.001 * k, 0.01 * k)}

    monkeypatch.setattr(inelastic, "_run", run)
    monkeypatch.setattr(inelastic, "simulate", lambda *args, **kwargs: None)
    monkeypatch.setattr(inelastic, "spread", lambda quick, say: [])
    monkeypatch.setattr(inelastic, "RUNS", inelastic.RUNS[:2])
    data = inelastic.measure(quick=False, say=lambda text: None)
    assert data["repeats"] == 5 and len(calls) == 10
    for index, run_data in enumerate(data["runs"]):
        ks = np.arange(index + 1, 11, 2)   # the run's repeats, interleaved (1, 3, .. or 2, 4, ..)
        row = run_data["rows"]["Rrs(550)"]
        assert row["value"] == pytest.approx(0.001 * ks.mean())
        assert row["rel"] == pytest.approx(0.01 * np.sqrt(np.mean(ks ** 2)))
        t = float(np.median(2.0 * ks))
        assert run_data["time_s"] == pytest.approx(t)
        assert row["time_to_target_s"] == pytest.approx(t * (row["rel"] / 0.01) ** 2)
