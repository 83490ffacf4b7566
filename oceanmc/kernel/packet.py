"""The photon packet: a PACKET record (kernel/records.py: position, weight, direction, beam flag,
hero and reference wavelengths) and its spectral state, a float row of its own `ps`
(records.packet_state_size). The split stack holds rows of both, so a copy of a packet is
the whole packet at every wavelength.

The spectral state of a walk of n wavelengths (kernel/spectral.py says what each part means):
K (n), G (n), F at the last settle (n), then D, the free path since the last settle. A
one-wavelength walk keeps its whole state in the record (p.w) and reads no row.

With inelastic processes (grid.n_parts > 1 parts of the tally row: the elastic light, then each
process's) a packet carries light of several parts at once: what a process emits at a collision
rides on in the packet that emitted it (kernel/channels/inelastic.py). Every event after that
acts on all of a wavelength's light alike (the walk, the surface, the bottom and every scorer
see only the total), so the row keeps, after D, each part's share of the packet's light at each
wavelength (n_parts x n, summing to 1 at each wavelength; weights()), which changes only when
an emission adds light, and the scorers split what they score by it (tally.deposit).

Only this module knows the row's layout: every other function takes the views of weights()."""
from .compile import internal, kernel


@kernel
def weights(grid, ps):
    """Views of the packet's spectral state: K, G (each wavelength's share of p.w: what a scorer
    multiplies a packet's weight by), F at the last settle (n_wl each), and each part's share
    of the packet's light at each wavelength (part-major, n_parts x n_wl; an empty view where
    all light is of one part: no inelastic processes). The loops over wavelengths index these
    views from 0, which lets LLVM vectorise them (an offset index of unknown sign costs a
    wraparound test per element; measured 2.5x slower)."""
    n = grid.n_wl
    start = 3 * n + 1
    size = grid.n_parts * n if grid.n_parts > 1 else 0
    return ps[:n], ps[n:2 * n], ps[2 * n:3 * n], ps[start:start + size]


@kernel
def free_path_at(grid):
    """Where D, the free path since the last settle, lies in the row."""
    return 3 * grid.n_wl


@kernel
def belong_to(grid, ps, part):
    """All of the packet's light, at every wavelength, is of part `part`."""
    _, _, _, share = weights(grid, ps)
    n = grid.n_wl
    for i in range(share.shape[0]):
        share[i] = 0.0
    if share.shape[0] > 0:
        for j in range(n):
            share[part * n + j] = 1.0


@internal
def launch(p, w, ux, uy, uz, beam):
    """The packet at the surface (z = 0, segment 0) with weight w and direction (ux, uy, uz),
    of the elastic light; beam: it belongs to the collimated solar beam (the spectral state is
    set by spectral.start)."""
    p.z = 0.0
    p.seg = 0
    p.w = w
    p.ux = ux
    p.uy = uy
    p.uz = uz
    p.beam = 1 if beam else 0
    p.part = 0


@internal
def copy(grid, dst, dst_ps, src, src_ps):
    """The whole packet src (record and spectral state) into dst."""
    dst.z = src.z
    dst.w = src.w
    dst.ux = src.ux
    dst.uy = src.uy
    dst.uz = src.uz
    dst.seg = src.seg
    dst.beam = src.beam
    dst.wavelength = src.wavelength
    dst.reference = src.reference
    dst.part = src.part
    if grid.n_wl > 1:
        for j in range(free_path_at(grid) + 1 + weights(grid, src_ps)[3].shape[0]):
            dst_ps[j] = src_ps[j]


@kernel
def divide(grid, p, ps, copies):
    """The packet's weight at every wavelength divided by `copies` (splitting): p.w, and what
    it carried at its last settle (the settle's budget books differences from it); K and G are
    ratios and stay."""
    p.w /= copies
    if grid.n_wl > 1:
        _, _, last, _ = weights(grid, ps)
        for j in range(grid.n_wl):
            last[j] /= copies
