"""The compiled kernel, ready to run: its entry points compiled, or loaded from the disk cache.

Every scene has the same argument types (records of fixed dtypes, flat pools), so each entry
point has one signature, known before any scene is packed, and is compiled once per kernel
version and machine. ready() compiles them in a helper thread (LLVM releases the GIL) so that
the main thread can say what is happening every few seconds on stderr and stop at once on
Ctrl-C (KeyboardInterrupt) or when should_stop() says so (CompileInterrupted).

Numba compiles one function at a time, so on a machine with two or more cores the photon loop
is compiled in two processes that meet in the disk cache (parts()): a child process compiles
the local estimates at a collision, the events at the surface and the bottom, the free flight
and trace_batch's other callees, then the functions the loop calls by address
(kernel/outline.py: the inelastic emissions), while this one compiles the collision (its
elastic channel first) and then trace_batch, which loads the child's part from the cache, and
finally loads the functions called by address. If the child fails or is slow, this process
compiles what it lacks: the result is the same.

trace_batch's own compilation is the longest single step and cannot be shared out: Numba links
every callee's optimised LLVM IR into the entry point's module, then optimises it again (7.7 s,
LLVM's pass timings) and generates machine code for all of it (4.8 s), after each callee did
the same for its own. Measured one after the other in one process (2 cores, a CI run beside
it): the collision 13.1 s, the surface events 4.6 s, the bottom 5.0 s, trace_batch 11.7 s. The
collision alone here and the surface events beside the bottom in the child (before: collision
and surface here, 16.3 s, against 8.8 s there) took a cold `oceanmc run configs/default.yaml`
from 27.6-29.7 s (kernel 23.9-25.2 s) to 25.4-28.5 s (kernel 21.9-23.5 s), quiet machine,
interleaved runs. Moving trace_batch's other callees (the free flight, the plane crossings, the
photon's start: 2.6 s of Numba's front end that trace_batch compiled itself) into the child
took a cold compilation (ready(), empty cache, interleaved, 2026-11-27) from 27.5-29.0 s to
25.3-26.4 s; giving the start and the sky's sampling back to this process instead, to balance
the two, did not help (25.5-25.9 s). `oceanmc run` compiles before it packs its scenes
(cli.py), so that the packers' kernel function (component_density, 2-3 s cold) is the child's:
a cold `oceanmc run configs/default.yaml --photons 20000` took 29.5-30.5 s before these two
changes, 26.4-27.9 s after the first and 26.0-27.1 s after both (interleaved, 3 runs each; with
component_density here after the collision, whose phase functions it shares, 26.9-27.7 s).
Now (ready(), empty cache, twice; kernel bcac4d9) the child exits at 12.7-13.1 s, the
collision is compiled at 13.3-13.8 s and trace_batch takes 9.2-9.5 s more: the two halves are
balanced, and what is left is the collision's and trace_batch's own compilation. Kernel
e4782e8's vectorised cap scores, emission bands and carried shares added 4-5 s (one process:
32.3 s against 37.5 s, trace_batch +1.8 s, the cap scores +1.3 s, the collision +0.7 s; ready(),
interleaved: 23.7-24.8 s against 27.5-29.1 s); kernel c484c1c's exp (kernel/exp.py, in five loops)
added 1.2 s in one process (41.8 / 42.1 s against 42.7 / 43.6 s, interleaved), and the same exp
in the exact directions' and the bottom's scores (seven inlined call sites) 5.5 s to ready(),
so those were reverted (commit d8e354b). Calling the inelastic emissions by address
(kernel/outline.py) took ready() from 29.8 / 29.3 s to 23.1 / 25.2 s (empty cache, 2026-11-27,
interleaved; calling the bottom's local estimates and BRDF sampling by address as well:
20.4-20.8 s against 34.1-34.6 s, one process: every part 48.5 -> 34.8 s, trace_batch 18.5 -> 8.5
s, but runs with a bottom or an exact direction 13-20% slower, kernel/outline.py). The local
estimates at a collision are compiled first in the child, so that the collision here finds them
in the cache (with the bottom's parts called by address: 21.7 s without that order). The child
then packs the scenes `oceanmc run` was given (child_main), so that their tables are in the disk
caches when this process packs them: when it packed them while trace_batch compiled, a cold
`oceanmc run CONFIG --photons 20000` (interleaved, twice) took 27.1-27.9 s instead of 30.0-30.2
s for deep_chlorophyll_maximum.yaml, 27.8-28.6 s instead of 30.6-31.7 s for windy_case1.yaml,
with the same results bit for bit; packing them before the functions called by address made no
difference (windy_case1.yaml 26.8 / 27.1 s against 26.2 / 26.4 s, deep_chlorophyll_maximum.yaml
26.0 / 26.8 s against 26.4 / 26.7 s, with the bottom's parts called by address).
(trace_batch at LLVM level 0, its callees at 1: 7.6 s instead of 11.2 s, but its machine code
then keeps dynamic globals, which Numba will not cache: every run would compile again.)
"""
from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Callable, Sequence

import numba
from numba.core.config import _OptLevel

from ..kernel import local_estimate, outline, sources, spectral, transport
from ..kernel.channels import dispatch as channels
from ..kernel.compile import CACHE_DIR
from ..kernel.phase.dispatch import component_density
from ..kernel.surface.dispatch import transmittance
from ..kernel.transport import trace_batch

COMPILE_NOTICE_AFTER_S = 1.0
# LLVM's optimisation level for the kernel's IR (machine code is still generated at Numba's
# default level): level 1 keeps the inlining of the event functions; measured on this 2-core
# machine, one process: 14.7-15.7 s of compilation against 21.3 s at level 3, and as many
# photons/s on the bare-walk scene (4.7M per CPU-second at both, within the noise)
KERNEL_OPT_LEVEL = 1
CHILD_TIMEOUT_S = 600.0


class CompileInterrupted(Exception):
    """The user asked to stop while the kernel was compiling; nothing was traced."""


def parts() -> dict[str, list[tuple]]:
    """(dispatcher, argument types) to compile, in order: `events` (in the child process when
    there is one: the local estimates at a collision, the walk's events but the collision, and
    trace_batch's other callees), `collision` (its elastic channel, then the collision, which
    finds its local estimates in the cache) and `entry` (the entry points, trace_batch first)
    here, and `outlined` (the functions called by address, kernel/outline.py: in the child
    after its events, loaded from the cache here). A function compiled in the child with other
    argument types than its caller here calls it with would only be compiled again here, at no
    other cost (checked once: none is)."""
    types = outline.argument_types()
    return {name: [(f, outline.signature(f, types)) for f in functions] for name, functions in (
        ("events", (local_estimate.at_collision, transport.enter_from_air,
                    transport.leave_or_reflect, transport.reflect_at_bottom,
                    transport.free_flight, transport.cross_plane, transport.after_reflection,
                    transport.split_into, sources.sky_direction, spectral.start,
                    component_density, transmittance)),
        ("collision", (channels.scatter, transport.collide)),
        ("entry", (trace_batch, component_density, transmittance)),
        ("outlined", tuple(f for f, _ in outline.OUTLINED)))}


def compile_part(name: str) -> None:
    """Compiles one part at the kernel's optimisation level (the child process runs this)."""
    previous = numba.config.OPT
    numba.config.OPT = _OptLevel(KERNEL_OPT_LEVEL)
    try:
        for dispatcher, sig in parts()[name]:
            dispatcher.compile(sig)
    finally:
        numba.config.OPT = previous


def _in_cache() -> bool:
    """Whether the disk cache already holds the photon loop's entry point (then loading the
    loop takes 0.3 s)."""
    return any(CACHE_DIR.rglob(f"transport.{trace_batch.__name__}-*.nbi"))


EVENTS_COMPILED = "events compiled"


def child_main(scene_files: list[str]) -> None:
    """The compiling child process: compiles the part `events` into the shared cache, says so
    on stdout, compiles the part `outlined` while the parent compiles trace_batch, then packs
    the scenes of scene_files (their tables, cached on disk, are then the parent's for the
    asking: a profile's or a windy sea's take seconds to build). A scene it cannot pack is left
    to the parent, which reports why."""
    compile_part("events")
    print(EVENTS_COMPILED, flush=True)
    compile_part("outlined")
    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())   # no one reads on
    from ..config import load_config
    from .simulation import prepare
    for path in scene_files:
        try:
            prepare(load_config(path))
        except Exception:  # the parent packs it again and says what is wrong
            pass


def _start_child(scene_files: Sequence[Path]) -> subprocess.Popen | None:
    """The compiling child process (child_main), if this machine has a core to spare for it."""
    if (os.cpu_count() or 1) < 2:
        return None
    code = "import sys; from oceanmc.run.compiling import child_main; child_main(sys.argv[1:])"
    try:
        return subprocess.Popen([sys.executable, "-c", code, *map(str, scene_files)],
                                stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, text=True,
                                env=dict(os.environ, OCEANMC_CACHE_DIR=str(CACHE_DIR.parent)))
    except OSError:
        return None


def _events_compiled(child: subprocess.Popen) -> None:
    """Waits (CHILD_TIMEOUT_S at most) until the child has compiled the part `events`, or has
    ended (then trace_batch compiles what it lacks)."""
    waiter = threading.Thread(target=child.stdout.readline, daemon=True)
    waiter.start()
    waiter.join(CHILD_TIMEOUT_S)


# seconds that ready() spent compiling or loading the photon loop, not yet reported by a run
# (startup_seconds): `oceanmc run` makes the loop ready before it packs its scenes, and its
# first run still reports the time
_unreported_startup = [0.0]


def startup_seconds() -> float:
    """The time ready() spent compiling or loading the photon loop since this was last asked
    (0 once the loop is in this process)."""
    seconds, _unreported_startup[0] = _unreported_startup[0], 0.0
    return seconds


def ready(should_stop: Callable[[], bool] | None = None, scene_files: Sequence[Path] = ()):
    """The photon loop, ready to call with trace_batch's arguments but the last (the table of
    outlined functions' addresses, kernel/outline.py, which it adds): trace_batch's compiled
    entry point (plain trace_batch under NUMBA_DISABLE_JIT=1). On a cold start the compiling
    child also packs scene_files (child_main), and this returns once it has, so that their
    packing here finds their tables in the disk caches."""
    if not hasattr(trace_batch, "overloads"):
        calls = outline.addresses()
        return lambda *args: trace_batch(*args, calls)
    entry_sig = parts()["entry"][0][1]
    if any(sig not in f.overloads for name in ("entry", "outlined") for f, sig in parts()[name]):
        failure = []
        child = None

        def compile_all():
            nonlocal child
            try:
                if not _in_cache():
                    child = _start_child(scene_files)
                    if child is not None:
                        compile_part("collision")   # while the child compiles the other events
                        _events_compiled(child)
                compile_part("entry")
                if child is not None:   # the outlined functions it compiles, its packing
                    try:
                        child.wait(timeout=CHILD_TIMEOUT_S)
                    except subprocess.TimeoutExpired:   # the packing here does it instead
                        child.kill()
                compile_part("outlined")   # from the cache, where the child compiled them
            except BaseException as exc:  # handed to the main thread
                failure.append(exc)

        worker = threading.Thread(target=compile_all, name="oceanmc-compile", daemon=True)
        t0 = time.perf_counter()
        worker.start()
        said = 0.0
        try:
            while worker.is_alive():
                worker.join(0.1)
                if should_stop is not None and should_stop():
                    raise CompileInterrupted("stopped while compiling the photon loop")
                elapsed = time.perf_counter() - t0
                if worker.is_alive() and elapsed >= COMPILE_NOTICE_AFTER_S \
                        and elapsed - said >= 5.0:
                    if not said:
                        print(f"oceanmc: compiling the photon loop (once per oceanmc version on "
                              f"this machine; cached in {CACHE_DIR})", file=sys.stderr,
                              flush=True)
                    else:
                        print(f"oceanmc: still compiling, {elapsed:.0f} s", file=sys.stderr,
                              flush=True)
                    said = elapsed
        except BaseException:
            if child is not None:
                child.kill()
            raise
        if failure:
            raise failure[0]
        _unreported_startup[0] += time.perf_counter() - t0
        if said:
            print(f"oceanmc: photon loop compiled in {time.perf_counter() - t0:.1f} s",
                  file=sys.stderr, flush=True)
    calls = outline.addresses()
    entry = trace_batch.overloads[entry_sig].entry_point
    return lambda *args: entry(*args, calls)
