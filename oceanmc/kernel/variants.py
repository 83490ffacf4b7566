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
scene never runs; run/compiling.py has the figures per variant. The rough sea's facet walk,
the bottoms beyond the closed-form four and the exact directions' local estimates became parts
of their own on 2026-11-28: leaving them out took 1-5 s off cold starts of the shipped
configs that do not use them (benchmarks/speed.md; run/compiling.py)."""
from __future__ import annotations

from typing import NamedTuple

from .models import (BOTTOM_LAMBERTIAN, BOTTOM_LAMBERTIAN_SPECULAR, BOTTOM_MINNAERT,
                     BOTTOM_SPECULAR)


class Variant(NamedTuple):
    spectral: bool = True            # several wavelengths in one history (spectral.py)
    inelastic: bool = True           # Raman scattering and fluorescence (channels/inelastic.py)
    rough_surface: bool = True       # the rough sea, sampled from its table (surface/)
    facet_walk: bool = True          # ... or by its facet walk (surface.method: walk)
    reflecting_bottom: bool = True   # a bottom that reflects (brdf/, its local estimates):
    #   Lambertian, Minnaert, specular, Lambertian + specular
    detailed_bottom: bool = True     # ... or GGX, Hapke, a measured table, or any BRDF sampled
    #   by table (brdf/general.py)
    local_estimates: bool = True     # local (next-event) estimates (local_estimate.py): the
    #   nadir cap's
    exact_directions: bool = True    # ... and those in exact directions
    #   (tallies.local_directions_deg)

    def kernel_args(self) -> tuple:
        """The with_<part> arguments of trace_batch, in order: True or None."""
        return tuple(True if on else None for on in self)

    @property
    def consistent(self) -> bool:
        """Whether every refinement (REFINES) comes with the part it refines: the others are
        never asked for."""
        return all(not getattr(self, refinement) or getattr(self, part)
                   for refinement, part in REFINES.items())

    def holds(self, other: Variant) -> bool:
        """Whether every part of `other` is compiled in here."""
        return all(mine or not theirs for mine, theirs in zip(self, other))

    def supersets(self) -> list[Variant]:
        """Every consistent variant that holds this one, this one first, then by how few parts
        they add (the nearest first)."""
        free = [k for k, on in enumerate(self) if not on]
        found = []
        for mask in range(1 << len(free)):
            parts = list(self)
            for bit, k in enumerate(free):
                if mask >> bit & 1:
                    parts[k] = True
            if Variant(*parts).consistent:
                found.append(Variant(*parts))
        return sorted(found, key=sum)

    @property
    def label(self) -> str:
        """The parts compiled in, for messages ('plain' for none)."""
        return ", ".join(name.replace("_", " ") for name, on in zip(self._fields, self)
                         if on) or "plain"


PARTS = Variant._fields
EVERYTHING = Variant()
# parts that only add to another (a scene that uses one uses the other): a variant with the
# one compiles the other in
REFINES = {"facet_walk": "rough_surface", "detailed_bottom": "reflecting_bottom",
           "exact_directions": "local_estimates"}
# the bottoms that reflecting_bottom alone runs, by their own samplers (brdf/dispatch.py);
# every other reflecting bottom, and any bottom sampled by table, needs detailed_bottom
CLOSED_FORM_BOTTOMS = (BOTTOM_LAMBERTIAN, BOTTOM_MINNAERT, BOTTOM_SPECULAR,
                       BOTTOM_LAMBERTIAN_SPECULAR)


def union(variants) -> Variant:
    """The variant holding every part of each of `variants` (none: the plain loop)."""
    variants = list(variants)
    return Variant(*(any(v[k] for v in variants) for k in range(len(PARTS))))
