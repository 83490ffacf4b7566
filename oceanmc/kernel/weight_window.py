"""Depth importance weight windows: how many copies a packet becomes on entering a segment of
the water column (transport.trace_batch, through split_into), against the segment's window
weight W (the segment's ESTIMATOR row; scene/weight_window.py says how W falls with depth and
why).

The packet's standing is r = w / W, with w its heaviest wavelength's weight in a spectral walk
(settled on the plane: kernel/spectral.py, so that p.w G_j is wavelength j's weight). Above
the window, r > UPPER, it is split into k = min(round(r), MAX_COPIES) copies of w / k, unbiased
whatever k (Kalos & Whitlock, Monte Carlo Methods, 2nd ed. 2008, on splitting); the bounds are
MCNP's weight-window defaults (X-5 Monte Carlo Team, MCNP5 manual vol. I, LA-UR-03-1987, the
WWP card: an upper bound 5 times the lower and a survival weight 3 times it, so 5/3 of the
survival weight; at most 5 splits per event).

Below the window nothing happens at the plane: the roulette at collisions, whose threshold
each segment's row scales by its W (MCNP scales its weight cutoff by the importance in the same
way), ends the packets that have lost weight. A window's own roulette at the planes (survival
w / W below W / 3, as MCNP's) was tried and left out: it brings light scattered up from depth
to the surface as few heavy packets, and on the bench's deep scene with upward bias 0.1 Lu at
0 m needed about 750 s for 1% (one run) against 12-15 s without it.
"""
from . import packet
from .compile import internal

UPPER = 5.0 / 3.0     # split above UPPER W
MAX_COPIES = 5        # copies of one split at most (more follow at the next plane)


@internal
def copies(ctrl, grid, p, ps):
    """How many copies the packet becomes in the segment of row ctrl (1: none)."""
    r = p.w / ctrl.window
    if grid.n_wl > 1:
        _, g, _, _ = packet.weights(grid, ps)
        top = 0.0
        for j in range(grid.n_wl):
            top = max(top, g[j])
        r *= top
    if r <= UPPER:
        return 1
    return min(int(r + 0.5), MAX_COPIES)
