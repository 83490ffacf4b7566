"""Reading a scene from YAML or a dict into a SceneConfig, one ConfigError per bad scene, and
writing it back as YAML."""
from __future__ import annotations

import datetime
import difflib
import hashlib
import json
import os
import re
import stat
import sys
import textwrap
import types
from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any, Literal, Union, get_args, get_origin

import numpy as np
import yaml
from pydantic import BaseModel, Tag, ValidationError

from .base import (QUOTED_NUMBER, SHOWN_VALUE, UNIT_SUFFIXES, ConfigError, _items, _Strict,
                   allowed_numbers, too_long_integer)
from .bottom import ReflectanceSpectrum, TableBottom, reflectance_keys
from .illumination import SkyMap
from .phase import Mixture, TablePhase
from .scene import SceneConfig


# the keys that say which member of a union a mapping is (a bottom's or a phase's model, a
# profile's profile)
DISCRIMINATORS = ("model", "profile")


def _union_tags(root: type[BaseModel]) -> frozenset[str]:
    """The tags pydantic puts in an error's location to say which member of a union it tried:
    the `model` value of each member of a discriminated union (isotropic, ..., lambertian, ...)
    and each explicit Tag (the sky's sky_name and SkyMap), found anywhere in the schema."""
    tags: set[str] = set()
    seen: set[type] = set()

    def visit(tp: Any) -> None:
        origin = get_origin(tp)
        if origin is Annotated:
            base, *metadata = get_args(tp)
            tags.update(m.tag for m in metadata if isinstance(m, Tag))
            visit(base)
        elif origin in (Union, types.UnionType):
            for member in get_args(tp):
                if isinstance(member, type) and issubclass(member, BaseModel):
                    for key in DISCRIMINATORS:
                        field = member.model_fields.get(key)
                        if field is not None and get_origin(field.annotation) is Literal:
                            tags.update(get_args(field.annotation))
                visit(member)
        elif isinstance(tp, type) and issubclass(tp, BaseModel):
            if tp not in seen:
                seen.add(tp)
                for field in tp.model_fields.values():
                    visit(field.annotation)
        else:
            for arg in get_args(tp):  # list[...], tuple[...], Literal[...] values (ignored)
                visit(arg)

    visit(root)
    return frozenset(tags)


_UNION_TAGS = _union_tags(SceneConfig)


MAX_CONFIG_BYTES = 1 << 20  # a scene is a few KB; the limit stops /dev/zero and the like
# a text table of MAX_TABLE_VALUES (scene/phase_tables.py) numbers would be about a gigabyte; no
# table comes near this, and the bound keeps a mistaken file from filling the memory
MAX_TABLE_BYTES = 1 << 28
MAX_YAML_NODES = 100_000   # after aliases are expanded: stops "billion laughs" alias bombs


class _SceneLoader(yaml.SafeLoader):
    """yaml.SafeLoader that refuses a key given twice in one mapping (the second would silently
    win) and documents whose aliases expand to more than MAX_YAML_NODES nodes."""

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            if isinstance(key, (str, int, float, bool)) and key in seen:
                mark = key_node.start_mark
                raise yaml.constructor.ConstructorError(
                    None, None, f"key {key!r} given twice", mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


class _LongInteger(Exception):
    """An integer of more digits than Python turns text into (sys.get_int_max_str_digits)."""

    def __init__(self, node: yaml.Node) -> None:
        super().__init__()
        self.mark = node.start_mark
        self.digits = sum(c.isdigit() for c in node.value)


def _construct_int(loader: yaml.SafeLoader, node: yaml.Node) -> int:
    try:
        return yaml.SafeLoader.construct_yaml_int(loader, node)
    except ValueError:   # (PyYAML's int() of 4301 digits or more)
        raise _LongInteger(node) from None


_SceneLoader.add_constructor("tag:yaml.org,2002:int", _construct_int)


class _RecursiveAlias(Exception):
    """An alias inside the node its anchor names (`a: &x [*x]`): it expands without end."""

    def __init__(self, node: yaml.Node) -> None:
        super().__init__()
        self.mark = node.start_mark


def _expanded_size(node: yaml.Node) -> int:
    """Nodes in the document with every alias expanded, computed on the composed graph (where
    an alias is a shared node) without expanding it. Raises _RecursiveAlias for a node that
    holds itself."""
    sizes: dict[int, int] = {}
    open_nodes: set[int] = set()   # the nodes being counted: one met again holds itself

    def size(n: yaml.Node) -> int:
        if id(n) in open_nodes:
            raise _RecursiveAlias(n)
        if id(n) in sizes:
            return sizes[id(n)]
        open_nodes.add(id(n))
        if isinstance(n, yaml.SequenceNode):
            total = 1 + sum(size(child) for child in n.value)
        elif isinstance(n, yaml.MappingNode):
            total = 1 + sum(size(k) + size(v) for k, v in n.value)
        else:
            total = 1
        open_nodes.discard(id(n))
        sizes[id(n)] = min(total, MAX_YAML_NODES + 1)
        return sizes[id(n)]
    return size(node)


def file_problem(path: str | Path) -> str | None:
    """Why `path` cannot be read as a data file (no such file, not a regular file: a folder, a
    FIFO, a device; cannot read it), or None. Never raises (pathlib's is_file raises on a name
    too long for the system)."""
    try:
        info = os.stat(path)
    except FileNotFoundError:
        return "no such file"
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        return f"cannot read it ({getattr(exc, 'strerror', None) or exc})"
    if not stat.S_ISREG(info.st_mode):
        return "not a regular file"
    # (its permissions: read as HDF5, it was 'not an oceanmc results file (Permission denied)')
    return None if os.access(path, os.R_OK) else "cannot read it (permission denied)"


def read_table_text(path: str | Path, origin: str) -> str:
    """The text of a table file (read_text_file, at most MAX_TABLE_BYTES)."""
    return read_text_file(path, origin, MAX_TABLE_BYTES, f"larger than {MAX_TABLE_BYTES >> 20} "
                          "MB; allowed: a table file of at most that size")


def read_text_file(path: str | Path, origin: str, limit: int, too_large: str) -> str:
    """The UTF-8 text of a regular file of at most `limit` bytes (a FIFO or a device such as
    /dev/zero would block or never end); every problem is a ConfigError starting with origin
    (too_large ends the one for a larger file). Scene configs and the table files read it."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except FileNotFoundError:
        raise ConfigError(f"{origin}: no such file") from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        raise ConfigError(f"{origin}: cannot read it ({getattr(exc, 'strerror', None) or exc})"
                          ) from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise ConfigError(f"{origin}: not a regular file")
    with os.fdopen(fd, "rb") as file:
        data = file.read(limit + 1)
    if len(data) > limit:
        raise ConfigError(f"{origin}: {too_large}")
    try:
        # (utf-8-sig: a byte-order mark, which Excel's "CSV UTF-8" writes first, is dropped, not
        # read as part of the first column's name)
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{origin}: not UTF-8 text ({exc.reason} at byte {exc.start})"
                          ) from None


def read_yaml_file(path: str | Path, origin: str, kind: str = "scene") -> Any:
    """The YAML document in a file, read with the guards of a scene config: a regular file (a
    FIFO would block, /dev/zero never end) of at most MAX_CONFIG_BYTES, UTF-8, no key given
    twice, aliases expanding to at most MAX_YAML_NODES values. Every problem is one
    ConfigError starting with origin; `kind` (scene, sweep) names what the file should be.
    Scene configs and sweep files (sweeps/axes.py) read it."""
    text = read_text_file(path, origin, MAX_CONFIG_BYTES, f"larger than "
                          f"{MAX_CONFIG_BYTES // 1024} KB; a {kind} file is a few KB of YAML")
    return _parse_yaml(text, origin, kind)


def _parse_yaml(text: str, origin: str, kind: str = "scene") -> Any:
    try:
        loader = _SceneLoader(text)
        try:
            node = loader.get_single_node()
            if node is None:
                return None
            try:
                too_many = _expanded_size(node) > MAX_YAML_NODES
            except _RecursiveAlias as exc:
                at = f"line {exc.mark.line + 1}, column {exc.mark.column + 1}"
                raise ConfigError(f"{origin}: not valid for a {kind}: {at}: an anchor's value "
                                  "holds an alias to that anchor (a recursive alias such as "
                                  "`a: &x [*x]`), which expands without end") from None
            if too_many:
                raise ConfigError(f"{origin}: its aliases expand to more than "
                                  f"{MAX_YAML_NODES:,} values; a {kind} needs far fewer")
            try:
                return loader.construct_document(node)
            except _LongInteger as exc:
                at = f"line {exc.mark.line + 1}, column {exc.mark.column + 1}"
                raise ConfigError(f"{origin}: not valid for a {kind}: {at}: an integer of "
                                  f"{exc.digits} digits; allowed: at most "
                                  f"{sys.get_int_max_str_digits()} digits") from None
        finally:
            loader.dispose()
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        what = exc.problem or exc.context or "invalid"
        raise ConfigError(f"{origin}: not valid YAML: {where}{what}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"{origin}: not valid YAML: {str(exc).splitlines()[0]}") from None
    except RecursionError:
        raise ConfigError(f"{origin}: nested too deeply to be a {kind}") from None


# pydantic's names for the members of a union that are not models (a number with bounds, a
# literal, a list, ...), in an error's location after the field's key
_BRANCH_TAG_PREFIXES = ("list[", "literal[", "dict[", "tuple[", "function-", "constrained-")
_BRANCH_TAG_NAMES = frozenset({"float", "int", "str", "bool", "none"})


def _is_branch_tag(part: Any) -> bool:
    """Whether a part of an error's location names a union's member, not a key the user
    wrote."""
    return isinstance(part, str) and (part in _UNION_TAGS or part in _BRANCH_TAG_NAMES
                                      or part.startswith(_BRANCH_TAG_PREFIXES))


def _key_path(loc: tuple) -> str:
    path = ""
    for part in loc:
        if isinstance(part, int):
            path += f"[{part}]"
        elif _is_branch_tag(part):
            continue  # pydantic's union-branch tags are not keys the user wrote
        else:
            # a key with a line break or another unprintable character is shown quoted, so
            # that the message stays one line
            key = str(part) if str(part).isprintable() else repr(str(part))
            path += ("." if path else "") + key
    return path or "(top level)"


# a key's unit, left out when a misspelt key is matched (`chl: 1` or `b488: 3e-4`: the quantity
# without its unit is close to none of the keys with it)
_UNIT_SUFFIX = re.compile("(" + "|".join(suffix for suffix, _ in UNIT_SUFFIXES) + ")$")


def _closest(key: str, names) -> str | None:
    """The name closest to `key` (by the whole name, or by the name without its unit), if one is
    close."""
    by_stem = {_UNIT_SUFFIX.sub("", name): name for name in sorted(names)}
    by_stem.update({name: name for name in names})
    close = difflib.get_close_matches(key, sorted(by_stem), n=1, cutoff=0.6)
    return by_stem[close[0]] if close else None


@lru_cache(maxsize=1)
def _section_keys() -> dict[str, list[str]]:
    """{key: the key paths where it stands} over the scene's sections, the mappings reached
    through mappings alone from the top (illumination.sun_zenith_deg, tallies.depths_m; not
    through a list such as water.layers)."""
    found: dict[str, list[str]] = {}

    def visit(loc: tuple) -> None:
        for name in sorted(schema_keys(loc) or ()):
            found.setdefault(name, []).append(".".join((*loc, name)))
            if len(loc) < 3 and schema_keys((*loc, name)):
                visit((*loc, name))
    visit(())
    return found


def _suggested_key(loc: tuple) -> tuple[str, bool] | None:
    """(the nearest valid key at that level, True), if one is close; else (the path of a close
    key in another section, False) where it stands in one only (`sun_zenith` at the top:
    illumination.sun_zenith_deg); else None."""
    key = str(loc[-1])
    here = _closest(key, schema_keys(loc[:-1]) or set())
    if here is not None:
        return here, True
    elsewhere = _closest(key, _section_keys())
    paths = _section_keys().get(elsewhere, []) if elsewhere is not None else []
    return (paths[0], False) if len(paths) == 1 else None


def _suggestion(loc: tuple) -> str:
    """ "; did you mean KEY?" for an unknown key (_suggested_key)."""
    found = _suggested_key(loc)
    if found is None:
        return " (check its spelling and level)"
    key, here = found
    return f"; did you mean {key}?" if here else f"; did you mean {key} (not at this level)?"


def schema_keys(loc: tuple) -> set[str] | None:
    """The keys the schema allows in the mapping at a location (keys and list indices: an
    error's, or a sweep's key path): the fields of every model that may stand there (each
    member of a union); None where the schema does not say (a path it does not know, or one
    to a value that is not a mapping)."""
    models = [_bare(member) for annotation in _annotations_at(loc) or []
              for member, _ in _alternatives(annotation)
              if isinstance(_bare(member), type) and issubclass(_bare(member), BaseModel)]
    return {name for model in models for name in model.model_fields} if models else None


def _alternatives(annotation: Any, tags: tuple = ()) -> list[tuple[Any, tuple]]:
    """(member, the union tags that name it) of each member of a union, through Annotated
    (kept around a member, with the bounds in it) and nested unions; a model member is named
    by its `model` or `profile` value too. Not a union: the annotation alone."""
    origin = get_origin(annotation)
    inner, *metadata = get_args(annotation) if origin is Annotated else (annotation,)
    here = tags + tuple(m.tag for m in metadata if isinstance(m, Tag))
    if get_origin(inner) in (Union, types.UnionType):
        return [alternative for member in get_args(inner)
                for alternative in _alternatives(member, here)]
    if isinstance(inner, type) and issubclass(inner, BaseModel):
        here += tuple(tag for key in DISCRIMINATORS if key in inner.model_fields
                      and get_origin(inner.model_fields[key].annotation) is Literal
                      for tag in get_args(inner.model_fields[key].annotation))
    return [(annotation, here)]


def _bare(annotation: Any) -> Any:
    """The type inside Annotated."""
    return get_args(annotation)[0] if get_origin(annotation) is Annotated else annotation


def _annotations_at(loc: tuple) -> list[Any] | None:
    """The annotations of the value at a location in SceneConfig (an error's: keys, list
    indices and pydantic's names of union members), each with the bounds it carries; None
    where a key is not in the schema."""
    current: list[Any] = [SceneConfig]
    for part in loc:
        alternatives = [alt for annotation in current for alt in _alternatives(annotation)]
        members = [_bare(a) for a, _ in alternatives]
        if isinstance(part, int):
            current = [item for member in members if get_origin(member) in (list, tuple)
                       for item in _items(member, part)]
        elif _is_branch_tag(part):   # the member named (others: constrained-float, list[...])
            current = [a for a, tags in alternatives if part in tags] or current
        else:
            current = [member.model_fields[member._input_names()[part]].rebuild_annotation()
                       for member in members if isinstance(member, type)
                       and issubclass(member, _Strict) and part in member._input_names()]
        if not current:
            return None
    return current


def _shown(value: Any) -> str:
    """repr(value), except for a time, alone or in a list (YAML reads an unquoted one as a
    datetime: shown in ISO 8601, as written) and an integer too long for repr (more than 4300
    digits: a ValueError)."""
    if isinstance(value, (datetime.date, datetime.time)):
        return value.isoformat()
    if isinstance(value, list) and any(isinstance(v, (datetime.date, datetime.time))
                                       for v in value):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    try:
        return repr(value)
    except ValueError:
        return too_long_integer()


def _describe(error: dict) -> str:
    path = _key_path(tuple(error.get("loc", ())))
    kind = error.get("type", "")
    ctx = error.get("ctx") or {}
    msg = error.get("msg", "invalid")
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    if kind == SHOWN_VALUE:   # (`inf` as written, 1e+20): raised for the model or for the key
        where = path if "key" not in ctx else \
            ("" if path == "(top level)" else f"{path}.") + ctx["key"]
        return f"{where} = {ctx['value']}: {ctx['problem']}"
    if kind == QUOTED_NUMBER:   # raised for the model: its key is below the path
        where = "" if path == "(top level)" else f"{path}."
        return (f"{where}{ctx['key']} = {ctx['value']!r}: expected a number, got a string "
                "(write the number without quotes)")
    if kind == "extra_forbidden":
        return f"{path}: unknown key{_suggestion(error.get('loc', ()))}"
    if kind == "missing":
        return f"{path}: required key is missing"
    key = str(ctx.get("discriminator", "model")).strip("'")   # model, or a profile's profile
    if kind == "union_tag_invalid":
        return (f"{path}.{key} = {ctx.get('tag')!r}: unknown {key}; allowed: "
                f"{ctx.get('expected_tags')}")
    if kind == "union_tag_not_found":
        return f"{path}.{key}: required key is missing"
    if path == "(top level)" and kind == "value_error":
        return msg
    loc = tuple(error.get("loc", ()))
    forms = _union_forms(loc)
    if kind in _LENGTH_ERRORS:   # (a list member of a union too: wavelengths_nm: [])
        # a list of too few or too many (water.layers: []): pydantic's 'List should have at
        # least 1 item after validation, not 0' in the house words
        count = ctx.get("min_length") if kind == "too_short" else ctx.get("max_length")
        msg = (f"allowed: {'at least' if kind == 'too_short' else 'at most'} {count} "
               f"item{'s' if count != 1 else ''} (found {ctx.get('actual_length')})")
    elif kind in _BOOLEAN_ERRORS and not forms:
        msg = "allowed: true or false"
    elif kind == "literal_error" and "expected" in ctx and not forms:
        # one of a few words (surface.model: coxmunk): pydantic's 'Input should be ...' in the
        # words of every other message, with the nearest word when it is a misspelling
        msg = f"allowed: {ctx['expected']}{_nearest_word(error.get('input'), ctx['expected'])}"
    elif kind in _NOT_A_NUMBER and forms:
        # one member of a union that also takes a list, a file or a profile: its range alone
        # would read as all that is allowed (and a validator may bound it further, chl_mg_m3's
        # 100 mg/m3)
        msg = f"expected a number or {' or '.join(forms)}"
    else:
        allowed = _allowed_range(error) or (" or ".join(forms) if kind in _WRONG_FORM
                                            and len(forms) > 1 else "")
        expected = _expected_form(loc) if kind in _WRONG_FORM and not allowed else ""
        if allowed:
            msg = f"allowed: {allowed}"
        elif expected:
            msg = f"expected {expected}"
        if kind == "literal_error":   # a word of a union's (illumination.sky: unifrom)
            msg += _nearest_word(error.get("input"), str(ctx.get("expected", "")))
    if "input" in error and not isinstance(error["input"], dict):
        shown = _shown(error["input"])
        if len(shown) > 80:
            shown = shown[:77] + "..."
        return f"{path} = {shown}: {msg}"
    return f"{path}: {msg}"


def _nearest_word(value: object, expected: str) -> str:
    """' (did you mean 'cox_munk'?)' where `value` is a misspelling of one of the quoted words
    of pydantic's `expected` ("'flat', 'none' or 'cox_munk'"); '' otherwise."""
    if not isinstance(value, str):
        return ""
    words = re.findall(r"'([^']*)'", expected)
    near = difflib.get_close_matches(value.lower(), words, n=1, cutoff=0.6)
    return f" (did you mean {near[0]!r}?)" if near else ""


# and for a list of too few or too many items, and a value that is no boolean
_LENGTH_ERRORS = frozenset({"too_short", "too_long"})
_BOOLEAN_ERRORS = frozenset({"bool_parsing", "bool_type"})


# pydantic's types of the error for a number beyond one of its bounds
_BOUND_ERRORS = frozenset({"greater_than", "greater_than_equal", "less_than", "less_than_equal"})


# and for a value that is not a number where one is needed (`chl_mg_m3: one`)
_NOT_A_NUMBER = frozenset({"float_parsing", "float_type", "int_parsing", "int_type",
                           "int_from_float"})


def _allowed_range(error: dict) -> str:
    """For a number beyond a bound, or a value that is no number where one is needed, the
    numbers its key allows, in words (base.allowed_numbers: pydantic's message names only the
    bound it broke, `Input should be greater than or equal to 2`, or none); '' for another
    error, or a location not found in the schema."""
    kind = error.get("type")
    if kind not in _BOUND_ERRORS and kind not in _NOT_A_NUMBER:
        return ""
    annotations = _annotations_at(tuple(error.get("loc", ())))
    broken = error.get("ctx") if kind in _BOUND_ERRORS else None
    return allowed_numbers(annotations, broken) if annotations else ""


# pydantic's types of the error for a value of the wrong form (not one a member's own checks
# refused)
_WRONG_FORM = frozenset({"list_type", "tuple_type", "literal_error", "dict_type", "model_type",
                         "model_attributes_type"})


def _expected_form(loc: tuple) -> str:
    """For a value of the wrong form at a key of one form (`raman: on`, `excitation_range_nm:
    400`): that form in words, a mapping with its keys or a list of so many numbers
    (pydantic names a Python type: 'a valid dictionary or instance of Raman', 'a valid
    tuple'); '' where the schema gives no one form."""
    forms, models = [], {}
    for annotation in _annotations_at(loc) or []:
        for member, _ in _alternatives(annotation):
            bare = _bare(member)
            items = [a for a in get_args(bare) if a is not Ellipsis]
            if get_origin(bare) is tuple and Ellipsis not in get_args(bare):
                numbers = all(_bare(a) in (int, float) for a in items)
                forms.append(f"a list of {len(items)} {'numbers' if numbers else 'values'}")
            elif get_origin(bare) in (list, tuple):
                forms.append("a list")
            elif isinstance(bare, type) and issubclass(bare, BaseModel):
                forms.append(f"a mapping of its keys ({', '.join(bare.model_fields)})")
                for key in DISCRIMINATORS:   # a member chosen by its model (or profile)
                    if key in bare.model_fields:
                        models.setdefault(key, []).extend(
                            get_args(bare.model_fields[key].annotation))
    if len(forms) > 1 and len(models) == 1 and len(forms) == len(next(iter(models.values()))):
        # a union of models chosen by one key, each of one value: name that key's values
        (key, values), = models.items()
        return (f"a mapping {{{key}: ..., ...}} with {key} one of "
                f"{', '.join(dict.fromkeys(map(str, values)))}")
    return " or ".join(forms) if len(forms) == 1 else ""


def _union_forms(loc: tuple) -> list[str]:
    """For an error at a member of a union that chooses its member by the value's form (a list
    or {start, stop, step} for wavelengths_nm; a sky's name or {map: FILE}): the forms other
    than a number the key allows, in words (pydantic names only those of the member it
    tried); [] where the error is not at a union's member."""
    if not (loc and _is_branch_tag(loc[-1])):
        return []
    forms = []
    for annotation in _annotations_at(loc[:-1]) or []:
        for member, _ in _alternatives(annotation):
            bare = _bare(member)
            if get_origin(bare) is Literal:
                forms.append(", ".join(repr(v) for v in get_args(bare)))
            elif get_origin(bare) in (list, tuple):
                forms.append("a list")
            elif isinstance(bare, type) and issubclass(bare, BaseModel):
                keys = [name for name, field in bare.model_fields.items() if field.is_required()]
                forms.append(f"a mapping {{{', '.join(keys)}}}")
    return forms


def _first_problem(errors: list[dict]) -> tuple[str, int]:
    """The message for pydantic's first error, and how many errors it covers. A value that
    fits no member of a union (upward_fraction: a number in (0, 1), 'auto' or null) gets one
    error per member at the same key: one line with what each member allows. An unknown key
    close to a valid one, beside missing keys in the same mapping (a misspelt key), is named
    first with the nearest valid key; else the missing key is."""
    def parent(error: dict) -> str:
        return _key_path(tuple(error.get("loc", ()))[:-1])

    first = errors[0]
    if first.get("type") == "missing":
        missing = {str(e["loc"][-1]) for e in errors if e.get("type") == "missing"
                   and e.get("loc") and parent(e) == parent(first)}
        unknown = [e for e in errors
                   if e.get("type") == "extra_forbidden" and parent(e) == parent(first)]
        suggested = {id(e): _suggested_key(tuple(e.get("loc", ()))) for e in unknown}
        named = [e for e in unknown if suggested[id(e)] is not None]
        if named:
            # an unknown key that names a missing one (`latitude` for latitude_deg) and that
            # missing key are one problem: the count of the others says so too
            pairs = sum(suggested[id(e)][1] and suggested[id(e)][0] in missing for e in named)
            return _describe(named[0]), 1 + pairs
    loc = tuple(first.get("loc", ()))
    if loc and _is_branch_tag(loc[-1]) and first.get("type") in _WRONG_FORM:
        # a value of one member's form that the member refused (theta_edges_deg: ['a'], a
        # list, but not of numbers): that member's error, not the other's "wrong form"
        path = _key_path(loc)
        for error in errors[1:]:
            deeper = tuple(error.get("loc", ()))
            if _key_path(deeper).startswith(path) and not (
                    _is_branch_tag(deeper[-1]) and error.get("type") in _WRONG_FORM):
                return _describe(error), 1
    # (a member that is a model reports its own keys after the tag: described as they are)
    if not (loc and _is_branch_tag(loc[-1])) or isinstance(first.get("input"), dict):
        return _describe(first), 1
    path = _key_path(loc)
    members = [e for e in errors if _key_path(tuple(e.get("loc", ()))) == path]
    if len(members) == 1:
        return _describe(first), 1
    allowed: list[str] = []
    for error in members:
        text = _allowed_range(error) or error.get("msg", "").split(", unable")[0]
        text = text[len("Input should be "):] if text.startswith("Input should be ") else text
        if text not in allowed:
            allowed.append(text)
    shown = _shown(first["input"]) if "input" in first else "this value"
    if len(shown) > 80:
        shown = shown[:77] + "..."
    return f"{path} = {shown}: allowed: {' or '.join(allowed)}", len(members)


def load_config(source: str | Path | dict[str, Any], overrides: dict[str, Any] | None = None,
                *, base_dir: str | Path | None = None) -> SceneConfig:
    """Reads a scene from a YAML file path or a dict, applies top-level overrides (photons, seed),
    and returns the validated SceneConfig. Raises ConfigError with one clear message. Table files
    named in a dict are relative to base_dir (default: the current folder); a sweep's points
    are dicts made from a YAML file, whose folder they keep."""
    origin = "config"
    if isinstance(source, (str, Path)):
        path = Path(source)
        origin = str(path)
        data = read_yaml_file(path, origin)
        base_dir = path.parent
    elif isinstance(source, dict):
        data = source
        base_dir = Path.cwd() if base_dir is None else Path(base_dir)
    else:
        raise ConfigError(f"{origin}: expected a YAML file path or a mapping, got "
                          f"{type(source).__name__}")
    if data is None:
        raise ConfigError(f"{origin}: the file is empty; a scene needs at least water and bottom")
    if not isinstance(data, dict):
        raise ConfigError(f"{origin}: the top level must be a mapping of keys (name, photons, "
                          f"water, bottom, ...), got {type(data).__name__}")
    data = dict(data)
    given = {key: value for key, value in (overrides or {}).items() if value is not None}
    _check_overridden({key: data[key] for key in given if key in data}, origin)
    data.update(given)
    try:
        config = SceneConfig.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors()
        first, shown = _first_problem(errors)
        blamed = [key for key, value in (overrides or {}).items()
                  if value is not None and (first.startswith(f"{key} ")
                                            or first.startswith(f"{key}:"))]
        if blamed:  # the value came from the command line, not from the file
            origin = f"--{blamed[0]} (with {origin})"
        rest = len(errors) - shown
        more = f" (and {rest} more problem{'s' if rest > 1 else ''})" if rest else ""
        raise ConfigError(f"{origin}: {first}{more}") from None
    except RecursionError:
        raise ConfigError(f"{origin}: nested too deeply to be a scene") from None
    _resolve_files(config, base_dir, origin)
    return config


def _check_overridden(values: dict[str, Any], origin: str) -> None:
    """The file's own values of the top-level keys the command line overrides (--photons,
    --seed; load_config's overrides) are checked as well: `photons: many` is a mistake in the
    file whatever replaces it. Validated alone (the scene's other keys missing): only these
    keys' errors count, among them those of the model's own checks (a boolean or a quoted
    number, `seed: '5'`), whose location is the model's, (): only these keys are there."""
    if not values:
        return
    try:
        SceneConfig.model_validate(values)
    except ValidationError as exc:
        errors = [e for e in exc.errors() if _error_key(e) in values]
        if errors:
            first, _ = _first_problem(errors)
            raise ConfigError(f"{origin}: {first} (the file's value, which is overridden, "
                              "must be valid too)") from None


def _error_key(error: dict) -> str | None:
    """The top-level key an error of SceneConfig is about: the first of its location, or, for
    one raised by the model's own checks (location ()), the key they name in the error's
    context (a quoted number) or at the start of its message (`photons = True: ...`)."""
    loc = tuple(error.get("loc", ()))
    if loc:
        return loc[0] if isinstance(loc[0], str) else None
    named = (error.get("ctx") or {}).get("key")
    if not isinstance(named, str):
        msg = error.get("msg", "")
        msg = msg[len("Value error, "):] if msg.startswith("Value error, ") else msg
        named = msg.split(" = ", 1)[0] if " = " in msg else None
    return named.split("[", 1)[0].split(".", 1)[0] if named else None


def data_file_fields(config: SceneConfig) -> list[tuple[object, str, str]]:
    """(model, attribute, key path) of every data file the scene names: phase, component,
    profile and spectrum tables, the bottom's BRDF table and reflectance spectra, the sky
    map."""
    fields: list[tuple[object, str, str]] = []
    for i, layer in enumerate(config.water.layers):
        at = f"water.layers[{i}]"
        phases = [(c.phase, f"{at}.phase.components[{k}].phase")
                  for k, c in enumerate(layer.phase.components)] \
            if isinstance(layer.phase, Mixture) else [(layer.phase, f"{at}.phase")]
        for k, component in enumerate(layer.components or ()):
            where = f"{at}.components[{k}]"
            phases.append((getattr(component, "phase", None), f"{where}.phase"))
            if component.model == "table":
                fields.append((component, "file", f"{where}.file"))
            if getattr(component, "absorption_file", None) is not None:
                fields.append((component, "absorption_file", f"{where}.absorption_file"))
            for key, value in component.__dict__.items():
                if getattr(value, "profile", None) == "table":
                    fields.append((value, "file", f"{where}.{key}.file"))
        fields += [(phase, "file", f"{where}.file") for phase, where in phases
                   if isinstance(phase, TablePhase)]
    if isinstance(config.bottom, TableBottom):
        fields.append((config.bottom, "file", "bottom.file"))
    fields += [(value, "file", f"{key}.file") for key, value in reflectance_keys(config.bottom)
               if isinstance(value, ReflectanceSpectrum)]
    if config.illumination.spectrum.model == "table":
        fields.append((config.illumination.spectrum, "file", "illumination.spectrum.file"))
    if isinstance(config.illumination.sky, SkyMap):
        fields.append((config.illumination.sky, "map", "illumination.sky.map"))
    return fields


def file_keys(problem: str, config: SceneConfig) -> list[str]:
    """The key paths of the scene's data files a problem of building it is about: the file its
    message names (`BRDF table PATH: no such file`, `KEY.file: PATH: ...`)."""
    return [key for model, attribute, key in data_file_fields(config)
            if f"{getattr(model, attribute)}:" in problem]


def at_file_key(problem: str, config: SceneConfig) -> str:
    """A problem of a data file (`phase table PATH: no such file`) under the key that names the
    file (`water.layers[0].phase.file: phase table PATH: ...`), so that a scene with several
    tables says which; as it is where it names no file or starts with the key already."""
    keys = file_keys(problem, config)
    if keys and not any(problem.startswith(key) for key in keys):
        return f"{keys[0]}: {problem}"
    return problem


def _resolve_files(config: SceneConfig, base_dir: Path, origin: str) -> None:
    """Table files are relative to the config file's folder; they are checked when the scene is
    built (oceanmc/scene.py), which reports the file and the problem."""
    for model, attribute, key in data_file_fields(config):
        path = getattr(model, attribute)
        try:
            resolved = (base_dir / path).resolve()
        except (OSError, RuntimeError) as exc:   # RuntimeError: a symlink loop (Python < 3.13)
            raise ConfigError(f"{origin}: {key} = {path!r}: cannot resolve the path "
                              f"({getattr(exc, 'strerror', None) or exc})") from None
        setattr(model, attribute, str(resolved))


def data_file_hashes(config: SceneConfig) -> str:
    """JSON {path: sha256 of its content} of every data file the scene names: the stored config
    holds only the paths, so merge and resume compare these to refuse an edited table."""
    hashes = {}
    for model, attribute, _ in data_file_fields(config):
        path = getattr(model, attribute)
        digest = hashlib.sha256()
        try:   # not blocking on a FIFO, nor reading a device such as /dev/zero forever
            with open(os.open(path, os.O_RDONLY | os.O_NONBLOCK), "rb") as f:
                if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                    hashes[path] = "not a regular file"
                    continue
                while chunk := f.read(1 << 20):
                    digest.update(chunk)
            hashes[path] = digest.hexdigest()
        except (OSError, ValueError) as exc:   # the scene build reports it; this records it
            hashes[path] = f"unreadable ({getattr(exc, 'strerror', None) or exc})"
    return json.dumps(hashes, sort_keys=True)


def config_to_yaml(config: SceneConfig, spectrum: tuple | None = None) -> str:
    """The full resolved scene (defaults filled in) as YAML text; load_config reads it back.

    A spectrum from a model or a table (illumination.spectrum spectrl2 or table) resolves to
    Ed(0+) and its diffuse share per wavelength, which the scene's keys do not show (its
    diffuse_fraction key stays 0): they are written as comments under illumination's
    diffuse_fraction (YAML comments: the text still loads as the same scene). `spectrum`: the
    (Ed0, diffuse_fraction) arrays already computed by optics.illumination_spectrum, else they
    are computed here (and left out if they cannot be)."""
    text = yaml.safe_dump(config.model_dump(), sort_keys=False, allow_unicode=True)
    if config.illumination.spectrum.model == "flat":
        return text
    if spectrum is None:
        from ..optics.illumination import illumination_spectrum   # optics imports config
        try:
            spectrum = illumination_spectrum(config)[:2]
        except (ConfigError, OSError, ValueError):
            return text       # the scene's build reports the problem; nothing to note here
    note = spectrum_note(config, *spectrum)
    lines = text.splitlines(keepends=True)
    start = lines.index("illumination:\n")
    at = next(i for i in range(start + 1, len(lines))
              if lines[i].startswith("  diffuse_fraction:"))
    return "".join(lines[:at + 1] + [f"  # {line}\n" for line in note] + lines[at + 1:])


# at most this many wavelengths are listed one by one in the note (beyond: the range and mean)
NOTE_WAVELENGTHS = 64


def spectrum_note(config: SceneConfig, ed0, diffuse) -> list[str]:
    """Comment lines on what a spectrum model or table resolved to: the diffuse share of Ed(0+)
    per wavelength (its mean over the band), and Ed(0+) per wavelength."""
    import numpy as np
    model = config.illumination.spectrum.model
    wl = np.asarray(config.wavelengths, dtype=float)
    ed0, diffuse = np.asarray(ed0, dtype=float), np.asarray(diffuse, dtype=float)
    source = "SPECTRL2 (Bird & Riordan 1986)" if model == "spectrl2" else "the spectrum table"
    weighted = float((ed0 * diffuse).sum() / ed0.sum())
    lines = textwrap.wrap(
        f"diffuse_fraction is not used with spectrum {model}: {source} gave the sky's share "
        f"of Ed(0+) per wavelength, as used in this scene: mean {diffuse.mean():.4f} over "
        f"{wl[0]:g}-{wl[-1]:g} nm ({weighted:.4f} weighted by Ed(0+)), from "
        f"{diffuse.min():.4f} to {diffuse.max():.4f}", 92)

    if len(wl) > NOTE_WAVELENGTHS:   # the results file's attributes hold every value
        return lines

    def listing(values, digits):
        cells = [f"{w:g}: {v:.{digits}g}" for w, v in zip(wl, values)]
        return ["  " + ", ".join(cells[i:i + 6]) for i in range(0, len(cells), 6)]
    units = "W m-2 nm-1 times Ed0" if model == "spectrl2" else "the table's Ed0 times Ed0"
    return lines + ["diffuse share (nm: fraction):"] + listing(diffuse, 4) \
        + [f"Ed(0+) (nm: {units} = {config.illumination.Ed0:g}):"] + listing(ed0, 5)
