"""Parts of the photon loop called by address instead of merged into it: the inelastic
channels' emissions (channels.emit), the largest part of the kernel that not every scene runs.

Merged into trace_batch (kernel/compile.py's alwaysinline), a function's code is optimised and
compiled by LLVM again in every function it is merged into (alone, in its event, in
trace_batch), and trace_batch cannot be compiled until it is. Called through the address table
`calls` (one int64 per function of OUTLINED, in that order: addresses()), it is compiled once,
on its own, while trace_batch compiles (run/compiling.py), and its cached machine code is found
by address. Measured (ready(), empty cache, 2 cores, 2026-11-27, interleaved): 23.1 / 25.2 s
against 29.8 / 29.3 s merged.

A call by address costs about 6 ns more than merged code (a microbenchmark with this many
arguments), nothing beside an emission's work. Other parts were called by address and merged
again, for what they cost at run time beyond the call itself (merged, LLVM shares the loop's
values with them; an opaque call on a path of the loop costs the loop even where it is not
taken): the bottom's local estimates and BRDF sampling (ready() 20.4-20.8 s, but
configs/default.yaml ran at 183-223 against 233-259 thousand photons per CPU-second, and the
bare-walk scene with an exact-nadir estimate, where the black bottom is never called, at
1.9-3.0 against 2.9-3.3 million photons/s, interleaved), the local estimates at a collision
(2-3 s less compilation; the nadir-cap scene 3.5 against 3.9-4.0 million photons/s) and the
rough surface's sampling (0.3 s less; the bare-walk scene at 5 m/s 3.5-4.0 against 3.9-4.2
million photons/s).

A call passes its arguments as a call to any other kernel function does (Numba's calling
convention: arrays by their fields, records by pointer). The argument types at each call site
are checked, when trace_batch is compiled, against the types the function is compiled for
(signature(): from its parameters' names), so a call cannot pass what the function does not
expect. The kernel raises no exceptions (error_model "numpy", no raise statements), so a call's
status is not read. Under NUMBA_DISABLE_JIT the callers call the functions themselves."""
from __future__ import annotations

import inspect

import numba
import numpy as np
from numba.core import cgutils, types
from numba.core.errors import TypingError
from numba.extending import intrinsic

from . import records
from .channels import dispatch as channels

# the functions called by address and their return types, in the order of the table `calls`
OUTLINED = ((channels.emit, types.int64),)


def argument_types() -> dict[str, types.Type]:
    """The Numba type of each kernel argument by its name, the same in every kernel function
    (a record by its component's name, its one-row array by name_row, the scene's pools
    `floats` and `ints`, the packet p and its spectral state ps, ...)."""
    f8 = numba.typeof(np.zeros(1))
    found = {"floats": f8, "ints": numba.typeof(np.zeros(1, dtype=np.int64)),
             "bp": f8, "tally": f8, "tally_row": f8, "ps": f8, "work": f8, "beam_in": f8,
             "angles": f8, "states": numba.typeof(np.zeros((1, 1))),
             "stack_ps": numba.typeof(np.zeros((1, 1))),
             "rng": numba.typeof(np.zeros(1, dtype=np.uint64)),
             "rng_emitted": numba.typeof(np.zeros(1, dtype=np.uint64)),
             "calls": numba.typeof(np.zeros(1, dtype=np.int64)),
             "layer": types.int64, "events": types.int64, "wavelength": types.int64,
             "n_stacked": types.int64, "target": types.int64, "level": types.int64,
             "copies": types.int64, "component": types.int64, "tau": types.float64,
             "w_scattered": types.float64, "from_sky": types.boolean,
             "carrying": types.boolean,
             "n_photons": types.int64, "start": types.int64, "work_budget": types.int64,
             "mu": types.float64}
    for name, dtype in (("medium", records.MEDIUM), ("surface", records.SURFACE),
                        ("bottom", records.BOTTOM), ("sky", records.SKY), ("grid", records.GRID),
                        ("est", records.ESTIMATES), ("ctrl", records.ESTIMATOR),
                        ("packet", records.PACKET)):
        row = numba.typeof(np.zeros(1, dtype=dtype))
        found[name], found[f"{name}_row"] = row.dtype, row
    found["p"], found["stack"] = found["packet"], found["packet_row"]
    return found


def signature(function, found: dict[str, types.Type] | None = None) -> tuple:
    """The argument types of a kernel function, from its parameters' names."""
    found = argument_types() if found is None else found
    python = getattr(function, "py_func", function)   # a plain function under NUMBA_DISABLE_JIT
    return tuple(found[name] for name in inspect.signature(python).parameters)


def address(function) -> int:
    """Where the machine code of an outlined function starts (compiled for signature(), or
    loaded from the disk cache, if it was not yet)."""
    sig = signature(function)
    function.compile(sig)
    compiled = function.overloads[sig]
    return compiled.library.get_pointer_to_function(compiled.fndesc.llvm_func_name)


def addresses() -> np.ndarray:
    """The table `calls` that trace_batch takes: OUTLINED's addresses, in order."""
    if numba.config.DISABLE_JIT:
        return np.arange(len(OUTLINED), dtype=np.int64)
    return np.array([address(function) for function, _ in OUTLINED], dtype=np.int64)


def _caller(slot: int):
    """call(calls, args): OUTLINED[slot]'s function, at the address calls[slot], with the
    arguments args (a tuple)."""
    function, returns = OUTLINED[slot]
    if numba.config.DISABLE_JIT:
        def call(calls, args):
            return function(*args)
        return call

    @intrinsic
    def call(typingctx, calls, args):
        expected = signature(function)
        if tuple(args.types) != expected:
            raise TypingError(f"outline: {function.py_func.__name__} called with "
                              f"{tuple(args.types)}, compiled for {expected}")

        def codegen(context, builder, sig, llargs):
            calls_value, args_value = llargs
            table = context.make_array(sig.args[0])(context, builder, calls_value)
            at = builder.load(cgutils.gep_inbounds(builder, table.data, slot))
            function_type = context.call_conv.get_function_type(returns, expected)
            callee = builder.inttoptr(at, function_type.as_pointer())
            returned = cgutils.alloca_once(builder, function_type.args[0].pointee)
            builder.store(cgutils.get_null_value(function_type.args[0].pointee), returned)
            exception = cgutils.alloca_once(builder, function_type.args[1].pointee)
            values = cgutils.unpack_tuple(builder, args_value, len(expected))
            packed = context.call_conv._get_arg_packer(expected).as_arguments(builder, values)
            builder.call(callee, [returned, exception, *packed])
            return context.get_returned_value(builder, returns, builder.load(returned))

        return returns(calls, args), codegen
    return call


emit = _caller(0)   # OUTLINED[0]
