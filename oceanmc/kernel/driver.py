"""Batches in parallel: prange over the batches of one call; each batch writes only its own slice
of the tally arrays and seeds its own random stream, so results do not depend on the thread count
or on how batches are grouped into calls."""
from numba import njit, prange

from .transport import trace_batch


@njit(parallel=True, error_model="numpy", cache=True)
def run_batches(sc, n_photons, seeds, flux, radiance, local, cap, budget, events):
    for i in prange(seeds.shape[0]):
        events[i] = trace_batch(sc, n_photons, seeds[i], flux[i], radiance[i], local[i],
                                cap[i], budget[i])
