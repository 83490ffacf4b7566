"""The result model: a run's quantities, each with its per-batch values, and what the run was.

Every quantity keeps its per-batch values (leading `batch` axis); the estimate is the mean over
batches and its standard error the sample standard deviation over sqrt(batches). Because the
batch values are stored, results of independent runs merge by concatenating batches (merge.py).
"""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .derived import DERIVED_NAMES, derive
from .format import save_result


@dataclass
class Quantity:
    name: str                 # path in the file: "Ed", "air/Lw", "budget/water_leaving"
    dims: tuple[str, ...]     # dimensions of the estimate (without the batch axis)
    batches: np.ndarray       # (batch, *dims)
    units: str
    description: str

    @property
    def mean(self) -> np.ndarray:
        if self.batches.shape[0] == 0:   # a run stopped before its first batch was whole
            return np.full(self.batches.shape[1:], np.nan)
        return self.batches.mean(axis=0)

    @property
    def stderr(self) -> np.ndarray:
        n = self.batches.shape[0]
        if n < 2:
            return np.full(self.batches.shape[1:], np.nan)
        # the deviations are divided by their largest magnitude before they are squared:
        # squared unscaled, deviations below about 1e-154 underflow to 0 (a standard error of
        # exactly 0 for a tiny quantity) and those above about 1e154 overflow
        deviations = self.batches - self.batches.mean(axis=0)
        scale = np.abs(deviations).max(axis=0)
        safe = np.where(scale > 0.0, scale, 1.0)
        spread = np.sqrt(((deviations / safe) ** 2).sum(axis=0) / (n - 1))
        return scale * spread / math.sqrt(n)


@dataclass
class Result:
    """A run's quantities (oceanmc.simulate's, or a results file's: oceanmc.load_result).

    result["Ed"] is a quantity's estimate (the mean over batches), result.stderr("Ed") its
    standard error, result.keys() their names ("Ed", "air/Rrs_nadir", "raman/Lu", ...; the
    README's Outputs), result.quantities[name].batches the per-batch values, result.coords the
    coordinates (depth, theta, phi, wavelength, ...), result.attrs what the run was (its scene
    as config_yaml, photons, seed, timing). The derived quantities (Kd, R, Q, t_up, ...) are
    computed from the batch means: oceanmc.derive(result). result.save(path) writes the file
    that `oceanmc show` and `plot` read and xarray opens."""
    coords: dict[str, np.ndarray]
    quantities: dict[str, Quantity]
    attrs: dict[str, object] = field(default_factory=dict)
    # a partial run's unfinished batches, from which --resume continues them (simulation.py)
    resume_state: dict[str, np.ndarray] | None = None
    # the IOPs the run used (optics.iops_table): a, b, bb, c (layer, wavelength) in 1/m and the
    # coordinates layer_top (m), layer_thickness (m), wavelength (nm), and the bottom's
    # reflectance (wavelength) where it has one; the file's group `iops`
    iops: dict[str, np.ndarray] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return self._quantity(name).mean

    def __contains__(self, name: str) -> bool:
        return name in self.quantities

    def keys(self):
        """The names of the quantities, as result[name] takes them."""
        return self.quantities.keys()

    def stderr(self, name: str) -> np.ndarray:
        """The standard error of quantity `name` over the batches (the estimate: result[name])."""
        return self._quantity(name).stderr

    def _quantity(self, name: str) -> Quantity:
        """The quantity, or a KeyError naming the nearest names (`Rrs_nadir` is
        `air/Rrs_nadir`)."""
        if name in self.quantities:
            return self.quantities[name]
        leaf = str(name).rpartition("/")[2]
        near = [q for q in self.quantities if q.rpartition("/")[2] == leaf] or \
            difflib.get_close_matches(str(name), list(self.quantities), n=3, cutoff=0.6)
        hint = f"; did you mean {' or '.join(near)}?" if near else ""
        if str(name).startswith("derived/") or leaf in DERIVED_NAMES:
            hint = self._derived_hint(str(name), leaf)
        raise KeyError(f"no quantity {name!r} in this result{hint}")

    def _derived_hint(self, name: str, leaf: str) -> str:
        """Where a derived quantity (the results file's group derived, computed from the
        batches, not held here) is, or why this result has none of that name."""
        if leaf not in DERIVED_NAMES:
            return f"; the derived quantities are {', '.join(DERIVED_NAMES)}"
        if name.partition("/")[0] in str(self.attrs.get("inelastic_parts", "")).split():
            # raman/Kd
            return (f"; {leaf} is derived from the whole light's batch means only: "
                    f"oceanmc.derive(result)[{leaf!r}]")
        if leaf not in derive(self):
            return (f"; {leaf} is derived from the batch means, and this result's tallies do "
                    "not give it (t_up needs depth 0 tallied, a K function two tally depths, "
                    "KLu and Q the nadir radiance Lu)")
        return (f"; {leaf} is derived from the batch means: oceanmc.derive(result)[{leaf!r}] "
                "(.value, .stderr), or the results file's group derived")

    def __repr__(self) -> str:
        # (the dataclass's own repr printed every batch of every quantity: 67,000 characters
        # for a one-wavelength run)
        sizes = ", ".join(f"{k} {len(v)}" for k, v in self.coords.items()
                          if k in ("wavelength", "depth", "direction") and len(v))
        return (f"<oceanmc Result {self.attrs.get('name', '')!r}: {len(self.quantities)} "
                f"quantities ({sizes}), {self.attrs.get('batches', '?')} batches, "
                f"{self.attrs.get('photons', '?')} photons>")

    @property
    def config_yaml(self) -> str:
        return str(self.attrs["config_yaml"])

    def save(self, path: str | Path, overwrite: bool = True) -> Path:
        """Writes the results file (format.save_result); overwrite=False: never replace an
        existing file (placement.place_atomically), and refuse one that exists before writing
        anything (FileExistsError). A folder is refused (IsADirectoryError) before writing."""
        if Path(path).is_dir() or Path(path).name in ("", ".", ".."):
            raise IsADirectoryError(f"{path} is a folder: save() takes the results file's own "
                                    "path, such as results/scene.h5")
        if not overwrite and Path(path).exists():
            raise FileExistsError(f"{path} exists; save(..., overwrite=True) replaces it")
        return save_result(self, path, overwrite)


# ratios derivation.from_tallies leaves out of a Result where their denominator is 0 in a batch
# (there is no value to give: 0/0): air/rho_local without sky light, and air/t_up without
# upwelling light at 0- in files written before 2026-11-29 (it is now derived from the batch
# means: run/derived.py), which merge with newer ones that way. The wavelengths of a spectral
# run, and runs of one scene, may differ in these only (a batch of very absorbing water may
# have no upwelling photon where another has some)
UNDEFINED_RATIOS = frozenset({"air/t_up", "air/rho_local"})


def common_quantities(parts: list[Result]) -> set[str]:
    """The quantities every part holds: a ratio of UNDEFINED_RATIOS that some part (a
    wavelength of a spectral run, a run to merge) lacks is left out of the whole, as a run
    leaves it out when one of its batches lacks it."""
    return set.intersection(*(set(p.quantities) for p in parts))
