"""The compiled kernel, ready to run: its entry points compiled, or loaded from the disk cache.

Every scene has the same argument types (records of fixed dtypes, flat pools), so each entry
point has one signature, known before any scene is packed, and is compiled once per kernel
version and machine. ready() compiles them in a helper thread (LLVM releases the GIL) so that
the main thread can say what is happening every few seconds on stderr and stop at once on
Ctrl-C (KeyboardInterrupt) or when should_stop() says so (CompileInterrupted)."""
from __future__ import annotations

import sys
import threading
import time
from typing import Callable

import numba
import numpy as np
from numba.core.config import _OptLevel

from ..kernel import records
from ..kernel.compile import CACHE_DIR
from ..kernel.phase.dispatch import layer_density
from ..kernel.surface.dispatch import transmittance
from ..kernel.transport import trace_batch

COMPILE_NOTICE_AFTER_S = 1.0
# LLVM's optimisation level for the kernel's IR (machine code is still generated at Numba's
# default level): level 1 keeps the inlining of the event functions and compiles the loop in
# about 0.75 of the time of level 3 with as many photons/s (benchmarks/bench.md)
KERNEL_OPT_LEVEL = 1


class CompileInterrupted(Exception):
    """The user asked to stop while the kernel was compiling; nothing was traced."""


def _types(*dtypes_or_arrays) -> tuple:
    return tuple(numba.typeof(x) for x in dtypes_or_arrays)


def signatures() -> list[tuple]:
    """(dispatcher, argument types) of each entry point."""
    def row(dtype):
        return np.zeros(1, dtype=dtype)
    f, i = np.zeros(1), np.zeros(1, dtype=np.int64)
    trace = _types(row(records.MEDIUM), f, i, row(records.SURFACE), row(records.BOTTOM), f,
                   row(records.SKY), f, row(records.GRID), f, i, row(records.ESTIMATES), f, i,
                   row(records.ESTIMATOR), 1, np.int64(1), f, row(records.PACKET),
                   row(records.PACKET))
    density = _types(row(records.MEDIUM)[0], f, i, 1, f)
    surface = _types(row(records.SURFACE)[0], 1.0)
    return [(trace_batch, trace), (layer_density, density), (transmittance, surface)]


def _missing() -> list[tuple]:
    return [(f, sig) for f, sig in signatures() if sig not in f.overloads]


def ready(should_stop: Callable[[], bool] | None = None):
    """trace_batch's compiled entry point (plain trace_batch under NUMBA_DISABLE_JIT=1)."""
    if not hasattr(trace_batch, "overloads"):
        return trace_batch
    missing = _missing()
    if missing:
        failure = []

        def compile_them():
            previous = numba.config.OPT
            numba.config.OPT = _OptLevel(KERNEL_OPT_LEVEL)
            try:
                for dispatcher, sig in missing:
                    dispatcher.compile(sig)
            except BaseException as exc:  # handed to the main thread
                failure.append(exc)
            finally:
                numba.config.OPT = previous

        worker = threading.Thread(target=compile_them, name="oceanmc-compile", daemon=True)
        t0 = time.perf_counter()
        worker.start()
        said = 0.0
        while worker.is_alive():
            worker.join(0.1)
            if should_stop is not None and should_stop():
                raise CompileInterrupted("stopped while compiling the photon loop")
            elapsed = time.perf_counter() - t0
            if worker.is_alive() and elapsed >= COMPILE_NOTICE_AFTER_S and elapsed - said >= 5.0:
                if not said:
                    print(f"oceanmc: compiling the photon loop (once per oceanmc version on this "
                          f"machine; cached in {CACHE_DIR})", file=sys.stderr, flush=True)
                else:
                    print(f"oceanmc: still compiling, {elapsed:.0f} s", file=sys.stderr,
                          flush=True)
                said = elapsed
        if failure:
            raise failure[0]
        if said:
            print(f"oceanmc: photon loop compiled in {time.perf_counter() - t0:.1f} s",
                  file=sys.stderr, flush=True)
    return trace_batch.overloads[signatures()[0][1]].entry_point
