"""The wavelength loops fold their remainder into masked vector iterations only in machine code
for AVX-512 (kernel/compile.py KERNEL_TAIL_FOLDING, masked_vectors): AVX2's masked moves made
the photon loop slower. Compiled (not run) in a process of its own per target, as Numba sets
its target machine once per process."""
import os
import platform
import subprocess
import sys
import textwrap

import pytest

from conftest import REPO

HASWELL = ("+64bit,+avx,+avx2,+bmi,+bmi2,+cmov,+crc32,+cx16,+cx8,+f16c,+fma,+fsgsbase,+fxsr,"
           "+invpcid,+lzcnt,+mmx,+movbe,+pclmul,+popcnt,+rdrnd,+sahf,+sse,+sse2,+sse3,+sse4.1,"
           "+sse4.2,+ssse3,+x87,+xsave,+xsaveopt")
SKYLAKE_AVX512 = HASWELL + ",+avx512f,+avx512vl,+avx512bw,+avx512dq,+avx512cd"

# a loop over wavelengths as the kernel's, compiled in kernel_optimisation with tail folding
# asked for; prints whether the target counts as AVX-512, and the masked moves of each kind in
# its machine code (AVX2's vmaskmov, AVX-512's {%k} masks)
PROGRAM = textwrap.dedent('''
    import numba
    from oceanmc.kernel.compile import kernel_optimisation, masked_vectors
    with kernel_optimisation(tail_folding=True):
        @numba.njit
        def axpy(a, b, x):
            for i in range(a.size):
                a[i] += x * b[i]
        axpy.compile("(float64[::1], float64[::1], float64)")
    asm = axpy.inspect_asm(axpy.signatures[0])
    print(masked_vectors(), "vmaskmov" in asm, "{%k" in asm)
''')


def _compiled_for(cpu_name: str, features: str) -> list[str]:
    env = {**os.environ, "NUMBA_CPU_NAME": cpu_name, "NUMBA_CPU_FEATURES": features,
           "PYTHONPATH": str(REPO)}
    done = subprocess.run([sys.executable, "-c", PROGRAM], env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


@pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"),
                    reason="the targets compared are x86's (Haswell's AVX2, Skylake's AVX-512)")
@pytest.mark.parametrize("cpu_name, features, folds", [("haswell", HASWELL, False),
                                                       ("skylake-avx512", SKYLAKE_AVX512, True)])
def test_tail_folding_only_with_avx512(cpu_name, features, folds):
    avx512, avx2_masked, avx512_masked = _compiled_for(cpu_name, features)
    assert avx512 == str(folds)
    assert avx2_masked == "False"   # (with folding on AVX2 the loop had vmaskmovpd)
    assert avx512_masked == str(folds)
