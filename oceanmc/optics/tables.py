"""Spectral tables: the published ones shipped in oceanmc/data (each file's header cites its
source) and users' CSVs, read once (again when the file changes) and interpolated linearly in
wavelength. A wavelength outside a table's range is a ConfigError naming the key, the table and
its range."""
from __future__ import annotations

import os
from functools import lru_cache
from importlib import resources

import numpy as np

from ..config import ConfigError
from ..config.loading import read_table_text

def read_csv(path: str) -> dict[str, np.ndarray]:
    """The columns of a CSV with '#' comment lines and one header line of column names; parsed
    again whenever the file changes (a table edited between two runs of one process is read
    anew, as its recorded hash says)."""
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such file") from None
    except (OSError, ValueError) as exc:
        raise ConfigError(f"{path}: cannot read it ({getattr(exc, 'strerror', None) or exc})"
                          ) from None
    return _parsed_csv(path, info.st_mtime_ns, info.st_size, info.st_ino)


@lru_cache(maxsize=256)
def _parsed_csv(path: str, mtime_ns: int, size: int, inode: int) -> dict[str, np.ndarray]:
    """read_csv's table, remembered by the file's path, modification time, size and inode."""
    lines = read_table_text(path, path).splitlines()
    rows = [line for line in lines if line.strip() and not line.lstrip().startswith("#")]
    if len(rows) < 2:
        raise ConfigError(f"{path}: needs a header line of column names and at least one row")
    names = [n.strip() for n in rows[0].split(",")]
    other = next((name for sep, name in ((";", "semicolons"), ("\t", "tabs"))
                  if len(names) == 1 and sep in rows[0]), None)
    if other:
        raise ConfigError(f"{path}: the header {rows[0].strip()!r} is one column: its columns "
                          f"are separated by {other}; allowed: columns separated by commas")
    twice = [n for k, n in enumerate(names) if n in names[:k]]
    if twice:
        raise ConfigError(f"{path}: column {twice[0]!r} appears twice in the header; allowed: "
                          "each column once")
    values = [_numbers(row) for row in rows[1:]]
    bad = next((row for row, numbers in zip(rows[1:], values) if numbers is None), None)
    if bad is not None:
        raise ConfigError(f"{path}: row {bad.strip()!r}: every row after the header must be "
                          f"{len(names)} number{'s' if len(names) > 1 else ''} separated by "
                          "commas")
    uneven = next((row for row, numbers in zip(rows[1:], values)
                   if len(numbers) != len(names)), None)
    if uneven is not None:
        raise ConfigError(f"{path}: row {uneven.strip()!r}: every row must have {len(names)} "
                          f"values ({', '.join(names)})")
    data = np.array(values)
    data.flags.writeable = False   # the remembered table is shared by every reader
    return {name: data[:, k] for k, name in enumerate(names)}


def _numbers(row: str) -> list[float] | None:
    """The row's comma-separated numbers; None if a field is not a number."""
    try:
        return [float(x) for x in row.split(",")]
    except ValueError:
        return None


@lru_cache(maxsize=None)
def packaged(name: str) -> dict[str, np.ndarray]:
    """A table shipped in oceanmc/data."""
    return read_csv(str(resources.files("oceanmc") / "data" / name))


def read_table(path: str, where: str, ranges: dict[str, tuple[float, float, str]],
               rows: int = 1) -> dict[str, np.ndarray]:
    """A user's CSV with the columns named in `ranges` ({name: (lowest, highest, unit)}; the
    first is the one interpolated along and must increase strictly) and at least `rows` rows;
    every value finite and within its column's range, so that nothing computed from them
    overflows. Every problem is one line naming the key, the file, the value and what is
    allowed."""
    try:
        table = read_csv(path)
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None
    missing = [c for c in ranges if c not in table]
    if missing:
        raise ConfigError(f"{where}: {path} lacks the column(s) {', '.join(missing)}; needed: "
                          f"{', '.join(ranges)} (found: {', '.join(table)})")
    axis = next(iter(ranges))
    nodes = table[axis]
    if len(nodes) < rows:
        raise ConfigError(f"{where}: {path} has {len(nodes)} row of {axis}; allowed: at least "
                          f"{rows}")
    for name, (low, high, unit) in ranges.items():
        values = table[name]
        outside = ~(np.isfinite(values) & (values >= low) & (values <= high))
        if outside.any():
            k = int(np.argmax(outside))
            at = f"row {k + 1}" if name == axis else f"{axis} = {nodes[k]:g}"
            raise ConfigError(f"{where}: {path}: {name} = {values[k]:g} at {at}; allowed: "
                              f"{low:g} .. {high:g}{' ' + unit if unit else ''}")
    falling = np.diff(nodes) <= 0.0
    if falling.any():
        k = int(np.argmax(falling))
        raise ConfigError(f"{where}: {path}: {axis} = {nodes[k + 1]:g} follows {nodes[k]:g}; "
                          f"allowed: strictly increasing")
    return table


class OutsideTable(ConfigError):
    """A wavelength outside a table's range (interpolate); `wavelength` says which, so that a
    caller can say where that wavelength came from (its default lets pickle rebuild it from
    the message, as a sweep's worker sends it)."""

    def __init__(self, message: str, wavelength: float = float("nan")) -> None:
        super().__init__(message)
        self.wavelength = wavelength

    def explained(self, added: list[float]) -> str:
        """The message, saying where the wavelength came from when the run added it for the
        excitation of inelastic light (`added`: SceneConfig.added_wavelengths), which the user
        never asked for."""
        if not any(np.isclose(self.wavelength, w) for w in added):
            return str(self)
        return (f"{self} (traced for the excitation of water.inelastic, which adds "
                f"{min(added):g}-{max(added):g} nm; ask for longer wavelengths, or give a table "
                "that covers these)")


def interpolate(wavelengths: np.ndarray, nodes: np.ndarray, values: np.ndarray, where: str,
                what: str) -> np.ndarray:
    """Linear interpolation; every wavelength must lie within the table's nodes."""
    outside = (wavelengths < nodes[0]) | (wavelengths > nodes[-1])
    if outside.any():
        first = float(wavelengths[outside][0])
        raise OutsideTable(f"{where}: wavelength {first:g} nm is outside the {what} table's "
                           f"range {nodes[0]:g}-{nodes[-1]:g} nm", first)
    return np.interp(wavelengths, nodes, values)
