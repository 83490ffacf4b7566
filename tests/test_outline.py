"""kernel/outline.py: the photon loop's calls by address. What they compute is proved by the
whole kernel's tests and validation (every inelastic scene's emissions go through one); here,
the table of addresses and the check of argument types at a call site."""
import numba
import numpy as np
import pytest
from numba.core.errors import TypingError

from oceanmc.kernel import outline

needs_jit = pytest.mark.skipif(numba.config.DISABLE_JIT, reason="addresses need compiled code")


@needs_jit
def test_the_table_holds_one_address_per_outlined_function():
    calls = outline.addresses()
    assert calls.dtype == np.int64 and len(calls) == len(outline.OUTLINED)
    assert np.all(calls != 0) and len(set(calls.tolist())) == len(calls)
    # each function is compiled for the signature its parameters' names give, once
    for function, _ in outline.OUTLINED:
        assert outline.signature(function) in function.overloads


@needs_jit
def test_a_call_with_other_argument_types_than_compiled_for_is_refused():
    @numba.njit(cache=False)
    def wrong(calls, x):
        return outline.emit(calls, (x, x))

    with pytest.raises(TypingError, match="emit called with"):
        wrong(np.zeros(1, dtype=np.int64), 1.0)


def test_every_parameter_of_an_outlined_function_has_a_type():
    types = outline.argument_types()
    for function, _ in outline.OUTLINED:
        assert len(outline.signature(function, types)) > 0
