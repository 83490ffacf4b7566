"""Tabulated phase functions, built once per scene for the kernel's tabulated sampler.

Every tabulated phase function is stored the same way: nodes psi_j (scattering angle, rad, from 0
to pi) and q_j = 2 pi p(psi_j) sin(psi_j), the probability density per unit angle. q is taken as
piecewise linear between nodes (the convention of the Petzold table's header, Mobley et al. 1993),
its exact cumulative integral is the CDF, and the kernel inverts it exactly (a quadratic per
interval). The table is renormalised to a total probability of 1.
"""
from __future__ import annotations

import math
import tokenize
import zipfile
import zlib
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

from ..config import ConfigError
from ..config.loading import file_problem, read_table_text


class TableError(ConfigError):
    """An auxiliary table that cannot be used; the message names the file and the problem."""


def cumulative(psi: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Exact integral of the piecewise-linear q from 0 to each node, normalised to end at 1."""
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (q[1:] + q[:-1]) * np.diff(psi))])
    return cdf / cdf[-1]


def guide(cdf: np.ndarray) -> np.ndarray:
    """The sampler's guide table (kernel/phase/tabulated.py): with G = len(cdf) - 1 cells of
    equal probability, entry k is the interval i that holds k / G (cdf[i] <= k / G < cdf[i +
    1]; the last interval for k = G)."""
    cells = len(cdf) - 1
    at = np.searchsorted(cdf, np.arange(cells + 1) / cells, side="right") - 1
    return np.clip(at, 0, cells - 1).astype(np.int64)


def normalised(psi: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(psi, q, cdf) with q scaled so that its piecewise-linear integral is 1."""
    total = float(np.sum(0.5 * (q[1:] + q[:-1]) * np.diff(psi)))
    q = q / total
    return psi, q, cumulative(psi, q)


def moments(psi: np.ndarray, q: np.ndarray) -> tuple[float, float]:
    """(g, bb/b) of a normalised table, integrating the piecewise-linear density finely."""
    fine = np.linspace(0.0, 1.0, 65)
    g = 0.0
    bb = 0.0
    for j in range(len(psi) - 1):
        x = psi[j] + fine * (psi[j + 1] - psi[j])
        dens = q[j] + fine * (q[j + 1] - q[j])
        g += np.trapezoid(dens * np.cos(x), x)
        back = x >= 0.5 * math.pi
        if back.any():
            bb += np.trapezoid(np.where(back, dens, 0.0), x)
    return float(g), float(bb)


# --- Petzold average particle -----------------------------------------------------------------

PETZOLD_SMALL_ANGLE_DEG = 0.12589
PETZOLD_SMALL_ANGLE_SLOPE = 1.346


@lru_cache(maxsize=None)
def petzold_table() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Petzold's average-particle phase function (Mobley et al. 1993, Table 2), as the header of
    the data file defines it: 2 pi p sin psi piecewise linear between the tabulated nodes, and
    p = p(0.12589 deg) (0.12589 deg/psi)^1.346 below the first node, resolved on log-spaced
    nodes down to 1e-6 deg. g = 0.924, bb/b = 0.0181."""
    angle_deg, p = read_angle_table(resources.files("oceanmc") / "data" / "petzold_average_particle.csv")
    p_ref = np.interp(PETZOLD_SMALL_ANGLE_DEG, angle_deg, p)
    small = np.geomspace(1e-6, angle_deg[0], 40)[:-1]
    p_small = p_ref * (PETZOLD_SMALL_ANGLE_DEG / small) ** PETZOLD_SMALL_ANGLE_SLOPE
    psi = np.radians(np.concatenate([[0.0], small, angle_deg]))
    pp = np.concatenate([[0.0], p_small, p])
    return normalised(psi, 2.0 * math.pi * pp * np.sin(psi))


# --- Fournier-Forand --------------------------------------------------------------------------

def fournier_forand_p(psi: np.ndarray, n: float, mu: float) -> np.ndarray:
    """Fournier-Forand phase function (Fournier & Jonasz 1999; Mobley, Ocean Optics Web Book,
    'The Fournier-Forand phase function', Eq. 1), 1/sr. n: particle index, mu: Junge slope."""
    nu = 0.5 * (3.0 - mu)
    s2 = np.sin(0.5 * psi) ** 2
    k = 4.0 / (3.0 * (n - 1.0) ** 2)
    delta = k * s2
    d180 = k
    with np.errstate(divide="ignore", invalid="ignore"):
        main = (nu * (1.0 - delta) - (1.0 - delta ** nu)
                + (delta * (1.0 - delta ** nu) - nu * (1.0 - delta)) / s2)
        main /= 4.0 * math.pi * (1.0 - delta) ** 2 * delta ** nu
    back = (1.0 - d180 ** nu) / (16.0 * math.pi * (d180 - 1.0) * d180 ** nu) \
        * (3.0 * np.cos(psi) ** 2 - 1.0)
    return main + back


def fournier_forand_bb(n: float, mu: float) -> float:
    """Backscatter fraction of FF (same reference, Eq. 3)."""
    nu = 0.5 * (3.0 - mu)
    d90 = 4.0 / (3.0 * (n - 1.0) ** 2) * math.sin(math.pi / 4.0) ** 2
    return 1.0 - (1.0 - d90 ** (nu + 1.0) - 0.5 * (1.0 - d90 ** nu)) / ((1.0 - d90) * d90 ** nu)


def fournier_forand_parameters(bb_ratio: float) -> tuple[float, float]:
    """(n, mu) giving the backscatter fraction, along Mobley et al. (2002)'s line
    n = 1.01 + 0.1542 (mu - 3)."""
    def excess(mu: float) -> float:
        return fournier_forand_bb(1.01 + 0.1542 * (mu - 3.0), mu) - bb_ratio
    from scipy.optimize import brentq  # here: scipy.optimize takes 0.4 s to import
    mu = brentq(excess, 3.0005, 5.5, xtol=1e-12)
    return 1.01 + 0.1542 * (mu - 3.0), mu


@lru_cache(maxsize=64)
def fournier_forand_table(bb_ratio: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """FF on 3500 nodes, log-spaced from 1e-10 rad to 0.2 rad, then linear to pi. FF integrates to
    exactly 1 (Fournier & Jonasz 1999), so the probability below the first node (up to 5% for
    bb/b = 5e-4, a forward spike no instrument resolves) is put in the first interval [0, 1e-10]
    rather than lost: the table keeps FF's backscatter fraction to 1e-4 relative."""
    n, mu = fournier_forand_parameters(bb_ratio)
    psi = np.concatenate([[0.0], np.geomspace(1e-10, 0.2, 2500),
                          np.linspace(0.2, math.pi, 1001)[1:]])
    q = 2.0 * math.pi * fournier_forand_p(psi, n, mu) * np.sin(psi)
    above_first = float(np.sum(0.5 * (q[2:] + q[1:-1]) * np.diff(psi[1:])))
    q[0] = max(0.0, 2.0 * (1.0 - above_first) / psi[1] - q[1])
    return normalised(psi, q)


# --- user tables ------------------------------------------------------------------------------


MAX_TABLE_VALUES = 10**8   # 800 MB of float64: far beyond any table, refused before loading
# what a malformed array file raises in the readers below; callers turn it into a TableError
# (numpy parses an .npy header with ast.literal_eval: a mangled one raises SyntaxError or
# tokenize.TokenError; a mangled deflated member zlib.error)
ARRAY_FILE_ERRORS = (OSError, ValueError, EOFError, TypeError, KeyError, zipfile.BadZipFile,
                     NotImplementedError, SyntaxError, tokenize.TokenError, RecursionError,
                     zlib.error)


def is_real(a: np.ndarray) -> bool:
    """Whether an array holds real numbers: integers or floats, not text, booleans, objects or
    complex numbers (whose imaginary parts a conversion to float would drop)."""
    return np.issubdtype(a.dtype, np.number) and not np.iscomplexobj(a)


def bounded_npy(file, name: str) -> np.ndarray:
    """The array of an .npy stream, its header's shape checked against MAX_TABLE_VALUES first
    (a header may claim 10^10 values in a file of a few bytes)."""
    readers = {(1, 0): np.lib.format.read_array_header_1_0,
               (2, 0): np.lib.format.read_array_header_2_0}
    version = np.lib.format.read_magic(file)
    if version not in readers:
        raise ValueError(f"{name}: .npy format version {version} not supported")
    shape, _, _ = readers[version](file)
    if math.prod(shape) > MAX_TABLE_VALUES:
        raise ValueError(f"{name}: its header claims shape {shape}, more than "
                         f"{MAX_TABLE_VALUES:,} values")
    file.seek(0)
    return np.lib.format.read_array(file, allow_pickle=False)


def npz_arrays(path: Path) -> dict[str, np.ndarray]:
    """The arrays of an .npz archive, each bounded as in bounded_npy."""
    data = {}
    with zipfile.ZipFile(path) as archive:
        for member in archive.namelist():
            with archive.open(member) as file:
                data[member.removesuffix(".npy")] = bounded_npy(file, member)
    return data


def hdf5_arrays(path: Path) -> dict[str, np.ndarray]:
    """The top-level datasets of an HDF5 file; soft and external links are not followed (they
    may dangle or leave the file), sizes are bounded as in bounded_npy."""
    import h5py
    data = {}
    with h5py.File(path, "r") as h5:
        for k in h5.keys():
            if not isinstance(h5.get(k, getlink=True), h5py.HardLink) or \
                    not isinstance(h5[k], h5py.Dataset):
                continue
            if h5[k].size > MAX_TABLE_VALUES:
                raise ValueError(f"{k} holds {h5[k].size:,} values, more than "
                                 f"{MAX_TABLE_VALUES:,}")
            data[k] = np.asarray(h5[k][()])
    return data


def numeric_rows(path: Path, what: str) -> list[tuple[int, list[float]]]:
    """(line number, values) of each data line of a text table: comma or whitespace separated,
    '#' comments and blank lines skipped, one non-numeric header line allowed before the data.
    Problems are TableErrors that start with `what` and the file."""
    try:
        text = read_table_text(path, f"{what} {path}")
    except ConfigError as exc:
        raise TableError(str(exc)) from None
    rows = []
    header = False
    for lineno, line in enumerate(text.splitlines(), 1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        try:
            rows.append((lineno, [float(x) for x in line.replace(",", " ").split()]))
        except ValueError:
            if rows or header:   # a second header line would drop a bad first data row
                raise TableError(f"{what} {path}, line {lineno}: not a number in "
                                 f"{line!r}") from None
            header = True
    return rows


# how far short of 0 and 180 deg a phase function table may stop: its ends are extrapolated
# (user_table), which near 180 deg is close to exact (p nearly flat there, 2 pi p sin psi then
# linear) but at the forward end misses what a peak puts there (Petzold's table starts at
# 0.1 deg); a table that stops further out is refused as partial: one of a hemisphere would
# have the other invented
MAX_FIRST_ANGLE_DEG = 10.0
MIN_LAST_ANGLE_DEG = 170.0


def read_angle_table(path) -> tuple[np.ndarray, np.ndarray]:
    """(angle_deg, p) from a two-column file: scattering angle (deg, 0..180, strictly increasing)
    and phase value (>= 0, any scale). Comma or whitespace separated; lines starting with '#' and a
    non-numeric header line are skipped. Every problem is a TableError naming the file."""
    path = Path(str(path))
    problem = file_problem(path)
    if problem:
        raise TableError(f"phase table {path}: {problem}")
    rows = []
    for lineno, values in numeric_rows(path, "phase table"):
        if len(values) != 2:
            raise TableError(f"phase table {path}, line {lineno}: expected 2 columns (angle_deg, "
                             f"value), got {len(values)}")
        rows.append(values)
    if len(rows) < 2:
        raise TableError(f"phase table {path}: needs at least 2 rows (angle_deg, value), "
                         f"got {len(rows)}")
    table = np.array(rows)
    angle, p = table[:, 0], table[:, 1]
    if not np.all(np.isfinite(table)):
        raise TableError(f"phase table {path}: contains NaN or inf")
    if angle[0] < 0.0 or angle[-1] > 180.0:
        raise TableError(f"phase table {path}: angles must lie in 0..180 deg, got "
                         f"{angle[0]}..{angle[-1]}")
    if np.any(np.diff(angle) <= 0.0):
        bad = int(np.argmin(np.diff(angle) > 0.0)) + 1
        raise TableError(f"phase table {path}: angles must increase strictly (row {bad + 1}: "
                         f"{angle[bad]} after {angle[bad - 1]})")
    if angle[0] > MAX_FIRST_ANGLE_DEG or angle[-1] < MIN_LAST_ANGLE_DEG:   # (see the limits)
        raise TableError(f"phase table {path}: its angles run {angle[0]:g}..{angle[-1]:g} deg; "
                         f"a phase function table must reach from at most "
                         f"{MAX_FIRST_ANGLE_DEG:g} deg to at least {MIN_LAST_ANGLE_DEG:g} deg "
                         "(beyond its ends 2 pi p sin(psi) goes linearly to 0 at 0 and 180 deg)")
    if np.any(p < 0.0):
        raise TableError(f"phase table {path}: negative phase value {p[p < 0][0]}")
    return angle, p


def user_table(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A user's phase function table (see read_angle_table for the format). Between nodes
    2 pi p sin psi is piecewise linear, as for Petzold; missing ends at 0 and 180 deg get q = 0."""
    angle, p = read_angle_table(path)
    psi = np.radians(angle)
    peak = float(np.max(p))
    # the scale of p is normalised away; dividing by its peak first keeps a table of values
    # near 1e308 from overflowing to inf in 2 pi p sin psi and in the integral
    q = 2.0 * math.pi * (p / peak if peak > 0.0 else p) * np.sin(psi)
    if psi[0] > 0.0:
        psi, q = np.concatenate([[0.0], psi]), np.concatenate([[0.0], q])
    if psi[-1] < math.pi:
        psi, q = np.concatenate([psi, [math.pi]]), np.concatenate([q, [0.0]])
    if np.sum(0.5 * (q[1:] + q[:-1]) * np.diff(psi)) <= 0.0:
        raise TableError(f"phase table {path}: the phase function integrates to zero")
    return normalised(psi, q)
