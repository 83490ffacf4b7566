import copy
import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

SMALL_SCENE = {
    "name": "small test scene",
    "photons": 20000,
    "batches": 8,
    "seed": 5,
    "illumination": {"Ed0": 1.0, "sun_zenith_deg": 30, "diffuse_fraction": 0.2},
    "surface": {"model": "flat", "n_water": 1.34},
    "water": {"layers": [{"thickness_m": 2.0, "a": 0.1, "b": 0.4,
                          "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
    "bottom": {"model": "lambertian", "reflectance": 0.3},
    "tallies": {"depths_m": [0, 1, 2]},
}


@pytest.fixture
def small_scene():
    """A fresh deep copy of a fast scene (a mutable dict each test may change)."""
    return copy.deepcopy(SMALL_SCENE)


@pytest.fixture
def thread_client():
    """A Dask client of one in-process worker with two threads (so that a test's monkeypatch
    reaches the points it runs), its scheduler's HTTP routes on a free port of 127.0.0.1 as
    sweeps.execute.local_client's are: left on 8787, two such tests at once in parallel
    processes warned 'Port 8787 is already in use'."""
    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                      dashboard_address=None,
                      scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}) as cluster, \
            Client(cluster) as client:
        yield client


@pytest.fixture(scope="session", autouse=True)
def whole_photon_loop():
    """The photon loop with every optional part compiled in (kernel/variants.py), made ready
    once per session: every scene of the tests then runs on it, in this process and, through
    the disk cache, in the processes the tests start (a scene runs on any variant that holds
    its parts, with the same results bit for bit), instead of each set of parts compiling a
    variant of its own. tests/test_variants.py runs scenes on their own variants."""
    from oceanmc.run.compiling import ready
    ready()


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    """`make test` runs the tests in parallel processes (pytest-xdist, -n auto): one per core
    this process may use, at most 8 (each holds its own compiled photon loop)."""
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return max(1, min(usable or 1, 8))


def pytest_collection_modifyitems(config, items):
    """Tests marked `long` (tens of seconds to minutes each) start first, dealt out among the
    parallel workers: `make test` runs `pytest -n auto --dist worksteal`, which gives worker k
    the k-th of as many contiguous parts of the collection as there are workers and later
    moves tests still queued from the end of a busy worker's part to an idle one. A long test
    at the end of the collection (the quick validation, in test_validation.py) kept one worker
    busy for minutes while the other had finished (72 s idle in a run on 2 cores); dealt out
    at the fronts of the parts, the long tests run beside the short ones. The order of the
    other tests is kept; every worker computes the same order, as xdist requires."""
    count = int(getattr(config, "workerinput", {}).get("workercount", 1))
    # the longest first (cpu_s: the CPU seconds a test took on 2 cores, 2026-11-28)
    long = sorted((item for item in items if item.get_closest_marker("long")),
                  key=lambda item: -item.get_closest_marker("long").kwargs["cpu_s"])
    rest = [item for item in items if not item.get_closest_marker("long")]
    ordered, left = [], len(items)
    for k in range(count):   # the sizes of worksteal's first parts
        size = left // (count - k)
        part = long[k::count]
        fill = max(0, size - len(part))
        ordered += part + rest[:fill]
        del rest[:fill]
        left -= size
    items[:] = ordered + rest


def pytest_configure(config):
    """With parallel workers (pytest-xdist), the controlling process compiles the whole photon
    loop into the disk cache before it starts them, so that each worker loads it (about a
    second) instead of all compiling it at once."""
    if not hasattr(config, "workerinput") and config.getoption("numprocesses", default=None):
        from oceanmc.run.compiling import ready
        ready()
