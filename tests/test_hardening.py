"""Hardening (issue 13): malformed or extreme input gets one clear line and exit 2, never a
wrong answer, a lost run or someone else's files deleted."""
import os
import subprocess
import sys

import pytest

from conftest import REPO

ENV = dict(os.environ, PYTHONPATH=str(REPO))


def test_cache_dir_keeps_folders_oceanmc_did_not_create(tmp_path):
    users = tmp_path / "numba-mine"
    users.mkdir()
    (users / "data.bin").write_bytes(b"x")
    ours = tmp_path / "numba-0000000000000000"
    ours.mkdir()
    (ours / ".oceanmc-kernel-cache").touch()
    env = dict(ENV, OCEANMC_CACHE_DIR=str(tmp_path))
    subprocess.run([sys.executable, "-c", "import oceanmc.kernel.compile"], env=env, check=True,
                   timeout=120)
    assert (users / "data.bin").is_file()
    assert not ours.exists()
    current = [p for p in tmp_path.glob("numba-*") if p != users]
    assert len(current) == 1 and (current[0] / ".oceanmc-kernel-cache").is_file()
