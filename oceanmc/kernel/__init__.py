"""The compiled world: @njit functions over plain arrays, integer model ids and floats only.

Nothing here imports the Python side (config, results); scene.py packs a SceneArrays for it.
Everything is importable and testable with NUMBA_DISABLE_JIT=1.

Every function is compiled with error_model="numpy": a float division by zero gives inf or nan
instead of raising, which removes a branch from every division in the photon loop (the kernel
guards its divisions itself; measured +25% photons/s).

Numba's on-disk cache checks only the source file of each cached function, not the files of the
functions it calls, so an edit to (say) tally.py would leave transport's cached machine code
stale. The cache therefore lives in a folder named after a hash of every kernel source file:
any kernel edit starts a fresh cache. Numba reads CACHE_DIR when a function is decorated, so it
is set only while the kernel modules load and restored afterwards.
"""
import hashlib
import os
import shutil
from pathlib import Path

import numba


def _kernel_hash() -> str:
    digest = hashlib.sha256(numba.__version__.encode())
    root = Path(__file__).parent
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


# OCEANMC_CACHE_DIR moves the cache (the benchmark uses an empty one to time a cold start)
CACHE_DIR = Path(os.environ.get("OCEANMC_CACHE_DIR") or Path(__file__).parent / "__pycache__") \
    / f"numba-{_kernel_hash()}"
for _stale in CACHE_DIR.parent.glob("numba-*"):
    if _stale != CACHE_DIR:
        shutil.rmtree(_stale, ignore_errors=True)  # caches of earlier kernel sources

_previous = numba.config.CACHE_DIR
numba.config.CACHE_DIR = str(CACHE_DIR)
try:
    from . import transport  # noqa: E402,F401  (imports every kernel module)
    from .brdf import dispatch as _brdf  # noqa: E402,F401
    from .phase import dispatch as _phase  # noqa: E402,F401
finally:
    numba.config.CACHE_DIR = _previous
