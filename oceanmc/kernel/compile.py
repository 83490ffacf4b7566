"""How kernel functions are compiled. Functions called only by other compiled functions are
`internal`: no CPython or C-callable wrapper is built for them (measured: wrappers were 17% of
a cold compilation), so they cannot be called from Python; with NUMBA_DISABLE_JIT=1 they are
plain Python functions like the rest."""
from numba import njit

internal = njit(error_model="numpy", cache=True, no_cpython_wrapper=True,
                no_cfunc_wrapper=True)
