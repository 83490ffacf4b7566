"""The kernel's one search: bisection of a sorted stretch of a flat pool (the tally edges, the
phase and BRDF tables, the BRDF sampler's and the sky's CDFs).

interval(values, start, lo, hi, x) returns the index i in lo .. hi - 1 with

    values[start + i] <= x < values[start + i + 1]

reading only values[start + lo + 1] .. values[start + hi - 1], which must not decrease. The two
ends, values[start + lo] and values[start + hi], are never read: they count as -inf and +inf,
so they need not exist (lo = -1, hi = the stretch's length), an x below values[start + lo + 1]
gives lo and an x at or above values[start + hi - 1] gives hi - 1. Ties: an x equal to one or
more entries lies in the interval that starts at the last of them. In numpy's words, i is
lo + searchsorted(values[start + lo + 1:start + hi], x, side="right"). hi <= lo + 1 gives lo
without reading anything.

falling=True searches entries that do not increase, with the comparisons mirrored:
values[start + i] >= x > values[start + i + 1], the ends counting as +inf and -inf, ties in
the interval that starts at the last equal entry (lo + the number of entries >= x).

NaN: an x or an entry that is NaN fails every comparison, which moves hi down; a NaN x gives
lo. ceil(log2(hi - lo)) comparisons.

`hot` (compile.py): inlined into every caller (the phase sampler calls it at every
collision), and callable from Python for the tests."""
from .compile import hot


@hot
def interval(values, start, lo, hi, x, falling=False):
    """The i in lo .. hi - 1 with values[start + i] <= x < values[start + i + 1] (falling:
    values[start + i] >= x > values[start + i + 1]), the ends never read (module docstring)."""
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if (x <= values[start + mid]) if falling else (values[start + mid] <= x):
            lo = mid
        else:
            hi = mid
    return lo
