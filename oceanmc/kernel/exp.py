"""exp(x) in plain arithmetic, for the photon loop's loops over wavelengths.

Numba compiles math.exp to a call of libm's exp, which LLVM cannot vectorise (its only vector
exp is Intel's SVML, which the pip llvmlite is built without: llvmlite.binding.targets.
has_svml() is False), so every wavelength of a settle or of a local estimate paid a call through
glibc's wrapper. Measured (perf, the spectral bench's Chl 1 deep scene, 31 bands, 1 thread, kernel
e4782e8): libm's exp was 24% of the process's samples, the kernel's own code 49%. Written as
arithmetic on the float's bits the same function inlines and vectorises.

Method (Cody & Waite 1980, "Software Manual for the Elementary Functions", chapter 6; the split
of ln 2 as in fdlibm's e_exp.c):
- k = x / ln 2 rounded to the nearest integer, by adding and subtracting 1.5 2^52 (the sum's low
  bits are then k itself, so no float-to-integer conversion is needed);
- r = x - k ln 2 with ln 2 = LN2_HI + LN2_LO, LN2_HI of 32 significant bits so that k LN2_HI is
  exact for |k| < 2^20; |r| <= ln(2) / 2;
- exp(r) by its Taylor polynomial of degree 13 (truncation below |r|^14 / 14! < 4e-18 relative),
  as 1 + (r + r^2 q(r)) so that the one rounding of a number near 1 comes last, q evaluated by
  Estrin's scheme (Knuth, TAOCP vol. 2, 4.6.4), whose dependency chains are a few multiply-adds
  long instead of Horner's eleven;
- 2^k from the exponent bits, as 2^floor(k/2) 2^(k - floor(k/2)) so that results below 2^-1022
  come out subnormal by the multiplication's own rounding.
x > 709.78 gives inf, x < -745.13 gives 0, NaN gives NaN. tests/test_exp.py checks it against
math.exp (within 1 unit in the last place for normal results; 9% of them differ by 1).

Under NUMBA_DISABLE_JIT=1 (the kernel as plain Python) exp is math.exp.
"""
import math

import numba
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from .compile import internal

INV_LN2 = 1.4426950408889634
LN2_HI = 6.93147180369123816490e-01     # fdlibm e_exp.c: ln2HI[0], 0x3fe62e42 fee00000
LN2_LO = 1.90821492927058770002e-10     # fdlibm e_exp.c: ln2LO[0]
ROUNDING_SHIFT = 6755399441055744.0     # 1.5 * 2^52
ROUNDING_SHIFT_BITS = 0x4338000000000000
EXPONENT_BIAS = 1023
OVERFLOW = 709.782712893384             # ln(DBL_MAX)
UNDERFLOW = -745.1332191019412          # ln(2^-1075): below it exp rounds to 0
# 1 / m! for m = 2..13
T2, T3 = 0.5, 1.0 / 6.0
T4, T5, T6, T7 = 1.0 / 24.0, 1.0 / 120.0, 1.0 / 720.0, 1.0 / 5040.0
T8, T9, T10, T11 = 1.0 / 40320.0, 1.0 / 362880.0, 1.0 / 3628800.0, 1.0 / 39916800.0
T12, T13 = 1.0 / 479001600.0, 1.0 / 6227020800.0


@intrinsic
def _float_from_bits(typingctx, bits):
    """The float64 whose IEEE 754 bits are the int64 `bits`."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())
    return types.float64(types.int64), codegen


@intrinsic
def _bits_of_float(typingctx, value):
    """The IEEE 754 bits of the float64 `value`, as an int64."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))
    return types.int64(types.float64), codegen


@internal
def _exp(x):
    """e^x (see the module's docstring)."""
    clamped = min(max(x, UNDERFLOW - 1.0), OVERFLOW + 1.0)   # keeps 2^k's exponents in range
    shifted = clamped * INV_LN2 + ROUNDING_SHIFT
    k = shifted - ROUNDING_SHIFT
    k_bits = _bits_of_float(shifted) - ROUNDING_SHIFT_BITS
    r = (clamped - k * LN2_HI) - k * LN2_LO
    r2 = r * r
    r4 = r2 * r2
    # 1 + (r + r^2 q(r)): the one rounding of a number near 1 comes last
    q = ((T2 + T3 * r) + (T4 + T5 * r) * r2) + ((T6 + T7 * r) + (T8 + T9 * r) * r2) * r4 \
        + ((T10 + T11 * r) + (T12 + T13 * r) * r2) * (r4 * r4)
    poly = 1.0 + (r + r2 * q)
    half = k_bits >> 1
    y = poly * _float_from_bits((half + EXPONENT_BIAS) << 52) \
        * _float_from_bits((k_bits - half + EXPONENT_BIAS) << 52)
    if x > OVERFLOW:
        y = math.inf
    if x < UNDERFLOW:
        y = 0.0
    if x != x:
        y = x
    return y


exp = math.exp if numba.config.DISABLE_JIT else _exp
