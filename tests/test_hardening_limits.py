"""Limits found before any photon: tallies too large for memory; partial files merged and then
resumed."""
import resource

import pytest
import yaml

import oceanmc
from oceanmc.cli import main
from oceanmc.config import ConfigError


def test_an_enormous_tally_is_refused_before_allocation(tmp_path, small_scene, capsys):
    # a small config (about 20 KB) asking for terabytes: 2,000 depths x 1 deg x 1 deg quads
    small_scene["batches"] = 1000
    small_scene["tallies"] = {"depths_m": [round(0.001 * i, 3) for i in range(2000)],
                              "theta_edges_deg": list(range(181)), "phi_bands": 360}
    path = tmp_path / "huge.yaml"
    path.write_text(yaml.safe_dump(small_scene))
    assert path.stat().st_size < 30_000
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    assert main(["run", str(path), "-o", str(tmp_path / "huge.h5")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "GiB" in err and "more than the limit of" in err, err
    assert "tallies.depths_m" in err and not (tmp_path / "huge.h5").exists()
    # nothing near the tallies' size was allocated (ru_maxrss in KiB on Linux)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 500_000
    with pytest.raises(ConfigError, match="GiB"):
        oceanmc.simulate(small_scene)
