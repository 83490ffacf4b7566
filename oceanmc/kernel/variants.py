"""Which optional parts of the photon loop a compiled trace_batch holds.

trace_batch and its events take one argument per optional part (PARTS; named with_<part> in
their signatures). True compiles the part in: the scene's records then decide at run time
whether it runs, as they always have. None compiles it out: Numba types the argument as
NoneType, and its dead-branch pruning decides `with_<part> is not None` at compile time (an
untyped pass, numba.core.analysis.dead_branch_prune: a comparison of a function argument of
NoneType with None), so that what the pruned branch calls is neither compiled nor linked into
trace_batch. A scene runs on any variant that holds every part it uses, with the same draws and
the same arithmetic in the same order: its results are the same bit for bit (tests/
test_variants.py).

Why: one trace_batch holding every part took 64-73 s to compile on a cold start (ready(), 2
cores, 2026-11-27; trace_batch's own LLVM work alone 34 s), most of it for parts that a given
scene never runs; run/compiling.py has the figures per variant."""
from __future__ import annotations

from typing import NamedTuple


class Variant(NamedTuple):
    spectral: bool = True            # several wavelengths in one history (spectral.py)
    inelastic: bool = True           # Raman scattering and fluorescence (channels/inelastic.py)
    rough_surface: bool = True       # the rough sea's sampling (surface/: table or facet walk)
    reflecting_bottom: bool = True   # a bottom that reflects (brdf/, its local estimates)
    local_estimates: bool = True     # local (next-event) estimates (local_estimate.py)

    def kernel_args(self) -> tuple:
        """The with_<part> arguments of trace_batch, in order: True or None."""
        return tuple(True if on else None for on in self)

    def holds(self, other: Variant) -> bool:
        """Whether every part of `other` is compiled in here."""
        return all(mine or not theirs for mine, theirs in zip(self, other))

    def supersets(self) -> list[Variant]:
        """Every variant that holds this one, this one first, then by how few parts they add
        (the nearest first)."""
        free = [k for k, on in enumerate(self) if not on]
        found = []
        for mask in range(1 << len(free)):
            parts = list(self)
            for bit, k in enumerate(free):
                if mask >> bit & 1:
                    parts[k] = True
            found.append(Variant(*parts))
        return sorted(found, key=sum)

    @property
    def label(self) -> str:
        """The parts compiled in, for messages ('plain' for none)."""
        return ", ".join(name.replace("_", " ") for name, on in zip(self._fields, self)
                         if on) or "plain"


PARTS = Variant._fields
EVERYTHING = Variant()


def union(variants) -> Variant:
    """The variant holding every part of each of `variants` (none: the plain loop)."""
    variants = list(variants)
    return Variant(*(any(v[k] for v in variants) for k in range(len(PARTS))))
