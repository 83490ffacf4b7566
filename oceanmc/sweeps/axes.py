"""The sweep file and its axes: key paths into a scene, the values along each axis, the grid of
points (every combination of the axes; the keys of a `zip` group vary together, as one axis).

A key path names one value of the scene the way the README's tables do, with list indices in
brackets: `water.layers[0].a`, `bottom.reflectance`, `illumination.sun_zenith_deg`,
`water.layers[0].phase.components[1].b` (negative indices count from the end, as in Python).
Nothing here knows the scene's schema: a path reaches whatever the base scene's mapping holds,
so keys added to the schema later are reachable without a change here; the scene's own
validation (points.py) then judges every value.

An axis is `KEY.PATH: VALUES` (its dimension named by the key path) or `NAME: {key: KEY.PATH,
values: VALUES}` (named NAME, e.g. `chl`); the same two forms stand inside a `zip` group.
"""
from __future__ import annotations

import copy
import difflib
import itertools
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ..config import ConfigError
from ..config.base import exponent_number
from ..config.loading import schema_keys

# a key, then any number of [index]: `layers[0]`, `components[-1]`, `bottom`
_SEGMENT = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[-?\d+\])*)$")
_INDEX = re.compile(r"\[(-?\d+)\]")
SWEEP_KEYS = ("base", "set", "axes", "batch_groups")
GENERATORS = ("linspace", "geomspace")
# every point's scene is validated (about 1-2 ms each) before anything runs, and each becomes a
# results file and a task: 100,000 points take minutes to check and are far more than a look-up
# table needs; {linspace: [0, 1, 10000000]} was validated for more than 10 minutes unbounded
MAX_POINTS = 100_000


class SweepError(ConfigError):
    """A sweep file or a point of it that cannot run; the message names the key, the value, the
    point's coordinates where there is one, and what is allowed."""


def parse_key_path(path: str, where: str = "axes") -> list[str | int]:
    """`water.layers[0].a` -> ['water', 'layers', 0, 'a']. `where` names the place in the
    sweep file the path was written (axes, set, axes: NAME.key) in the one-line error."""
    if not isinstance(path, str) or not path:
        raise SweepError(f"{where}: {path!r} is not a key path (e.g. water.layers[0].a)")
    steps: list[str | int] = []
    for segment in path.split("."):
        match = _SEGMENT.match(segment)
        if match is None:
            raise SweepError(f"{where}: {path!r} is not a key path: {segment!r} should be a key "
                             "optionally followed by list indices, e.g. layers[0]")
        steps.append(match.group(1))
        steps += [int(i) for i in _INDEX.findall(match.group(2))]
    return steps


def set_key_path(scene: dict, path: str, value: Any, written: str | None = None) -> None:
    """Sets the value at a key path in a scene mapping (in place). Missing mappings on the way are
    created (a key the base scene leaves at its default); a list index must exist. `written`:
    how the sweep file gave the path, which starts the one-line error (default `axes: PATH`;
    `set: PATH`, or `axes: NAME.key = PATH` for a named axis)."""
    written = written or f"axes: {path}"
    steps = parse_key_path(path, written.split(":")[0])
    node: Any = scene
    for depth, (step, following) in enumerate(zip(steps, steps[1:] + [None])):
        where = _render(steps[:depth]) or "the scene"
        last = following is None
        if isinstance(step, int):
            if not isinstance(node, list):
                raise SweepError(f"{written}: {where} is not a list, so [{step}] does not "
                                 "apply")
            if not -len(node) <= step < len(node):
                raise SweepError(f"{written}: {where} has {len(node)} entr"
                                 f"{'y' if len(node) == 1 else 'ies'} in the base scene; allowed "
                                 f"indices {-len(node)} .. {len(node) - 1}")
        elif not isinstance(node, dict):
            raise SweepError(f"{written}: {where} is not a mapping, so it has no key "
                             f"{step!r}")
        if last:
            node[step] = value
        elif isinstance(step, str) and node.get(step) is None:
            _check_missing_key(written, steps, depth, node)
            node[step] = {}   # following is a key: a list index needs the base scene's list
            node = node[step]
        else:
            node = node[step]


def _check_missing_key(written: str, steps: list[str | int], depth: int, node: dict) -> None:
    """A key on the way that the base scene lacks is created as a mapping if the scene allows it
    there; an unknown key (with the nearest valid one: the schema's keys at that level and the
    base scene's) or one followed by a list index (there is no list to index) is refused."""
    step, following = steps[depth], steps[depth + 1]
    allowed = schema_keys(tuple(steps[:depth]))
    if allowed is not None and step not in allowed:
        close = difflib.get_close_matches(step, sorted(allowed | set(map(str, node))), n=1,
                                          cutoff=0.6)
        hint = f"; did you mean {_render(steps[:depth] + [close[0]])}?" if close else \
            f"; allowed keys there: {', '.join(sorted(allowed))}"
        raise SweepError(f"{written}: {_render(steps[:depth + 1])} is an unknown key{hint}")
    if isinstance(following, int):
        raise SweepError(f"{written}: the base scene has no {_render(steps[:depth + 1])}, so "
                         f"[{following}] does not apply; give {_render(steps[:depth + 1])} in the "
                         "base scene, or make the whole list an axis's value")


def _render(steps: list[str | int]) -> str:
    text = ""
    for step in steps:
        text += f"[{step}]" if isinstance(step, int) else ("." if text else "") + step
    return text


@dataclass(frozen=True)
class Axis:
    """One dimension of the sweep: a key path and its values, or a zip group of several key
    paths whose values vary together (then the dimension is named after the first). Each key's
    coordinate is named by its key path, or by the short name given to it (`chl: {key: PATH,
    values: [...]}`)."""
    keys: tuple[str, ...]
    values: tuple[tuple[Any, ...], ...]   # values[k][i]: key k at position i
    aliases: tuple[str | None, ...] = ()  # aliases[k]: key k's short name, None: its key path

    def name(self, k: int) -> str:
        """The coordinate name of key k: its short name, else its key path."""
        alias = self.aliases[k] if k < len(self.aliases) else None
        return alias or self.keys[k]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.name(k) for k in range(len(self.keys)))

    @property
    def dim(self) -> str:
        return self.name(0)

    def __len__(self) -> int:
        return len(self.values[0])


@dataclass(frozen=True)
class SweepSpec:
    """A parsed sweep: the base scene (a mapping, as written), its folder (for the table files
    it names), settings applied to every point, the axes, and how many batch groups each point
    is spread over."""
    base: dict
    base_dir: Path
    settings: dict[str, Any]
    axes: tuple[Axis, ...]
    batch_groups: int

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(axis) for axis in self.axes)

    @property
    def names(self) -> dict[str, str]:
        """{key path: the name the sweep file gave it}: its short name, else the path."""
        return {key: axis.name(k) for axis in self.axes for k, key in enumerate(axis.keys)}

    def points(self):
        """(index tuple, [(key path, value), ...]) for every point, in C order."""
        for index in itertools.product(*(range(len(axis)) for axis in self.axes)):
            yield index, [(key, axis.values[k][i]) for axis, i in zip(self.axes, index)
                          for k, key in enumerate(axis.keys)]

    def scene_at(self, assignments) -> dict:
        """The base scene with the settings and a point's (key path, value) assignments; a
        path that does not fit the base scene is refused as the sweep file wrote it."""
        scene = copy.deepcopy(self.base)
        for key, value in self.settings.items():
            set_key_path(scene, key, value, f"set: {key}")
        names = self.names
        for key, value in assignments:
            name = names.get(key, key)
            set_key_path(scene, key, value, None if name == key else f"axes: {name}.key = {key}")
        return scene

    def label(self, assignments) -> str:
        """A point's coordinates for messages, by the names the sweep file gave its axes:
        `chl = 0.3, bottom.reflectance = 0.2`."""
        names = self.names
        return label([(names.get(key, key), value) for key, value in assignments])

    def to_yaml(self) -> str:
        """The sweep as a YAML text (stored in the dataset's attributes; load_sweep reads its
        axes back)."""
        def entry(axis: Axis, k: int) -> tuple[str, Any]:
            values = list(axis.values[k])
            if axis.name(k) == axis.keys[k]:
                return axis.keys[k], values
            return axis.name(k), {"key": axis.keys[k], "values": values}

        axes: dict[str, Any] = {}
        zips = []
        for axis in self.axes:
            if len(axis.keys) == 1:
                name, value = entry(axis, 0)
                axes[name] = value
            else:
                zips.append(dict(entry(axis, k) for k in range(len(axis.keys))))
        if zips:
            axes["zip"] = zips
        return yaml.safe_dump({"set": self.settings, "axes": axes,
                               "batch_groups": self.batch_groups}, sort_keys=False)


def load_sweep(source: str | Path | dict) -> SweepSpec:
    """Reads a sweep (a YAML file or a mapping with `base`, `axes`, optional `set` and
    `batch_groups`). `base` is a scene file (relative to the sweep file), a scene mapping, or a
    SceneConfig."""
    if isinstance(source, (str, Path)):
        path = Path(source)
        data = _read_yaml(path, str(path), "sweep")
        folder = path.parent
    else:
        data, folder = plain_values(source), Path.cwd()
    if not isinstance(data, dict):
        raise SweepError(f"sweep: the top level must be a mapping with keys {', '.join(SWEEP_KEYS)}"
                         f", got {type(data).__name__}")
    unknown = sorted(set(map(str, data)) - set(SWEEP_KEYS))
    if unknown:
        raise SweepError(f"sweep: {unknown[0]}: unknown key{_nearest(unknown[0], SWEEP_KEYS)} "
                         f"(allowed: {', '.join(SWEEP_KEYS)})")
    base, base_dir = _base_scene(data.get("base"), folder)
    settings = data.get("set") or {}
    if not isinstance(settings, dict):
        raise SweepError(f"set: expected a mapping of key paths to values, got {settings!r}")
    for key in settings:
        parse_key_path(key, "set")
    axes = _axes(data.get("axes"))
    total = math.prod(len(axis) for axis in axes)
    if total > MAX_POINTS:   # before any point is built
        sizes = " x ".join(f"{len(axis):,} ({axis.dim})" for axis in axes)
        raise SweepError(f"axes: {sizes}{f' = {total:,}' if len(axes) > 1 else ''} points; "
                         f"allowed: at most {MAX_POINTS:,} points in a sweep (split it into "
                         "several sweeps)")
    groups = data.get("batch_groups", 1)
    check_count("batch_groups", groups, " (the number of tasks each point's batches are "
                "spread over)")
    return SweepSpec(base, base_dir, dict(settings), axes, groups)


def plain_values(value: Any) -> Any:
    """A sweep given as a mapping with numpy's arrays and numbers in it (a notebook's axes:
    np.linspace(0.1, 0.3, 5), np.float64) as the lists and numbers a YAML file gives, which the
    points' labels and scenes are written from (an array was refused as no list, a list of
    np.float64 raised PyYAML's RepresenterError: a user's review); anything else as it is."""
    if isinstance(value, np.ndarray):
        return plain_values(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, dict):
        return {key: plain_values(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain_values(item) for item in value]
    return value


def check_count(name: str, value: Any, what: str = "") -> None:
    """SweepError unless value is an integer >= 1 (a bool is not)."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise SweepError(f"{name} = {value!r}: expected an integer >= 1{what}")


def _read_yaml(path: Path, what: str, kind: str) -> Any:
    """The YAML document in path, read with the scene loader's guards (a key given twice, a
    FIFO or a device, a file over 1 MB, an alias bomb: each refused in one line); `what` names
    it in the one-line error, `kind` (sweep, scene) says what it should be."""
    from ..config.loading import read_yaml_file
    try:
        return read_yaml_file(path, what, kind)
    except ConfigError as exc:   # a SweepError, which `oceanmc sweep` reports (exit status 2)
        raise SweepError(str(exc)) from None


def _base_scene(base: Any, folder: Path) -> tuple[dict, Path]:
    from ..config import SceneConfig
    if base is None:
        raise SweepError("base: required key is missing (a scene file or a scene mapping)")
    if isinstance(base, SceneConfig):
        return base.model_dump(), folder
    if isinstance(base, (str, Path)):
        path = Path(base) if Path(base).is_absolute() else folder / base
        # a relative base is relative to the sweep file's folder: the message says where
        where = "" if str(path) == str(base) else f" ({path})"
        scene = _read_yaml(path, f"base = {str(base)!r}{where}", "scene")
        if not isinstance(scene, dict):
            raise SweepError(f"base = {str(base)!r}: not a scene (a mapping of keys)")
        return scene, path.parent
    if isinstance(base, dict):
        return copy.deepcopy(base), folder
    raise SweepError(f"base = {base!r}: expected a scene file or a scene mapping")


def _axes(spec: Any) -> tuple[Axis, ...]:
    if spec is None:
        return ()
    if not isinstance(spec, dict):
        raise SweepError(f"axes: expected a mapping of key paths to lists of values, got "
                         f"{type(spec).__name__}")
    axes = []
    for key, values in spec.items():
        if key == "zip":
            groups = values if isinstance(values, list) else [values]
            for group in groups:
                axes.append(_zip_axis(group))
        else:
            path, alias, grid = _entry(key, values)
            axes.append(Axis((path,), (grid,), (alias,)))
    for axis in axes:
        _check_distinct(axis)
    seen: set[str] = set()
    for axis in axes:
        for key in axis.keys:
            if key in seen:
                raise SweepError(f"axes: {key} appears twice")
            seen.add(key)
    names: dict[str, str] = {}
    for axis in axes:
        for k, key in enumerate(axis.keys):
            name = axis.name(k)
            if name in names or (name != key and name in seen):
                raise SweepError(f"axes: {name}: the name is given twice ({names.get(name, name)}"
                                 f" and {key}); each axis and coordinate needs its own name")
            names[name] = key
    return tuple(axes)


# the names of a sweep dataset's own dimensions, coordinates and per-point variables, which a
# short axis name must not take (a results file's quantities are named as in RESERVED_PREFIXES
# or RESERVED_NAMES)
RESERVED_NAMES = frozenset({
    "depth", "theta", "phi", "theta_edges", "phi_edges", "direction", "direction_theta",
    "direction_phi", "wavelength", "wavelength_traced", "status", "error", "photons",
    "wall_time_s", "zip",
    "Ed", "Eu", "Eod", "Eou", "Eo", "Lu", "Lu_crossing", "local_radiance", "radiance"})
RESERVED_PREFIXES = ("air_", "budget_")
_ALIAS = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
ALIAS_KEYS = ("key", "values")


def _entry(name: str, spec: Any) -> tuple[str, str | None, tuple[Any, ...]]:
    """(key path, short name or None, values) of one axis entry: `KEY.PATH: VALUES` or
    `NAME: {key: KEY.PATH, values: VALUES}` (the dimension or coordinate then named NAME)."""
    if isinstance(spec, dict) and ("key" in spec or "values" in spec):
        unknown = sorted(set(map(str, spec)) - set(ALIAS_KEYS))
        missing = [key for key in ALIAS_KEYS if key not in spec]
        if unknown or missing:
            raise SweepError(f"axes: {name}: a named axis is {{key: KEY.PATH, values: [...]}}; "
                             + (f"unknown key {unknown[0]!r}{_nearest(unknown[0], ALIAS_KEYS)}"
                                if unknown else f"{missing[0]} is missing"))
        if not isinstance(name, str) or not _ALIAS.match(name):
            raise SweepError(f"axes: {name!r}: a short axis name is letters, digits and _ "
                             "(not starting with a digit), e.g. chl; it names the dataset's "
                             "dimension")
        if name in RESERVED_NAMES or name.startswith(RESERVED_PREFIXES) \
                or name.endswith("_stderr"):
            raise SweepError(f"axes: {name}: the name is taken by the sweep dataset's own "
                             f"dimensions or variables; choose another (e.g. {name}_axis)")
        path = spec["key"]
        parse_key_path(path, f"axes: {name}.key")
        return path, name, _values(f"{name}.values", spec["values"])
    parse_key_path(name)
    return name, None, _values(name, spec)


def _nearest(key: str, allowed) -> str:
    """'; did you mean X?' for a misspelt key close to an allowed one, else ''."""
    close = difflib.get_close_matches(key, list(allowed), n=1)
    return f"; did you mean {close[0]}?" if close else ""


def _zip_axis(group: Any) -> Axis:
    if not isinstance(group, dict) or len(group) < 2:
        raise SweepError(f"axes.zip: expected a mapping of two or more key paths to lists of "
                         f"equal length, got {group!r}")
    entries = [_entry(name, spec) for name, spec in group.items()]
    keys = tuple(path for path, _, _ in entries)
    values = tuple(grid for _, _, grid in entries)
    lengths = {name: len(v) for name, v in zip(group, values)}
    if len(set(lengths.values())) > 1:
        raise SweepError(f"axes.zip: the lists must have equal lengths; got "
                         f"{', '.join(f'{k}: {n}' for k, n in lengths.items())}")
    return Axis(keys, values, tuple(alias for _, alias, _ in entries))


def _check_distinct(axis: Axis) -> None:
    """SweepError where two points of an axis are the same (a zip axis: the same values of all
    its keys): the dataset's coordinate would hold a value twice, and selecting it would
    return two points."""
    columns = [coordinate(values) for values in axis.values]
    seen: dict[tuple, int] = {}
    for i, point in enumerate(zip(*columns)):
        if point in seen:
            keys = " and ".join(axis.keys)
            raise SweepError(f"axes: {keys}: point {i + 1} repeats point {seen[point] + 1} "
                             f"({', '.join(str(v) for v in point)}); allowed: distinct values")
        seen[point] = i


def _values(key: str, values: Any) -> tuple[Any, ...]:
    """A list as written, or {linspace: [start, stop, num]} / {geomspace: [start, stop, num]}
    (numpy's, end points included). An exponent number that YAML 1.1 reads as a string (1e-3,
    5e2: no decimal point, or no sign on the exponent) is the number: a text coordinate
    otherwise."""
    if isinstance(values, dict):
        if len(values) != 1 or next(iter(values)) not in GENERATORS:
            raise SweepError(f"axes: {key} = {values!r}: expected a list of values or one of "
                             f"{', '.join(f'{{{g}: [start, stop, num]}}' for g in GENERATORS)}")
        (kind, args), = values.items()
        if isinstance(args, list):
            numbers = [exponent_number(a) for a in args]
            if len(args) == 3 and isinstance(args[2], str) and isinstance(numbers[2], float) \
                    and numbers[2].is_integer():
                numbers[2] = int(numbers[2])   # num written 1e3
            args = numbers
        if not (isinstance(args, list) and len(args) == 3
                and all(isinstance(a, (int, float)) and not isinstance(a, bool) for a in args)
                and isinstance(args[2], int) and args[2] >= 1
                and all(math.isfinite(a) for a in args)):
            raise SweepError(f"axes: {key}.{kind} = {args!r}: expected [start, stop, num] with "
                             "finite numbers and an integer num >= 1")
        if args[2] > MAX_POINTS:   # before numpy makes the grid
            raise SweepError(f"axes: {key}.{kind} = {args!r}: {args[2]:,} points; allowed: at "
                             f"most {MAX_POINTS:,} points in a sweep")
        if kind == "geomspace" and args[0] * args[1] <= 0:
            raise SweepError(f"axes: {key}.geomspace = {args!r}: start and stop must be "
                             "non-zero and of the same sign")
        grid = getattr(np, kind)(float(args[0]), float(args[1]), int(args[2]))
        return tuple(float(v) for v in grid)
    if not isinstance(values, list) or not values:
        raise SweepError(f"axes: {key} = {values!r}: expected a non-empty list of values")
    return tuple(exponent_number(v) for v in values)


def coordinate(values: tuple[Any, ...]) -> np.ndarray:
    """An axis's values as a coordinate array: numbers as float64 (int64 when all are integers),
    text as strings, anything else (a mapping, a list) as its YAML text."""
    if all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return np.array(values, dtype=np.int64)
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return np.array(values, dtype=np.float64)
    if all(isinstance(v, str) for v in values):
        return np.array(values, dtype=object)
    return np.array([yaml.safe_dump(v, default_flow_style=True).strip() for v in values],
                    dtype=object)


def label(assignments) -> str:
    """A point's coordinates for messages: `water.layers[0].a = 0.1, bottom.reflectance = 0.2`."""
    return ", ".join(f"{key} = {yaml.safe_dump(value, default_flow_style=True).strip()}"
                     .replace("\n...", "") for key, value in assignments)
