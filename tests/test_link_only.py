"""`internal` kernel functions (kernel/compile.py _LinkOnlyLibrary) get no machine code of their
own, only the IR their callers link in: callers compute with them, in this process and from the
disk cache in another, as with Numba's own libraries."""
import os
import subprocess
import sys
import textwrap

import pytest

from conftest import REPO
from oceanmc.kernel.compile import LINK_ONLY

pytestmark = pytest.mark.skipif(not LINK_ONLY, reason="a Numba other than 0.68: Numba's own "
                                "libraries for internal functions (kernel/compile.py)")

MODULE = textwrap.dedent('''
    from oceanmc.kernel.compile import internal, kernel

    @internal
    def twice(x):
        return 2.0 * x

    @internal
    def twice_plus_one(x):   # an internal function that links another
        return twice(x) + 1.0

    @kernel
    def first_caller(x):
        return twice_plus_one(x)

    @kernel
    def second_caller(x):
        return 3.0 * twice_plus_one(x)
''')


def _defined(module):
    return [f.name for f in module.functions if not f.is_declaration]


def test_internal_functions_have_linking_ir_and_no_machine_code(monkeypatch):
    from oceanmc.kernel import compile as kernel_compile
    monkeypatch.setattr(kernel_compile, "CACHE_WRITABLE", False)   # nothing of it cached

    @kernel_compile.internal
    def halve(x):
        return 0.5 * x

    @kernel_compile.kernel
    def caller(x):
        return halve(x) - 1.0

    assert caller(6.0) == 2.0
    (halved,) = halve.overloads.values()
    (called,) = caller.overloads.values()
    assert isinstance(halved.library, kernel_compile._LinkOnlyLibrary)
    engine_gets = halved.library._final_module   # what the JIT engine compiles
    assert _defined(engine_gets) == []
    # (the environment pointer, which Numba sets for every compiled function)
    assert any("NumbaEnv" in v.name for v in engine_gets.global_variables
               if not v.is_declaration)
    assert any("halve" in name for name in _defined(halved.library._get_module_for_linking()))
    assert not isinstance(called.library, kernel_compile._LinkOnlyLibrary)
    assert any("caller" in name for name in _defined(called.library._final_module))


def test_a_cached_internal_function_links_into_a_new_caller_in_another_process(tmp_path):
    """The first process compiles and caches twice_plus_one (with twice linked in) for
    first_caller; the second loads it from the cache (a cache hit) and links it into
    second_caller, which it compiles: the two compilation processes of run/compiling.py meet
    so."""
    (tmp_path / "linked_functions.py").write_text(MODULE)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), str(REPO)]),
               OCEANMC_CACHE_DIR=str(tmp_path / "cache"))
    first = subprocess.run(
        [sys.executable, "-c", "import linked_functions as m; print(m.first_caller(4.0))"],
        env=env, capture_output=True, text=True, timeout=300)
    assert first.returncode == 0, first.stderr
    assert first.stdout.split() == ["9.0"]
    second = subprocess.run(
        [sys.executable, "-c", "import linked_functions as m; print(m.second_caller(4.0)); "
         "print(sum(m.twice_plus_one.stats.cache_hits.values()), "
         "sum(m.second_caller.stats.cache_misses.values()))"],
        env=env, capture_output=True, text=True, timeout=300)
    assert second.returncode == 0, second.stderr
    assert second.stdout.split() == ["27.0", "1", "1"]


def test_recursive_internal_functions_are_compiled_as_numba_compiles_any(monkeypatch):
    """Mutual recursion leaves a call that Numba resolves from the callee's machine code at run
    time (RuntimeLinker): such a library gets its machine code (without it the call aborted:
    'unresolved symbol')."""
    from oceanmc.kernel import compile as kernel_compile
    monkeypatch.setattr(kernel_compile, "CACHE_WRITABLE", False)

    @kernel_compile.internal
    def count_down(n):
        return 0 if n <= 0 else 1 + count_down_other(n - 1)

    @kernel_compile.internal
    def count_down_other(n):
        return 0 if n <= 0 else 1 + count_down(n - 1)

    @kernel_compile.kernel
    def caller(n):
        return count_down(n)

    assert caller(5) == 5
