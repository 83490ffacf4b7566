"""The compiled kernel, ready to run: its entry points compiled, or loaded from the disk cache.

Every scene has the same argument types (records of fixed dtypes, flat pools) but for the
with_<part> arguments, which say which optional parts of the photon loop a variant of it holds
(kernel/variants.py): the entry points of a variant have one signature, known before any scene
is packed, and are compiled once per kernel version, variant and machine, when a scene first
needs that variant and no variant holding its parts is at hand (held_variant). The whole loop,
every part compiled in, took 64-73 s to compile cold here (ready(), 2 cores, 2026-11-27, a
machine about twice as slow as the one of the figures below); trace_batch's own LLVM work
alone was 34 s of a one-process compilation of 106 s (optimisation 19.6 s, machine code
14.4 s; the callees' 17.8 s and 17.0 s, Numba's front end 37.6 s). With no optional part the
same took 31 s (trace_batch 6.1 s). benchmarks/speed.md has each shipped config's cold start
with its own variant. ready() compiles in a helper thread (LLVM releases the GIL) so that the
main thread can say what is happening every few seconds on stderr and stop at once on Ctrl-C
(KeyboardInterrupt) or when should_stop() says so (CompileInterrupted).

Numba compiles one function at a time, so on a machine with two or more cores the photon loop's
events are compiled in two processes that meet in the disk cache: a child process compiles the
events at the surface and the bottom (the rough sea's facet walk, the BRDFs, the local
estimates from the bottom), the free flight and trace_batch's other callees while this one
compiles the collision (the phase functions, the inelastic channels, the local estimates from a
collision); trace_batch, compiled last, then loads the child's part from the cache. If the
child fails or is slow, trace_batch compiles that part itself: the result is the same.
trace_batch's own compilation is the longest single step and cannot be shared out: Numba links
every callee's LLVM IR into the entry point's module, then optimises it (7.7 s, LLVM's pass
timings) and generates machine code for all of it (4.8 s); until kernel 54ffa5b each callee had
done the same for its own (the last paragraph). Measured one after the other in one process (2 cores, a CI run beside
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
balanced, and what is left is the collision's and trace_batch's own compilation. (Sharing the
events out by claims, the child taking them from the longest, this process the rest once its
collision was compiled: tried 2026-11-28 on a quiet machine, kernel 9b845d7; the child had
every event compiled by the time the collision was, 5-6 s, for the spectral, bottom and
rough-sea variants, and cold `oceanmc run CONFIG --photons 20000`, interleaved, twice, moved
by -1.4 to +0.9 s: not kept.) Kernel
e4782e8's vectorised cap scores, emission bands and carried shares added 4-5 s (one process:
32.3 s against 37.5 s, trace_batch +1.8 s, the cap scores +1.3 s, the collision +0.7 s; ready(),
interleaved: 23.7-24.8 s against 27.5-29.1 s); kernel c484c1c's exp (kernel/exp.py, in five loops)
added 1.2 s in one process (41.8 / 42.1 s against 42.7 / 43.6 s, interleaved), and the same exp
in the exact directions' and the bottom's scores (seven inlined call sites) 5.5 s to ready(),
so those were reverted (commit d8e354b). While trace_batch compiles, the child
packs the scenes `oceanmc run` was given (child_main): a cold `oceanmc run CONFIG --photons
20000` (interleaved, twice) took 27.1-27.9 s instead of 30.0-30.2 s for
deep_chlorophyll_maximum.yaml, 27.8-28.6 s instead of 30.6-31.7 s for windy_case1.yaml, with
the same results bit for bit (the tables come from the disk caches).
Calling parts of the loop by address instead of merging them (commits eadf565-2b12516,
kernel/outline.py: a table of the parts' addresses passed to trace_batch, a Numba intrinsic per
part calling its cached machine code with Numba's calling convention, each part compiled once,
beside trace_batch; reverted): with the inelastic emissions so called, ready() took
23.1 / 25.2 s against 29.8 / 29.3 s and speed.md's cold starts were 24.6-26.8 s, with every
output bit for bit the same, but the inelastic bench's scene (1 thread, CPU time, 7 interleaved
pairs) ran at a median 27.5 against 31.2 thousand photons/s, and the bench's Raman and
fluorescence run at 73,826 against 83,936 photons/s; with the bottom's local estimates and BRDF
sampling so called as well, ready() took 20.4-20.8 s against 34.1-34.6 s, but
configs/default.yaml ran at 183-223 against 233-259 thousand photons per CPU-second and the
bare-walk scene with an exact-nadir estimate (its black bottom never calls them) at 1.9-3.0
against 2.9-3.3 million photons/s; the local estimates at a collision (2-3 s less) cost the
nadir-cap scene 10% of its photons/s, the rough surface's sampling (0.3 s less) the 5 m/s scene
9%. The call itself costs about 6 ns (a microbenchmark with 14 arguments); the rest is an opaque
call on a path of the loop, taken or not, which LLVM must assume writes the packet and the
streams. Run time every run against 5 s once: not kept. (Numba's own inlining, inline='always',
instead of LLVM's: 151 s for one process against 48.5 s.)
(trace_batch at LLVM level 0, its callees at 1: 7.6 s instead of 11.2 s, but its machine code
then keeps dynamic globals, which Numba will not cache: every run would compile again.)
Where the time goes (LLVM's pass timings, every part compiled in one process, 41.8 s, kernel
c484c1c, 2026-11-27): trace_batch's own module, after both halves, takes 1.0 s of the cheap
(inlining) passes, 9.05 s of full optimisation (LICM 1.1 s, InstCombine 0.9 s, about half of
it in the analyses between passes) and 5.7 s of machine code: 14.7 s that no second process
can share. The 181 callees' own LLVM work was 15 s of optimisation and 6.9 s of machine code,
which is never run (only their IR is linked into trace_batch), since Numba finalises every
function it compiles (no longer: below). Machine code at the target machine's level 1 instead of 3 (NUMBA_OPT=1
before Numba's code generator starts) took as long (5.6 s). So with one merged trace_batch a
cold start cannot fall below 14.7 s plus the longer half and Python's start-up: the 15 s of
issue 26 needs trace_batch split (the calls by address above cost run time) or smaller (a
trace_batch per feature set, compiled when a scene first needs it).
The callees' own optimisation and machine code are skipped (kernel/compile.py
_LinkOnlyLibrary, for `internal` functions, by a pipeline of Numba's own with a library of
their own kind): their IR, after Numba's function-level passes, is what trace_batch links and
optimises. Every output of every shipped config and validation scene is the same bit for bit
(benchmarks/regression.md) and the loop runs as fast (benchmarks/speed.md). Measured first as a
patch of Numba (one process, empty cache, tests beside it): the whole loop 96 s against 132 s
(events 30 against 42 s, the collision 22 against 43 s, trace_batch 45 against 47 s). As
shipped (2026-11-28, kernel 54ffa5b against 74e89e7, quiet machine): ready() with an empty
cache, one run each, the plain variant 15.6 s against 20.7 s, the whole loop 78.9 s against
92.8 s; a cold `oceanmc run CONFIG --photons 20000` on its own variant, interleaved:
bare_walk.yaml 19.4 / 15.2 s against 26.4 / 23.7 s, default.yaml 39.5 / 37.7 s against
49.7 / 49.9 s, windy_case1.yaml 44.4 s against 61.5 s, raman_fluorescence.yaml 62.7 s against
85.9 s. What is left is mostly trace_batch's own compilation, which no second process shares.
Parts of their own for the rough sea's facet walk (three inlined call sites, where a tabulated
sea needs none), the bottoms beyond the closed-form four (GGX, Hapke, tables and the general
tabulated sampler: the BRDF dispatch at the bottom event, in its local estimates and, until
then, in an emission's exact directions, which never reach a BRDF) and the exact directions'
local estimates (kernel/variants.py REFINES; 2026-11-28, kernel 98f0a19 against the change,
cold `oceanmc run CONFIG --photons 20000`, empty caches, interleaved, twice, a busy day of this
machine): default.yaml 12.7 / 16.6 s against 11.7 / 11.7 s, shallow_sand_spectral.yaml 20.2 /
18.7 s against 17.6 / 16.1 s, windy_case1.yaml 20.6 / 18.7 s against 19.2 / 17.3 s,
raman_fluorescence.yaml 21.4 / 22.9 s against 20.0 / 19.0 s; deep_chlorophyll_maximum.yaml,
which uses none of them, 14.6 / 15.6 s against 14.7 / 16.4 s (every output the same bit for
bit).
LLVM's loop unrolling and loop strength reduction, off for the loop since kernel 7b22a15
(kernel/compile.py kernel_optimisation, which compile_part uses: measurements there), took 1.4
to 4.2 s off the cold starts. Tried beside them the same day (2026-11-29, each variant compiled
cold in a process of its own, two interleaved rounds, loop times medians of 5) and not kept:
LLVM level 2 for the kernel's IR, compiled 0.1-1.4 s later, the inelastic bench's scene 0.673 /
0.623 s against 0.643 / 0.601 s, default.yaml 0.780 / 0.770 s against 0.805 / 0.797 s,
bare_walk.yaml and windy_case1.yaml alike; the loop vectoriser's interleaving off as well, no
faster anywhere (inelastic 0.669 / 0.628 s) and compiled as long.
"""
from __future__ import annotations

import functools
import inspect
import os
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Callable, Sequence

import numba
import numpy as np

from ..kernel import records, sources, spectral, transport
from ..kernel.compile import CACHE_DIR, CACHE_WRITABLE, kernel_optimisation
from ..kernel.phase.dispatch import component_density
from ..kernel.surface.dispatch import transmittance
from ..kernel.transport import trace_batch
from ..kernel.variants import EVERYTHING, PARTS, Variant

COMPILE_NOTICE_AFTER_S = 1.0
CHILD_TIMEOUT_S = 600.0


class CompileInterrupted(Exception):
    """The user asked to stop while the kernel was compiling or loading from the disk cache
    (the text says which: "while compiling the photon loop"); nothing was traced."""


def _argument_types(variant: Variant) -> dict[str, numba.types.Type]:
    """The Numba type of each kernel argument by its name, the same in every kernel function
    (a record by its component's name, its one-row array by name_row, the scene's pools
    `floats` and `ints`, the packet p and its spectral state ps, ...; with_<part>: boolean
    where the variant compiles the part in, NoneType where it does not)."""
    f8 = numba.typeof(np.zeros(1))
    types = {"floats": f8, "ints": numba.typeof(np.zeros(1, dtype=np.int64)),
             "bp": f8, "tally": f8, "tally_row": f8, "ps": f8, "work": f8, "beam_in": f8,
             "angles": f8, "states": numba.typeof(np.zeros((1, 1))),
             "stack_ps": numba.typeof(np.zeros((1, 1))),
             "rng": numba.typeof(np.zeros(1, dtype=np.uint64)),
             "rng_emitted": numba.typeof(np.zeros(1, dtype=np.uint64)),
             "layer": numba.int64, "events": numba.int64, "wavelength": numba.int64,
             "n_stacked": numba.int64, "target": numba.int64, "level": numba.int64,
             "copies": numba.int64, "component": numba.int64, "tau": numba.float64,
             "from_sky": numba.boolean,
             "n_photons": numba.int64, "start": numba.int64, "work_budget": numba.int64,
             "mu": numba.float64}
    for name, dtype in (("medium", records.MEDIUM), ("surface", records.SURFACE),
                        ("bottom", records.BOTTOM), ("sky", records.SKY), ("grid", records.GRID),
                        ("est", records.ESTIMATES), ("ctrl", records.ESTIMATOR),
                        ("packet", records.PACKET)):
        row = numba.typeof(np.zeros(1, dtype=dtype))
        types[name], types[f"{name}_row"] = row.dtype, row
    types["p"], types["stack"] = types["packet"], types["packet_row"]
    for part, on in zip(PARTS, variant):
        types[f"with_{part}"] = numba.boolean if on else numba.none
    return types


def _signature(function, types: dict[str, numba.types.Type]) -> tuple:
    """The argument types of a kernel function, from its parameters' names."""
    return tuple(types[name] for name in inspect.signature(function.py_func).parameters)


@functools.cache
def parts(variant: Variant) -> dict[str, tuple[tuple, ...]]:
    """(dispatcher, argument types) to compile, in order: `events` (in the child process when
    there is one: the walk's events but the collision, and trace_batch's other callees),
    `collision` and `entry` (the entry points, trace_batch first) here. A function compiled in
    `events` with other argument types than trace_batch calls it with would only be compiled
    again here, at no other cost (checked once: none is). Cached: ready() asks for every
    candidate variant's on each call, and the signatures come from inspect."""
    types = _argument_types(variant)
    spectral_start = (spectral.start,) if variant.spectral else ()
    return {name: tuple((f, _signature(f, types)) for f in functions) for name, functions in (
        ("events", (transport.enter_from_air, transport.leave_or_reflect,
                    transport.reflect_at_bottom, transport.free_flight, transport.cross_plane,
                    transport.after_reflection, transport.split_into, sources.sky_direction,
                    *spectral_start, component_density, transmittance)),
        ("collision", (transport.collide,)),
        ("entry", (trace_batch, component_density, transmittance)))}


def compile_part(name: str, variant: Variant) -> None:
    """Compiles one part of a variant with the kernel's LLVM settings (kernel/compile.py
    kernel_optimisation, whose tail folding only spectral variants take; the child process runs
    this too)."""
    with kernel_optimisation(tail_folding=variant.spectral):
        for dispatcher, sig in parts(variant)[name]:
            dispatcher.compile(sig)


def _entry_signature(variant: Variant) -> tuple:
    return parts(variant)["entry"][0][1]


def _loaded(variant: Variant) -> bool:
    """Loads trace_batch's variant from the disk cache into this process if the cache holds
    it (0.3 s), as Numba's Dispatcher.compile does with a cache hit; a miss costs a read of the
    cache's index. Whether it is here now."""
    sig = _entry_signature(variant)
    if sig in trace_batch.overloads:
        return True
    try:
        cres = trace_batch._cache.load_overload(sig, trace_batch.targetctx)
    except AttributeError:   # a Numba without this (private) interface: compile() loads it
        return False
    if cres is None:
        return False
    trace_batch.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
    trace_batch.add_overload(cres)
    return True


# OCEANMC_OWN_VARIANT=1: every scene runs on the variant with exactly its own parts, compiled
# where no process or cache holds it, never on a larger one. A larger one saves a compilation
# but runs slower: the own variant traced the bare-walk scene 16%, configs/default.yaml 14%,
# and the bench's exact-nadir, nadir-cap and rough-sea scenes 7%, 6% and 10% faster than the
# whole loop, with the same tallies bit for bit (1 thread, medians of 7 interleaved runs,
# 2026-11-27). The bench sets it, so that its speeds do not depend on what the cache holds.
OWN_VARIANT_ENV = "OCEANMC_OWN_VARIANT"


def _candidates(variant: Variant) -> list[Variant]:
    """The variants a scene using `variant`'s parts may run on, the nearest first."""
    return [variant] if os.environ.get(OWN_VARIANT_ENV) == "1" else variant.supersets()


def held_variant(variant: Variant) -> Variant | None:
    """The variant of trace_batch, in this process or in the disk cache, that holds every part
    of `variant`: the nearest (Variant.supersets) of those here, else of those on disk (then
    loaded); None when there is none. A scene runs on any variant that holds its parts, with
    the same results bit for bit (kernel/variants.py), and compiles its own only when none is
    at hand (or, under OCEANMC_OWN_VARIANT=1, when its own is not)."""
    return _here(variant) or next((candidate for candidate in _candidates(variant)
                                   if _loaded(candidate)), None)


def _here(variant: Variant) -> Variant | None:
    """The nearest variant holding `variant` that this process has compiled or loaded."""
    return next((candidate for candidate in _candidates(variant)
                 if _entry_signature(candidate) in trace_batch.overloads), None)


EVENTS_COMPILED = "events compiled"


def child_main(variant: str, scene_files: list[str]) -> None:
    """The compiling child process: compiles the part `events` of the variant (its parts as
    0s and 1s in PARTS' order) into the shared cache, says so on stdout, then packs the scenes
    of scene_files while the parent compiles trace_batch (their tables, cached on disk, are
    then the parent's for the asking: a profile's or a windy sea's take seconds to build), and
    compiles what their runs call after the photons. A scene it cannot pack is left to the
    parent, which reports why."""
    compile_part("events", Variant(*(flag == "1" for flag in variant)))
    print(EVENTS_COMPILED, flush=True)
    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())   # no one reads on
    from ..config import load_config
    from ..scene.surface import reflected_local
    from .simulation import prepare
    for path in scene_files:
        try:
            run = prepare(load_config(path))
            if run.config.tallies.local_directions_deg:
                # what the run calls after its photons, compiled into the disk cache here: the
                # exact directions' reflected sky and sun glint (surface.dispatch.reflected_from,
                # cox_munk.glint_single; 1.5 s of a cold windy_case1.yaml in the parent)
                reflected_local(run.config, run.scene.surface[0], 0, 1)
        except Exception:  # the parent packs it again and says what is wrong
            pass


def _start_child(variant: Variant, scene_files: Sequence[Path]) -> subprocess.Popen | None:
    """The compiling child process (child_main), if this machine has a core to spare for it."""
    if (os.cpu_count() or 1) < 2 or not CACHE_WRITABLE:   # (they meet in the disk cache)
        return None
    code = ("import sys; from oceanmc.run.compiling import child_main; "
            "child_main(sys.argv[1], sys.argv[2:])")
    flags = "".join("1" if on else "0" for on in variant)
    try:
        return subprocess.Popen([sys.executable, "-c", code, flags, *map(str, scene_files)],
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


def ready(variant: Variant = EVERYTHING, should_stop: Callable[[], bool] | None = None,
          scene_files: Sequence[Path] = ()) -> tuple[Callable, Variant]:
    """(trace_batch's compiled entry point, its variant) for a scene that uses the parts of
    `variant`: the nearest variant holding them that this process has or the disk cache holds
    (held_variant), else this one, compiled (plain trace_batch, EVERYTHING under
    NUMBA_DISABLE_JIT=1). The entry point takes the variant's kernel_args() after the pools.
    On a cold start the compiling child also packs scene_files (child_main), and this returns
    once it has, so that their packing here finds their tables in the disk caches."""
    if not hasattr(trace_batch, "overloads"):
        return trace_batch, EVERYTHING
    here = _here(variant)
    if here is not None and all(sig in f.overloads for f, sig in parts(here)["entry"]):
        return trace_batch.overloads[_entry_signature(here)].entry_point, here
    t0 = time.perf_counter()
    held = held_variant(variant)
    cold = held is None
    held = held or variant
    if cold or any(sig not in f.overloads for f, sig in parts(held)["entry"]):
        failure = []
        child = None

        def compile_all():
            nonlocal child
            try:
                if cold:
                    child = _start_child(held, scene_files)
                    if child is not None:
                        compile_part("collision", held)   # while the child compiles the events
                        _events_compiled(child)
                compile_part("entry", held)
                if child is not None:   # its packing of the scenes
                    try:
                        child.wait(timeout=CHILD_TIMEOUT_S)
                    except subprocess.TimeoutExpired:   # the packing here does it instead
                        child.kill()
            except BaseException as exc:  # handed to the main thread
                failure.append(exc)

        worker = threading.Thread(target=compile_all, name="oceanmc-compile", daemon=True)
        worker.start()
        said = 0.0
        try:
            while True:
                worker.join(0.1)
                # asked at least once, even when the worker is done before the first look (a
                # load from the cache may be: a stop asked meanwhile was missed, 2026-11-29)
                if should_stop is not None and should_stop():
                    raise CompileInterrupted("while compiling the photon loop" if cold else
                                             "while loading the photon loop from the disk cache")
                if not worker.is_alive():
                    break
                elapsed = time.perf_counter() - t0
                if elapsed >= COMPILE_NOTICE_AFTER_S and elapsed - said >= 5.0:
                    if not said:
                        print(f"oceanmc: compiling the photon loop with its parts for this "
                              f"scene ({held.label}; once per oceanmc version and set of parts "
                              f"on this machine; cached in {CACHE_DIR})", file=sys.stderr,
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
        if said:
            print(f"oceanmc: photon loop compiled in {time.perf_counter() - t0:.1f} s",
                  file=sys.stderr, flush=True)
    _unreported_startup[0] += time.perf_counter() - t0
    return trace_batch.overloads[_entry_signature(held)].entry_point, held
