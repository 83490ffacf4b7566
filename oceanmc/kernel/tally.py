"""Plane-crossing tallies, the one crossing scorer: a photon of weight w crossing a level with
direction cosine mu adds w to Ed or Eu, w/|mu| to Eod or Eou and to the radiance of its quad
(normalised by the quad's solid angle and the photon count later, in run/derivation.py). Grazing
crossings use the surface-flux rule: 1/|mu| is replaced by 2/mu_cut when |mu| < mu_cut, which is
exact when the radiance is constant over |mu| < mu_cut and keeps the variance finite (MCNP
manual, F2 surface flux tally).

Tallies as OpenMC thinks of them: filters (level, theta band, phi band) times scores (Ed, Eu,
Eod, Eou, radiance), in one flat row per batch (kernel/records.py, GRID). Levels: the in-water
tally depths first, then grid.air_level (0+, all light) and grid.air_level + 1 (0+, water-leaving
light only).

Spectral scenes (kernel/spectral.py) hold every score with its wavelengths side by side
(spectral_at); score() adds a packet's weight to each wavelength, times the wavelength's share q
of it. With inelastic processes the row holds one copy of every score per part (the elastic
light's, then each process's); a packet's light at a wavelength may be of several parts at
once (kernel/packet.py shares), and every spectral scorer adds it through deposit(), which
splits it by the parts' shares."""
import math

from .compile import hot, internal, kernel
from .models import FLUX_ED, FLUX_EOD, FLUX_EOU, FLUX_EU
from .search import interval
from .packet import weights


@kernel
def theta_band(uz, mu_edges):
    """Index i with mu_edges[i] >= uz > mu_edges[i + 1] (mu_edges falls from 1 to -1)."""
    return interval(mu_edges, 0, 0, mu_edges.shape[0] - 1, uz, falling=True)


@kernel
def theta_band_fast(grid, floats, ints, uz):
    """theta_band by table: theta_lookup[k] is the band of the top of the k-th of M equal cells
    of uz in [-1, 1]; lower values in the same cell can only be in that band or a later one, so
    a short walk down the edges finishes the job exactly."""
    m = grid.n_lookup
    k = min(m - 1, int((uz + 1.0) * (0.5 * m)))
    band = ints[grid.theta_lookup + k]
    last = grid.n_theta - 1
    while band < last and uz <= floats[grid.theta_mu_edges + band + 1]:
        band += 1
    return band


@kernel
def phi_band(ux, uy, n_phi):
    """Band index with band 0 centred on phi = 0 (the sun's travel azimuth)."""
    phi = math.atan2(uy, ux)
    k = int(math.floor(phi * n_phi / (2.0 * math.pi) + 0.5))
    return k % n_phi


@kernel
def phi_band_fast(grid, floats, ux, uy):
    """phi_band without atan2: a polynomial guess of the azimuth (error < 0.0038 rad; Rajan et
    al. 2006, IEEE Signal Process. Mag. 23(3)). The bands are equal, so a guess farther than
    0.0063 rad (0.001 n bands) from an edge is the band; near an edge, exact tests against the
    edge directions (sign of the 2-D cross product) move it to the right band."""
    n = grid.n_phi
    if n <= 2:
        return phi_band(ux, uy, n)
    ax = abs(ux)
    ay = abs(uy)
    if ax >= ay:
        r = ay / ax if ax > 0.0 else 0.0
        angle = r * (0.25 * math.pi + 0.273 * (1.0 - r))
    else:
        r = ax / ay
        angle = 0.5 * math.pi - r * (0.25 * math.pi + 0.273 * (1.0 - r))
    if ux < 0.0:
        angle = math.pi - angle
    if uy < 0.0:
        angle = -angle
    x = angle * n / (2.0 * math.pi) + 0.5
    k = int(math.floor(x))
    frac = x - k
    k = k + n if k < 0 else (k - n if k >= n else k)
    if 0.001 * n < frac < 1.0 - 0.001 * n:
        return k
    # band k lies between edge k (inclusive) and edge k + 1 (exclusive), counterclockwise
    cos_at = grid.phi_edge_cos
    sin_at = grid.phi_edge_sin
    while floats[cos_at + k] * uy - floats[sin_at + k] * ux < 0.0:
        k = k - 1 if k > 0 else n - 1
    while True:
        up = k + 1 if k + 1 < n else 0
        if floats[cos_at + up] * uy - floats[sin_at + up] * ux < 0.0:
            return k
        k = up


@kernel
def inverse_mu(uz, mu_cut, beam):
    """1/|mu|, or 2/mu_cut below the cut for diffuse light. A collimated beam (the unscattered
    sun) always gets the exact 1/|mu|: every packet of it has the same mu, so there is no
    variance to tame, and the rule's assumption (radiance constant near the horizon) fails."""
    amu = abs(uz)
    return 1.0 / amu if (amu >= mu_cut or beam) else 2.0 / mu_cut


@kernel
def spectral_at(grid, index):
    """Where wavelength 0's value of score `index` (its offset in one wavelength's layout: the
    GRID record's offsets) lies in a spectral row: each score's n_wl wavelengths side by side
    from there, so scoring every wavelength of a packet writes one short stretch of memory
    (records.py, GRID)."""
    return grid.scores + (index - grid.scores) * grid.n_wl


@internal
def deposit(grid, tally, share, at, j, value):
    """Adds `value`, light of wavelength j, to the score whose wavelength-j element is at `at`
    in the first part of the row `tally`: all of it there when `share` is empty (light of one
    part: `tally` starts at that part), else each part's share of it (share[part * n_wl + j],
    packet.shares) to that part's copy of the score."""
    if share.shape[0] == 0:
        tally[at + j] += value
        return
    n = grid.n_wl
    size = grid.part_size
    for part in range(grid.n_parts):
        tally[part * size + at + j] += value * share[part * n + j]


@internal
def deposit_all(grid, tally, share, at, w, values):
    """deposit() of w times values[j] at every wavelength j (deposit_range from wavelength 0)."""
    deposit_range(grid, tally, share, at, 0, w, values)


@internal
def move_all(grid, tally, share, source_at, target_at, values):
    """values[j] at every wavelength j moved from the score at source_at to the one at
    target_at, split by the parts' shares as deposit() splits: deposit_all(-1) at the one and
    deposit_all(1) at the other, bit for bit ((-v) s = -(v s)), in one pass over the shares
    (an inelastic collision's take moves from its layer's absorption to shifted out: two
    passes took 8.5% of the inelastic bench's run by perf). A scene with inelastic light always
    has parts, so the shares are never empty here."""
    n = grid.n_wl
    size = grid.part_size
    for part in range(grid.n_parts):
        source = tally[part * size + source_at:part * size + source_at + n]
        target = tally[part * size + target_at:part * size + target_at + n]
        part_share = share[part * n:(part + 1) * n]
        for j in range(n):
            moved = values[j] * part_share[j]
            source[j] -= moved
            target[j] += moved


@internal
def deposit_range(grid, tally, share, at, first, w, values):
    """deposit() of w times values[j] at wavelengths first + j, j < len(values), one part
    after the other: each part's loop runs over contiguous wavelengths of the score and of the
    shares, through views that start at 0, which LLVM vectorises (one deposit() per
    wavelength loops over the parts inside and does not; measured on the inelastic bench's
    scene: splitting the scores by part took half the run's time). Every element receives the
    same one addition as from deposit()."""
    count = values.shape[0]
    if share.shape[0] == 0:
        row = tally[at + first:at + first + count]
        for j in range(count):
            row[j] += w * values[j]
        return
    n = grid.n_wl
    size = grid.part_size
    for part in range(grid.n_parts):
        start = part * size + at + first
        row = tally[start:start + count]
        part_share = share[part * n + first:part * n + first + count]
        for j in range(count):
            row[j] += (w * values[j]) * part_share[j]


@hot
def score(grid, tally, ps, index, w):
    """Adds weight w to score `index` (its offset in one wavelength's layout), and in a
    spectral scene w times each wavelength's share q of the packet (ps: its spectral state,
    kernel/packet.py) to that wavelength's."""
    if grid.n_wl == 1:
        tally[index] += w
        return
    _, q, _, share = weights(grid, ps)
    deposit_all(grid, tally, share, spectral_at(grid, index), w, q)


@kernel
def score_crossing(grid, floats, ints, tally, ps, level, w, ux, uy, uz, beam):
    """A crossing of tally level `level` (an in-water depth, or one of the air levels after
    them) by a packet of spectral state ps; beam: the packet is still part of the collimated
    solar beam."""
    w_over_mu = w * inverse_mu(uz, grid.mu_cut, beam)
    at = grid.flux + 4 * level
    plane = at + (FLUX_ED if uz > 0.0 else FLUX_EU)
    scalar = at + (FLUX_EOD if uz > 0.0 else FLUX_EOU)
    quad = -1
    if grid.radiance_on:
        band = theta_band_fast(grid, floats, ints, uz)
        col = 0 if ints[grid.theta_is_cap + band] else phi_band_fast(grid, floats, ux, uy)
        quad = grid.radiance + (level * grid.theta_cols + band) * grid.phi_cols + col
    if grid.n_wl == 1:
        tally[plane] += w
        tally[scalar] += w_over_mu
        if quad >= 0:
            tally[quad] += w_over_mu
        return
    _, q, _, share = weights(grid, ps)
    deposit_all(grid, tally, share, spectral_at(grid, plane), w, q)
    deposit_all(grid, tally, share, spectral_at(grid, scalar), w_over_mu, q)
    if quad >= 0:
        deposit_all(grid, tally, share, spectral_at(grid, quad), w_over_mu, q)
