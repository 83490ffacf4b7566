"""How kernel functions are compiled.

`kernel`: every function the photon loop calls. Compiled without Numba's reference counting
(_nrt=False): each array argument of a call otherwise costs an atomic incref/decref pair at the
callee (measured: 2.3x fewer photons/s with it). They borrow the caller's arrays, which outlive
the call, and none of them allocates.

No C-callable (cfunc) wrapper is built for any of them, and none at all for `internal`
functions, which only other compiled functions call (measured: the wrappers were 17% of a cold
compilation). `internal` functions carry LLVM's alwaysinline attribute: each has one call site
(the events of the photon loop and their helpers), so LLVM merges it into its caller once,
which is 1.7x more photons/s than calls that pass a dozen arrays by value.

With NUMBA_DISABLE_JIT=1 all of them are plain Python functions."""
from numba import njit

kernel = njit(error_model="numpy", cache=True, _nrt=False, no_cfunc_wrapper=True)
internal = njit(error_model="numpy", cache=True, _nrt=False, no_cpython_wrapper=True,
                no_cfunc_wrapper=True, forceinline=True)
