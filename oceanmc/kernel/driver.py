"""Batches in parallel: prange over the batches of one call; each batch writes only its own slice
of the tally arrays and seeds its own random stream, so results do not depend on the thread count
or on how batches are grouped into calls.

The photon loop is specialised by the features a scene uses (features_of): the bit mask is a
compile-time constant (a literal type), so each combination compiles its own loop, once, and the
disk cache keeps it. photon_loop() resolves the specialisation once per run: a plain call with a
literal would go through Numba's slow dispatch path (a failed typing, then a recompilation
attempt from the cache, 14 ms) on every call."""
import math

from numba import literally, njit, prange, typeof
from numba.core import types

from .models import (BOTTOM_BLACK, BOTTOM_NONE, FEATURE_BOTTOM, FEATURE_ESTIMATES,
                     FEATURE_RADIANCE, FEATURE_SKY, FEATURE_SPLITTING, FEATURE_UPWARD)
from .transport import trace_batch


def features_of(sc) -> int:
    """The FEATURE_* bits of the scene arrays: what the photon loop must contain for them."""
    features = 0
    if sc.diffuse_fraction > 0.0:
        features |= FEATURE_SKY
    if sc.bottom_model not in (BOTTOM_NONE, BOTTOM_BLACK):
        features |= FEATURE_BOTTOM
    if sc.tally_radiance:
        features |= FEATURE_RADIANCE
    if sc.local_estimates or sc.cap_estimates:
        features |= FEATURE_ESTIMATES
    if sc.split_weight < math.inf:
        features |= FEATURE_SPLITTING
    if sc.layer_up_fraction.max(initial=0.0) > 0.0:
        features |= FEATURE_UPWARD
    return features


@njit(parallel=True, error_model="numpy", cache=True)
def run_batches(sc, features, n_photons, seeds, flux, radiance, local, cap, budget, events,
                stack):
    features = literally(features)
    for i in prange(seeds.shape[0]):
        events[i] = trace_batch(sc, features, n_photons, seeds[i], flux[i], radiance[i], local[i],
                                cap[i], budget[i], stack[i])


def photon_loop(sc, n_photons, seeds, flux, radiance, local, cap, budget, events, stack):
    """run_batches compiled (or loaded from the cache) for this scene's features and these
    argument types, as a function of (n_photons, seeds, flux, radiance, local, cap, budget,
    events, stack); later calls must pass arrays of the same types (slices of the same
    arrays)."""
    features = features_of(sc)
    if not hasattr(run_batches, "overloads"):  # NUMBA_DISABLE_JIT=1: plain Python
        return lambda *tallies: run_batches(sc, features, *tallies)
    signature = (typeof(sc), types.literal(features)) + tuple(
        typeof(a) for a in (n_photons, seeds, flux, radiance, local, cap, budget, events, stack))
    compiled = run_batches.overloads.get(signature)
    if compiled is None:
        run_batches.compile(signature)
        compiled = run_batches.overloads[signature]
    entry = compiled.entry_point
    return lambda *tallies: entry(sc, features, *tallies)
