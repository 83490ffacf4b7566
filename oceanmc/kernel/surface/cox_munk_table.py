"""The wind-roughened sea sampled from a table of its facet walk (surface.method `table`).

The walk of cox_munk.py is exact but costs about ten flat-surface events per call. For isotropic
slopes its BSDF depends only on the side the light comes from, the incidence cosine mu_i, and,
for the light leaving, its cosine mu_o and its azimuth relative to the incident plane (symmetric
under phi -> -phi). scene/surface_table.py runs the walk once per (slopes, n_water) at NODES
incidences per side and stores, per side and node:
- R, the probability of reflection (T = 1 - R: every walk leaves on one side, so the table
  neither makes nor loses light);
- per branch (reflected, transmitted), the leaving directions as a 2-D distribution of equal
  probability cells: the quantiles of t_o = sqrt(1 - mu_o) at POLAR_BINS levels, and within
  each polar cell the quantiles of s = tan(dphi / 4) in [0, 1] (dphi in [0, pi] the azimuth
  from the incident plane) at AZIMUTH_BINS levels (a conditional quantile table; the cells
  adapt to the lobes, however narrow). The outermost
  cell of each axis is split TAIL_SPLITS times by halving (refined_bin), so that the sparse
  tails of multiple scattering are not smeared over the outermost 1/64 of the light.

Incidence nodes are uniform in t_i = sqrt(1 - mu_i) (nearly uniform in angle: dtheta/dt =
2/sqrt(2 - t^2)). Between two nodes the branch is chosen with the linearly interpolated R, and
the leaving direction by displacement interpolation (McCann 1997, Adv. Math. 128, 153; as
Bonneel et al. 2011, ACM Trans. Graph. 30(6) 158, do for BRDFs): the quantiles of the two nodes
are interpolated with the branch's share from each node, so a specular lobe moves with the
incidence instead of being blurred into two lobes (the mirror direction t_o = t_i is exact).
Inside a cell t_o and s are uniform: both change smoothly with the angles (dtheta/dt in
[sqrt 2, 2], dphi/ds = 4 / (1 + s^2) in [2, 4]) and give the direction without trigonometric
functions (mu_o = 1 - t^2, sin = t sqrt(2 - t^2); cos and sin of dphi / 2 are (1 - s^2) /
(1 + s^2) and 2 s / (1 + s^2)). The weight is 1, as the walk's."""
import math

from ..compile import batch, kernel
from ..rng import uniform
from .cox_munk import ESCAPED, facet, leave_facet, next_height, wander

NODES = 64                # incidence nodes per side, uniform in sqrt(1 - mu_i), 0 to 90 deg
MU_GRAZING = 2e-3         # the 90 deg node is walked at this cosine (89.9 deg)
POLAR_BINS = 64
AZIMUTH_BINS = 16
TAIL_SPLITS = 9           # the outermost cells split down to 2^-9 of their probability
POLAR_EDGES = POLAR_BINS + 2 * TAIL_SPLITS + 1
AZIMUTH_EDGES = AZIMUTH_BINS + 2 * TAIL_SPLITS + 1
# one (side, node, branch): the polar quantiles, then each polar cell's azimuth quantiles
BLOCK = POLAR_EDGES + (POLAR_EDGES - 1) * AZIMUTH_EDGES
REFLECTANCES = 2 * NODES  # R of (side, node) at side * NODES + node; side 0: from the air
TABLE_SIZE = REFLECTANCES + 2 * NODES * 2 * BLOCK
REFLECTED, TRANSMITTED = 0, 1


def block_at(side: int, node: int, branch: int) -> int:
    """Where the quantiles of (side, node, branch) start in the table."""
    return REFLECTANCES + ((side * NODES + node) * 2 + branch) * BLOCK


@kernel
def refined_bin(v, n):
    """(cell, within): the cell of the uniform draw v in [0, 1) among n equal cells whose first
    and last are each split TAIL_SPLITS times by halving toward the table's ends (n + 2
    TAIL_SPLITS cells; their probabilities: scene/surface_table.py edge_levels), and v's
    position within it, uniform in [0, 1)."""
    x = v * n
    j = min(int(x), n - 1)
    within = x - j
    if j == 0:
        return tail_cell(within)
    if j == n - 1:
        cell, inside = tail_cell(1.0 - within)
        return n + 2 * TAIL_SPLITS - 1 - cell, 1.0 - inside
    return j + TAIL_SPLITS, within


@kernel
def tail_cell(m):
    """(cell, within) of m in [0, 1] among [0, 2^-S), [2^-S, 2^-(S-1)), ..., [1/2, 1]."""
    for s in range(TAIL_SPLITS):
        m *= 2.0
        if m >= 1.0:
            return TAIL_SPLITS - s, m - 1.0
    return 0, m


@kernel
def sample(surface, floats, ux, uy, uz, u, rng):
    """(ox, oy, oz, transmitted) for a photon travelling (ux, uy, uz) that meets the surface
    (from the air when uz > 0), from the table at floats[surface.table]: u chooses the branch
    (reflected when u < R), rng gives the leaving direction."""
    side = 0 if uz > 0.0 else 1
    x = math.sqrt(max(0.0, 1.0 - abs(uz))) * (NODES - 1)
    node = min(int(x), NODES - 2)
    f = x - node
    at = surface.table
    r0 = floats[at + side * NODES + node]
    r1 = floats[at + side * NODES + node + 1]
    transmitted = u >= (1.0 - f) * r0 + f * r1
    if transmitted:
        r0, r1 = 1.0 - r0, 1.0 - r1
    # the branch's share from the upper node (its probability there, weighted by f)
    g = f * r1 / ((1.0 - f) * r0 + f * r1)
    lower = at + REFLECTANCES + ((side * NODES + node) * 2 + transmitted) * BLOCK
    upper = lower + 2 * BLOCK
    cell, within = refined_bin(uniform(rng), POLAR_BINS)
    lo = (1.0 - g) * floats[lower + cell] + g * floats[upper + cell]
    hi = (1.0 - g) * floats[lower + cell + 1] + g * floats[upper + cell + 1]
    t = lo + within * (hi - lo)
    v = 2.0 * uniform(rng)     # its integer part: the azimuth's sign (phi -> -phi symmetry)
    sign = 1.0
    if v >= 1.0:
        sign = -1.0
        v -= 1.0
    row = POLAR_EDGES + cell * AZIMUTH_EDGES
    cell, within = refined_bin(v, AZIMUTH_BINS)
    lo = (1.0 - g) * floats[lower + row + cell] + g * floats[upper + row + cell]
    hi = (1.0 - g) * floats[lower + row + cell + 1] + g * floats[upper + row + cell + 1]
    s = lo + within * (hi - lo)
    inv = 1.0 / (1.0 + s * s)
    c_half = (1.0 - s * s) * inv
    s_half = 2.0 * s * inv
    c = 2.0 * c_half * c_half - 1.0
    sn = sign * 2.0 * s_half * c_half
    mu_o = 1.0 - t * t
    sin_o = t * math.sqrt(max(0.0, 2.0 - t * t))   # sqrt(1 - mu_o^2)
    horizontal = math.sqrt(ux * ux + uy * uy)
    ex, ey = (ux / horizontal, uy / horizontal) if horizontal > 0.0 else (1.0, 0.0)
    oz = mu_o if (uz > 0.0) == transmitted else -mu_o
    return sin_o * (c * ex - sn * ey), sin_o * (sn * ex + c * ey), oz, transmitted


@batch
def walk_node(alpha, n_incident, n_other, mu, walks, strata, rng, branch, t_out, s_out,
              weight_out):
    """The leaving directions of `walks` walks of light travelling at incidence cosine mu into
    an isotropic surface (Beckmann alpha) from the medium of index n_incident, in the table's
    coordinates (t_o = sqrt(1 - mu_o), s = tan(dphi / 4), dphi in [0, pi] the azimuth from
    the incident plane, branch 0 reflected, 1 transmitted), with weights; returns how many
    were written (at most 2 a walk).

    Each walk splits once, at the first facet (expected-value splitting; Kalos & Whitlock,
    Monte Carlo Methods, 2008, 4.3): it goes on both reflected, with weight R_facet, and
    refracted, with weight 1 - R_facet, each continuation a walk of its own (cox_munk.wander).
    The weights of a walk add up to 1, so the table's R is an unbiased estimate of the walk's
    with far less noise: most of R's variance is the first facet's choice (near normal
    incidence from the air, R = 0.02 would otherwise rest on 2% of the walks). The first
    facets are drawn by Latin hypercube sampling (McKay, Beckman & Conover 1979,
    Technometrics 21, 239): walk i draws its facet's three uniforms in strata[d, i] of `walks`
    equal strata (strata[d] a random permutation of 0 .. walks - 1), so each of the three
    is spread evenly over the walks; unbiased, and measured on two tables of different seeds
    at 7 m/s (20,000 walks a node), the light in 10 x 15 deg quads differed by 0.1-0.7%
    instead of 1.2-1.4% at 30 and 60 deg incidence.
    The rest of each walk draws from rng."""
    x0 = math.sqrt(max(0.0, 1.0 - mu * mu))
    count = 0
    for i in range(walks):
        h = next_height(alpha, alpha, ESCAPED, x0, 0.0, -mu, uniform(rng))
        mx, my, mz, cos_i, r, cos_t, ratio = facet(
            alpha, alpha, n_incident, n_other, x0, 0.0, -mu, 1.0,
            (strata[0, i] + uniform(rng)) / walks, (strata[1, i] + uniform(rng)) / walks,
            (strata[2, i] + uniform(rng)) / walks)
        for reflected in (True, False):
            weight = r if reflected else 1.0 - r
            if weight <= 0.0:
                continue
            x, y, z = leave_facet(x0, 0.0, -mu, mx, my, mz, cos_i, cos_t, ratio, reflected)
            x, y, z, side = wander(alpha, alpha, n_incident, n_other, x, y, z, h,
                                   1.0 if reflected else -1.0, 1, uniform(rng), rng)
            branch[count] = REFLECTED if side > 0.0 else TRANSMITTED
            t_out[count] = math.sqrt(max(0.0, 1.0 - abs(z)))
            s_out[count] = math.tan(0.25 * math.atan2(abs(y), x))
            weight_out[count] = weight
            count += 1
    return count
