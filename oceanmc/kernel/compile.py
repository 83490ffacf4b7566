"""How kernel functions are compiled and cached.

Every function is compiled with error_model="numpy": a float division by zero gives inf or nan
instead of raising, which removes a branch from every division in the photon loop (the kernel
guards its divisions itself; measured +25% photons/s).

`kernel`: every function the photon loop calls. Compiled without Numba's reference counting
(_nrt=False): each array argument of a call otherwise costs an atomic incref/decref pair at the
callee (measured on the bare-walk scene: 1.5x fewer photons/s with it). They borrow the
caller's arrays, which outlive the call, and none of them allocates.

No C-callable (cfunc) wrapper is built for any of them, and none at all for `internal`
functions, which only other compiled functions call (measured: the wrappers were 17% of a cold
compilation). `internal` functions carry LLVM's alwaysinline attribute: the events of the photon
loop and their small helpers, each with one or two call sites, which LLVM merges into their
caller (1.7x more photons/s than calls that pass a dozen arrays by value; measured: leaving the
surface and bottom events to LLVM's own judgement cost 20% on the bare-walk scene and saved no
compile time). The crossing scorer, with seven call sites, is a plain `kernel` function: LLVM
decides (measured: as fast, and 0.8 s less to compile than inlining it everywhere).

`hot`: `kernel` functions that the loop calls at every collision and that tests also call from
Python, with the alwaysinline attribute (the phase function's sampling and evaluation:
measured +18% photons/s with an exact-direction local estimate, +14% with the nadir-cap one,
one run each).

`batch`: the photon loop's entry point (transport.trace_batch), which releases the GIL so that
batches run in parallel threads. `setup`: functions run once per scene or by tests, which may
allocate.

Numba's on-disk cache checks only the source file of each cached function, not the files of the
functions it calls, so an edit to (say) tally.py would leave transport's cached machine code
stale. The cache therefore lives in a folder named after a hash of every kernel source file:
any kernel edit starts a fresh cache. OCEANMC_CACHE_DIR moves it (the benchmark points it at an
empty folder to time a cold start). Caches of earlier kernel sources are deleted, but only
folders that hold oceanmc's marker file: OCEANMC_CACHE_DIR may name a folder that also holds a
user's own numba-* folders. Numba reads its CACHE_DIR when a function is decorated, so
the decorators here set it for the kernel's functions alone and restore it afterwards.

With Numba 0.68 (LINK_ONLY), `internal` functions get no machine code of their own
(_LinkOnlyLibrary): only other compiled functions call them, and Numba links their LLVM IR into
each caller's module, which it then optimises and compiles as one, so their own module-level
optimisation and machine code would never be used (run/compiling.py has the measurements).

With NUMBA_DISABLE_JIT=1 all of these are plain Python functions."""
import getpass
import hashlib
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

import llvmlite.binding as llvm
import numba
from numba.core import codegen as numba_codegen
from numba.core.codegen import RuntimeLinker
from numba.core.compiler import CompilerBase, DefaultPassBuilder
from numba.core.compiler_lock import require_global_compiler_lock
from numba.core.compiler_machinery import LoweringPass, register_pass
from numba.core.config import _OptLevel
from numba.core.typed_passes import AnnotateTypes


def _kernel_hash() -> str:
    digest = hashlib.sha256(numba.__version__.encode())
    root = Path(__file__).parent
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


CACHE_MARKER = ".oceanmc-kernel-cache"


def _cache_folder() -> tuple[Path, bool]:
    """The compile cache's folder and whether it can be written: the first of
    OCEANMC_CACHE_DIR, the package's __pycache__, the user's cache folder (XDG_CACHE_HOME or
    ~/.cache, /oceanmc) and the temporary folder (oceanmc-<user>) where the folder can be made
    and written. An install the user cannot write (a shared site-packages) thus caches in the
    user's own folder; where nothing can be written, Numba compiles without a cache (every
    process compiles again) rather than failing (measured: Numba's cache=True raises at
    decoration when no folder of its own is writable)."""
    roots = [Path(os.environ["OCEANMC_CACHE_DIR"])] if os.environ.get("OCEANMC_CACHE_DIR") else []
    roots.append(Path(__file__).parent / "__pycache__")
    try:
        roots.append(Path(os.environ.get("XDG_CACHE_HOME") or Path("~/.cache").expanduser())
                     / "oceanmc")
    except RuntimeError:   # no home folder
        pass
    user = str(os.getuid()) if hasattr(os, "getuid") else getpass.getuser()
    roots.append(Path(tempfile.gettempdir()) / f"oceanmc-{user}")
    name = f"numba-{_kernel_hash()}"
    for root in roots:
        try:
            (root / name).mkdir(parents=True, exist_ok=True)
            (root / name / CACHE_MARKER).touch()
        except OSError:
            continue
        if os.access(root / name, os.W_OK):
            return root / name, True
    return roots[0] / name, False


CACHE_DIR, CACHE_WRITABLE = _cache_folder()
if CACHE_WRITABLE:
    for _stale in CACHE_DIR.parent.glob("numba-*"):
        if _stale != CACHE_DIR and (_stale / CACHE_MARKER).is_file():
            shutil.rmtree(_stale, ignore_errors=True)  # caches of earlier kernel sources


class _LinkOnlyLibrary(numba_codegen.JITCodeLibrary):
    """The code library of an `internal` function: Numba's own but for finalize, which links
    the callees' IR as Numba does and keeps the result as the module other functions link in
    (the function-level passes of add_llvm_module have run on it), but skips the module-level
    optimisation and the machine code of the functions (a third of a cold compilation of the
    whole loop: 18 s of LLVM optimisation and 17 s of machine code, one process, for code that
    nothing calls; run/compiling.py). What it hands to the JIT engine is a module of the
    linked module's defined global variables alone (Numba's environment pointers, which
    CPUContext.get_executable sets for every compiled function, with or without an entry
    point; constant exception arguments). The disk cache stores it as Numba stores any library
    (serialize_using_object_code: that small module's object code and the linking IR), and
    loads it as Numba's own. A function that reaches a call Numba could not resolve when it
    compiled it (recursion: RuntimeLinker, filled from the machine code of the function it
    names) is compiled as Numba compiles any."""

    def finalize(self):
        require_global_compiler_lock()
        self._codegen._check_llvm_bugs()
        self._raise_if_finalized()
        seen = set()
        for library in self._linking_libraries:   # as CPUCodeLibrary.finalize links them
            if library not in seen:
                self._reload_init.update(library._reload_init)
                seen.add(library)
                self._final_module.link_in(library._get_module_for_linking(), preserve=True)
        if any(variable.name.startswith(RuntimeLinker.PREFIX)
               for variable in self._final_module.global_variables):
            self._optimize_final_module()   # the rest of CPUCodeLibrary.finalize
            self._final_module.verify()
            self._finalize_final_module()
            return
        self._final_module.verify()
        linking = self._final_module.clone()
        for function in linking.functions:   # as _get_module_for_linking makes them
            if not function.is_declaration and function.linkage == llvm.Linkage.external:
                function.linkage = "linkonce_odr"
        self._shared_module = linking
        header = str(self._codegen._create_empty_module(self.name))   # (triple, data layout)
        self._final_module = llvm.parse_assembly(header + "\n".join(
            str(variable) for variable in self._final_module.global_variables
            if not variable.is_declaration))
        self._final_module.name = linking.name
        self._finalize_final_module()


@register_pass(mutates_CFG=False, analysis_only=False)
class _LinkOnlyLowering(LoweringPass):
    """Gives the function a _LinkOnlyLibrary before Numba's native lowering, which otherwise
    makes a library of its own kind."""
    _name = "oceanmc_link_only_library"

    def __init__(self):   # (abstract in Numba's CompilerPass)
        LoweringPass.__init__(self)

    def run_pass(self, state):
        if state.library is None:
            state.library = _LinkOnlyLibrary(state.targetctx.codegen(),
                                             state.func_id.func_qualname)
            state.library.enable_object_caching()
        return True


class _LinkOnlyCompiler(CompilerBase):
    """Numba's nopython pipeline with _LinkOnlyLowering just before its lowering."""

    def define_pipelines(self):
        pipeline = DefaultPassBuilder.define_nopython_pipeline(self.state)
        pipeline.add_pass_after(_LinkOnlyLowering, AnnotateTypes)
        pipeline.finalize()
        return [pipeline]


def _jit(**options):
    def decorate(function):
        previous = numba.config.CACHE_DIR
        numba.config.CACHE_DIR = str(CACHE_DIR)
        try:
            return numba.njit(error_model="numpy", cache=CACHE_WRITABLE, **options)(function)
        finally:
            numba.config.CACHE_DIR = previous
    return decorate


kernel = _jit(_nrt=False, no_cfunc_wrapper=True)
# _LinkOnlyLibrary.finalize rewrites Numba 0.68's CPUCodeLibrary.finalize on its private
# helpers; with another Numba, `internal` functions are compiled as Numba compiles any (the
# same machine code in the end, a longer compilation)
LINK_ONLY = numba.__version__.startswith("0.68.")
internal = _jit(_nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True, forceinline=True,
                **({"pipeline_class": _LinkOnlyCompiler} if LINK_ONLY else {}))
hot = _jit(_nrt=False, no_cfunc_wrapper=True, forceinline=True)
batch = _jit(_nrt=False, nogil=True)
setup = _jit()


# How LLVM optimises the kernel's IR when run/compiling.py compiles a variant of the photon loop
# (set here, among the kernel's sources, so that a change of them changes the kernel hash and
# with it the disk cache). Level 1 (machine code is still generated at Numba's default level)
# keeps the inlining of the event functions; measured on this 2-core machine, one process:
# 14.7-15.7 s of compilation against 21.3 s at level 3, and as many photons/s on the bare-walk
# scene (4.7M per CPU-second at both, within the noise).
KERNEL_OPT_LEVEL = 1
# LLVM's loop unrolling (its LoopUnrollPass and LoopFullUnrollPass; the loop vectoriser still
# interleaves) off: the loops over wavelengths, levels and table rows have short trip counts
# that the unrolled copies only lengthen. Measured 2026-11-29 (each variant compiled cold in a
# process of its own, interleaved rounds; loop times medians of 5 runs): the inelastic bench's
# scene 0.641 / 0.655 / 0.587 s against 0.704 / 0.794 / 0.695 s, its elastic scene, bare_walk,
# default and windy_case1 as fast (within 1-4%, either way), and every variant compiled
# 0.4-1.9 s sooner (LLVM's pass timings: loop unrolling was 9% of trace_batch's optimisation).
# With the next setting as well, against neither (kernel 7b22a15 against 0eef064, same day):
# cold `oceanmc run CONFIG --photons 20000`, empty caches, interleaved, twice:
# raman_fluorescence.yaml 14.4 / 14.1 s against 18.6 / 18.3 s, windy_case1.yaml 12.6 / 12.6 s
# against 16.1 / 15.6 s, default.yaml 8.0 / 8.0 s against 9.2 / 9.6 s; the inelastic bench's
# photon loop (10^5 photons, 2 threads, three interleaved rounds of 3 runs) 0.93-1.00 s against
# 1.05-1.18 s; every output of every config and validation scene bit for bit the same.
KERNEL_LOOP_UNROLLING = False
# Machine code without LLVM's loop strength reduction (its option --disable-lsr, read when
# the code generator's passes are set up), a fifth of the machine code's passes for
# trace_batch (LLVM's pass timings: 0.86 s of 4.2 s for the inelastic variant): measured the
# same day, with loop unrolling off in both, each variant compiled cold in a process of its
# own, interleaved: compiled 0.0-1.6 s sooner (0.6 s on the mean of 10 pairs over four scenes), and
# the photon loop as fast (loop times, medians of 5, four rounds: bare_walk, 10^6 photons on
# one thread, 0.151 / 0.148 / 0.154 / 0.151 s against 0.150 / 0.148 / 0.150 / 0.150 s; the
# inelastic bench's scene 0.613 / 0.674 / 0.660 / 0.604 s against 0.643 / 0.746 / 0.638 /
# 0.636 s).
KERNEL_LOOP_STRENGTH_REDUCTION = False
# The vectorised loops over wavelengths fold their remainder into masked vector iterations
# (LLVM's --prefer-predicate-over-epilogue=predicate-else-scalar-epilogue; a loop that cannot
# be folded keeps its scalar remainder) instead of finishing it one element at a time: on this
# machine's AVX-512 a vector iteration takes 16 wavelengths (8 lanes, interleaved twice), so
# of the 31 bands of a 400-700 nm spectrum 15 went through the scalar remainder. Measured
# (2026-11-29, loop medians of 5, 2 threads, interleaved rounds, the same kernel with and
# without): the inelastic bench's elastic scene (31 bands) 0.201 / 0.204 / 0.200 / 0.218 /
# 0.218 s -> 0.166 / 0.183 / 0.170 / 0.174 / 0.172 s; case1_spectral.yaml (31 bands) 0.482 /
# 0.459 -> 0.434 / 0.386 s; windy_case1.yaml (16 bands, no remainder) 0.970 / 1.056 -> 1.003 /
# 0.990 s; default.yaml and bare_walk.yaml (one wavelength) as fast; the inelastic scene (37
# bands, a remainder of 5) 0.524 / 0.540 / 0.541 / 0.556 / 0.603 -> 0.521 / 0.543 / 0.512 /
# 0.612 / 0.549 s. Compiled as fast or faster (less code: 4.7 -> 4.1 s, 14.3 -> 13.4 s, one
# cold compilation each). Every output is the same bit for bit (benchmarks/regression.md), on
# any machine; the speed is measured on this one only (AMD znver5): where masked loads are slow
# (AVX2 without AVX-512) it does not pay, so only machine code for AVX-512, whose mask
# registers make a masked iteration as cheap as a full one, folds (masked_vectors): the same
# kernel compiled for AVX2 (NUMBA_CPU_NAME=haswell with Haswell's features, run on this
# machine, 2026-11-29, three interleaved rounds) was slower with folding, the elastic scene
# 0.371 / 0.388 / 0.347 s against 0.355 / 0.362 / 0.335 s, case1_spectral.yaml 0.535 / 0.533 /
# 0.490 against 0.512 / 0.528 / 0.494 s, the inelastic scene (6 * 10^4 photons) 0.703 / 0.677 /
# 0.653 against 0.670 / 0.604 / 0.578 s (AVX2's masked moves are slow on AMD's cores; Intel's
# AVX2 cores were not measured). Only variants with the spectral walk fold
# (kernel_optimisation's tail_folding): a one-wavelength loop has no wavelength loops to gain,
# and the rough sea's table lost by it on the surface bench's one-wavelength scene (its
# photons/s over the flat sea's 0.60 / 0.58 / 0.65 against 0.66 / 0.74 without, three and two
# runs).
KERNEL_TAIL_FOLDING = True


def masked_vectors() -> bool:
    """Whether the machine code Numba makes here has AVX-512's masked vector operations (the
    target's features: NUMBA_CPU_FEATURES where set, else the host's, as Numba chooses them;
    its cache keeps machine code per CPU name and features, so a cached kernel was folded or
    not as this says)."""
    features = numba.config.CPU_FEATURES
    if features is None:
        features = numba_codegen.get_host_cpu_features()
    return "+avx512f" in features.split(",")


def _kernel_pass_builder(tm, opt=2, loop_vectorize=False, slp_vectorize=False):
    """Numba 0.68's pass builder (numba/core/llvm_bindings.py create_pass_builder, which
    numba.core.codegen calls for every function and module pass manager) with the kernel's
    loop unrolling."""
    options = llvm.create_pipeline_tuning_options()
    options.speed_level = opt
    options.slp_vectorization = slp_vectorize
    options.loop_vectorization = loop_vectorize
    options.loop_unrolling = KERNEL_LOOP_UNROLLING
    return llvm.create_pass_builder(tm, options)


@contextmanager
def kernel_optimisation(tail_folding: bool = True):
    """Numba compiles with the kernel's LLVM settings (KERNEL_OPT_LEVEL, KERNEL_LOOP_UNROLLING,
    KERNEL_LOOP_STRENGTH_REDUCTION, KERNEL_TAIL_FOLDING where tail_folding and the target has
    AVX-512: masked_vectors) inside this block:
    run/compiling.py compiles the photon loop's variants in it. (Numba builds its pass managers
    anew for every function, from its config and its module's create_pass_builder, which this
    replaces while it lasts, and LLVM reads its options when it sets up the code generator's
    passes; another Numba than 0.68 keeps its own pass builder.)"""
    previous_level = numba.config.OPT
    previous_builder = getattr(numba_codegen, "create_pass_builder", None)
    numba.config.OPT = _OptLevel(KERNEL_OPT_LEVEL)
    if LINK_ONLY and previous_builder is not None:
        numba_codegen.create_pass_builder = _kernel_pass_builder
    llvm.set_option("", f"--disable-lsr={str(not KERNEL_LOOP_STRENGTH_REDUCTION).lower()}")
    if KERNEL_TAIL_FOLDING and tail_folding and masked_vectors():
        llvm.set_option("", "--prefer-predicate-over-epilogue=predicate-else-scalar-epilogue")
    try:
        yield
    finally:
        numba.config.OPT = previous_level
        if previous_builder is not None:
            numba_codegen.create_pass_builder = previous_builder
        llvm.set_option("", "--disable-lsr=false")   # (LLVM's defaults)
        llvm.set_option("", "--prefer-predicate-over-epilogue=scalar-epilogue")
