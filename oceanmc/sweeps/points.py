"""The sweep's points as scenes: each one built from the base scene and its coordinates,
validated as `oceanmc run` validates a scene (the schema, then the packing of the scene, which
reads and checks auxiliary tables) before any photon runs, and named by a hash of its resolved
scene, so that a rerun finds the points it has already done whatever the order of the axes."""
from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass

from ..config import ConfigError, SceneConfig, config_to_yaml, load_config
from ..config.loading import DISCRIMINATORS, file_keys
from ..optics.tables import OutsideTable
from .axes import SweepError, SweepSpec, parse_key_path


@dataclass(frozen=True)
class Point:
    index: tuple[int, ...]   # position on the axes
    label: str               # its coordinates, for messages
    config: SceneConfig
    yaml: str                # the resolved scene: `oceanmc run` of this text is this point

    @property
    def key(self) -> str:
        return hashlib.sha256(self.yaml.encode()).hexdigest()[:20]

    def batch_ranges(self, groups: int) -> list[tuple[int, int]]:
        """The batches split into up to `groups` contiguous ranges [first, end) of near-equal
        size (never an empty one)."""
        n = self.config.batches
        groups = min(groups, n)
        edges = [round(i * n / groups) for i in range(groups + 1)]
        return list(zip(edges[:-1], edges[1:]))

    def part_yaml(self, first: int, end: int) -> str:
        """The scene that runs batches first .. end-1 of this point: the same scene with its
        batch count cut at `end` and as many photons per batch. Batch b's random stream depends
        only on (seed, b), so these batches are the point's own (simulate(first_batch=...))."""
        if (first, end) == (0, self.config.batches):
            return self.yaml
        per_batch = math.ceil(self.config.photons / self.config.batches)
        part = self.config.model_copy(update={"batches": end, "photons": per_batch * end})
        return config_to_yaml(part)


def build_points(spec: SweepSpec) -> list[Point]:
    """Every point's scene, validated; raises SweepError naming the first bad point's
    coordinates (and how many more are bad)."""
    points: list[Point] = []
    bad: list[str] = []
    from_set: list[str] = []   # the problems of a value the sweep file's `set:` gives
    count = 0
    for index, assignments in spec.points():
        count += 1
        where = spec.label(assignments)   # by the names the sweep file gave its axes
        try:
            config = load_config(spec.scene_at(assignments), base_dir=spec.base_dir)
        except SweepError as exc:
            raise SweepError(str(exc)) from None   # a key path the base scene does not have
        except ConfigError as exc:
            text = _without_origin(exc)
            text = _model_switch(text, spec, spec.settings, assignments, "set:") or \
                _model_switch(text, spec, dict(assignments), assignments, "an axis") or text
            if _set_by(text, spec.settings) and not _set_by(text, dict(assignments)):
                from_set.append(text)
                text = f"set: {text}"
            bad.append(f"point ({where}): {text}")
            continue
        points.append(Point(index, where, config, config_to_yaml(config)))
    if bad and len(from_set) == count and len(set(from_set)) == 1:
        # the same problem at every point: the set value alone, whatever the axes
        raise SweepError(f"set: {from_set[0]}")
    if bad:
        _raise_first(bad)
    _check_same_tallies(points)
    _check_known_wavelengths(points)
    return points


def most_batch_groups(point: Point) -> int:
    """The most batch groups the point's batches can be spread over: the first group runs as
    a scene of its end's batch count (part_yaml), which must be at least 2."""
    return next(g for g in range(point.config.batches, 0, -1)
                if g == 1 or point.batch_ranges(g)[0][1] >= 2)


def check_batch_groups(groups: int, points: list[Point]) -> None:
    """SweepError, before anything runs, where a point has too few batches for `groups` (one
    point of each batch count is tried)."""
    first_of: dict[int, Point] = {}
    for point in points:
        first_of.setdefault(point.config.batches, point)
    for point in first_of.values():
        if point.batch_ranges(groups)[0][1] < 2 and groups > 1:
            most = most_batch_groups(point)
            raise SweepError(
                f"batch_groups = {groups}: point ({point.label}) has {point.config.batches} "
                f"batches, which can be spread over at most {most} groups (each group's scene "
                f"needs 2 batches or more); allowed: 1 .. {most}, or give the scene more "
                "batches")


def check_scenes(points: list[Point], spec: SweepSpec | None = None) -> None:
    """Packs every point's scene (which reads and checks its table files, BRDF checks and
    tables: ConfigError) without tracing a photon. Needs the compiled kernel (run.compiling).
    spec: the sweep, whose `set:` a problem of a table file it gives is blamed on (as
    build_points blames it for a value the schema refuses)."""
    from .. import scene
    given = dict(spec.points()) if spec is not None else {}
    bad = []
    from_set: list[str] = []
    for point in points:
        try:
            scene.build(point.config)
        except ConfigError as exc:
            text = (exc.explained(point.config.added_wavelengths)
                    if isinstance(exc, OutsideTable) else _without_origin(exc))
            keys = file_keys(text, point.config)
            # (`KEY:`: a file's key path is a problem at that key)
            if spec is not None and keys and all(
                    _set_by(f"{key}:", spec.settings)
                    and not _set_by(f"{key}:", dict(given[point.index])) for key in keys):
                text = text if _set_by(text, dict.fromkeys(keys)) else f"{keys[0]}: {text}"
                from_set.append(text)
                text = f"set: {text}"
            bad.append(f"point ({point.label}): {text}")
    if bad and len(from_set) == len(points) and len(set(from_set)) == 1:
        raise SweepError(f"set: {from_set[0]}")   # every point: the set's file alone
    if bad:
        _raise_first(bad)


def _set_by(problem: str, values: dict) -> bool:
    """Whether a point's problem (`KEY.PATH = value: ...`, `KEY.PATH: unknown key`) is at or
    under one of these key paths (the sweep file's `set:` keys, or a point's axis keys)."""
    return any(problem.startswith(str(key)) and problem[len(str(key)):][:1] in (":", " ", ".", "[")
               for key in values)


# a point's problem with a key of a mapping (config/loading.py _describe): `PATH.KEY: unknown
# key...` or `PATH.KEY: required key is missing`, and pydantic's count of its other problems
_KEY_PROBLEM = re.compile(r"^(?P<mapping>.+)\.(?P<key>[A-Za-z_]\w*): "
                          r"(?P<kind>unknown key|required key is missing)"
                          r".*?(?P<more>(?: \(and \d+ more problems?\))?)$")


def _model_switch(problem: str, spec: SweepSpec, values: dict, assignments,
                  given_by: str) -> str | None:
    """A point's problem with a key of a mapping whose model (or profile) `values` (the `set:`
    keys, or a point's axis keys: `given_by`) change from the base scene's, the key not given
    by the sweep file: said as the problem of that model's value, naming the base scene's key
    the model does not take, or the key it needs. As it was (`bottom.reflectance: unknown key;
    did you mean diffuse_reflectance?`) it blamed the point's coordinates: set: and the axes
    change only the keys they name, and the rest of the base scene's mapping stays."""
    found = _KEY_PROBLEM.match(problem)
    if found is None or _set_by(problem, spec.settings) or _set_by(problem, dict(assignments)):
        return None
    mapping, key = found["mapping"], found["key"]
    switch = next((f"{mapping}.{name}" for name in DISCRIMINATORS
                   if f"{mapping}.{name}" in values), None)
    if switch is None or _base_value(spec.base, switch) == values[switch]:
        return None
    if found["kind"] == "unknown key":
        what = (f"takes no {mapping}.{key}, which the base scene gives ({given_by} changes "
                f"only the keys it names; give the whole {mapping} mapping there instead)")
    else:
        what = f"{mapping}.{key}: required key is missing"
    return f"{switch} = {values[switch]!r}: {what}{found['more']}"


def _base_value(scene: dict, path: str):
    """The base scene's value at a key path, or None where it has none."""
    node = scene
    for step in parse_key_path(path):
        try:
            node = node[step]
        except (KeyError, IndexError, TypeError):
            return None
    return node


def _without_origin(exc: ConfigError) -> str:
    text = str(exc)
    return text[len("config: "):] if text.startswith("config: ") else text


def _raise_first(bad: list[str]) -> None:
    more = f" (and {len(bad) - 1} more point{'s' if len(bad) > 2 else ''})" if len(bad) > 1 \
        else ""
    raise SweepError(bad[0] + more)


def _check_known_wavelengths(points: list[Point]) -> None:
    """One wavelength grid for the dataset (dataset.wavelength_grid) needs every point's
    wavelengths: a scene without wavelengths_nm (one unnamed wavelength) cannot sit beside
    spectral ones."""
    unnamed = [p for p in points if any(math.isnan(w) for w in p.config.wavelengths)]
    named = [p for p in points if p not in unnamed]
    if unnamed and named:
        raise SweepError(f"point ({unnamed[0].label}) has no wavelengths_nm, point "
                         f"({named[0].label}) has: every point of a sweep needs wavelengths_nm "
                         "for one wavelength grid, or none does")


def _check_same_tallies(points: list[Point]) -> None:
    """One dataset needs the same depths, angular grid and directions at every point."""
    if not points:
        return
    first = points[0].config.tallies
    for point in points[1:]:
        if point.config.tallies != first:
            changed = [name for name in type(first).model_fields
                       if getattr(point.config.tallies, name) != getattr(first, name)]
            raise SweepError(f"point ({point.label}): tallies.{changed[0]} differs from the first "
                             f"point's: every point of a sweep needs the same tallies (depths, "
                             "angular grid, directions), which become the dataset's dimensions")
