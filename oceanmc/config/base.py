"""What every part of the schema shares: the error type, the strict base model, number types."""
from __future__ import annotations

import math
import re
import sys
import types
import typing
from typing import Annotated, Any

import yaml
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator
from pydantic_core import PydanticCustomError


class ConfigError(ValueError):
    """A scene that cannot be run; the message names the key, the value and what is allowed."""


def _members(annotation: Any) -> list[Any]:
    """The types a value may take under an annotation: through Annotated and unions."""
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        return _members(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        return [m for a in typing.get_args(annotation) for m in _members(a)]
    return [annotation]


def _admits_boolean(annotation: Any) -> bool:
    """Whether a field may take a boolean: a bool, Any, or a Literal (whose own validator may
    read one, as depth_splitting reads YAML's `on`), alone or in a union, through Annotated."""
    return any(m in (bool, Any) or typing.get_origin(m) is typing.Literal
               for m in _members(annotation))


def _expected(annotation: Any) -> str:
    """What a field takes, in words, for a message: a mapping (a group of keys), a list, a
    string or a number (or several of them, for a union)."""
    def kind(member: Any) -> str:
        if isinstance(member, type) and issubclass(member, BaseModel):
            return "a mapping"
        if member is str:
            return "a string"   # (`name: off`: not a number)
        return "a list" if typing.get_origin(member) in (list, tuple) else "a number"

    given = {kind(m) for m in _members(annotation) if m is not type(None)} or {"a number"}
    kinds = [k for k in ("a number", "a string", "a list", "a mapping") if k in given]
    return " or ".join([", ".join(kinds[:-1]), kinds[-1]]) if len(kinds) > 1 else kinds[0]


def _string_for_a_number(value: Any, annotations: list[Any]
                         ) -> tuple[str, str, list[Any]] | None:
    """(where, the string, the annotations it was given for) of a number given as a string
    where only a number is allowed (`'30'`, a number quoted in the YAML; see _quoted_number),
    in value or the lists it holds: where is '' or list indices ('[1]'); None if there is none.
    A member that takes the string (str, Any, a Literal holding it such as 'hydrolight' or
    'auto') lets it through, as does an annotation without a number (a model's own checks
    judge what it is given)."""
    members = [m for a in annotations for m in _members(a)]
    if isinstance(value, str):
        takes_string = any(m in (str, Any) or (typing.get_origin(m) is typing.Literal
                                               and value in typing.get_args(m))
                           for m in members)
        numbers = any(m in (int, float) for m in members)
        return ("", value, annotations) \
            if numbers and not takes_string and _quoted_number(value) else None
    if isinstance(value, (list, tuple)):
        sequences = [m for m in members if typing.get_origin(m) in (list, tuple)]
        if not sequences:
            return None
        for i, item in enumerate(value):
            found = _string_for_a_number(item, [a for m in sequences for a in _items(m, i)])
            if found is not None:
                return f"[{i}]{found[0]}", found[1], found[2]
    return None


def _items(sequence: Any, i: int) -> list[Any]:
    """The annotations item i of a list or tuple annotation may take: a list's item type, a
    fixed tuple's i-th (tuple[float, float]: one per position)."""
    args = typing.get_args(sequence)
    if typing.get_origin(sequence) is tuple and Ellipsis not in args:
        return [args[i]] if i < len(args) else []
    return [a for a in args if a is not Ellipsis]


def _numbers(annotation: Any, metadata: tuple = ()) -> list[tuple[type, tuple]]:
    """(int or float, its constraints: annotated_types' Ge, Gt, Le, Lt, AllowInfNan) of each
    number a value may be under an annotation, through Annotated (and a Field() in it) and
    unions; lists, models and names are left out."""
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        inner, *extra = typing.get_args(annotation)
        found = [c for m in extra for c in (getattr(m, "metadata", None) or [m])]
        return _numbers(inner, metadata + tuple(found))
    if origin in (typing.Union, types.UnionType):
        return [n for a in typing.get_args(annotation) for n in _numbers(a, metadata)]
    return [(annotation, metadata)] if annotation in (int, float) else []


def _bound(value: float) -> str:
    if value == int(value) and abs(value) < 1e6:
        return str(int(value))
    short = f"{value:.6g}"
    # an integer bound that 6 digits would round (seed's 2**63 - 1, not 9.22337e+18) exactly
    return str(value) if isinstance(value, int) and float(short) != value else short


def _allowed_number(kind: type, constraints: tuple) -> str:
    """`a number >= 0 and < 90`, `an integer 2 .. 100000`, `a number 0 .. 1`."""
    get = {name: getattr(c, name) for c in constraints for name in ("ge", "gt", "le", "lt")
           if getattr(c, name, None) is not None}
    what = "an integer" if kind is int else "a number"
    if kind is int:   # > 0 is >= 1
        get |= {"ge": get.pop("gt") + 1} if "gt" in get else {}
        get |= {"le": get.pop("lt") - 1} if "lt" in get else {}
    if "ge" in get and "le" in get:
        return f"{what} {_bound(get['ge'])} .. {_bound(get['le'])}"
    parts = [f"{sign} {_bound(get[name])}" for name, sign in
             (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")) if name in get]
    if not parts:
        return "a finite number" if kind is float else what
    return f"{what} {' and '.join(parts)}"


def _admits_infinity(kind: type, constraints: tuple, sign: float) -> bool:
    """Whether a number of this kind and these constraints may be +inf (sign 1) or -inf (-1)."""
    bounds = ("le", "lt") if sign > 0 else ("ge", "gt")
    return kind is float and not any(getattr(c, "allow_inf_nan", True) is False
                                     or any(getattr(c, b, None) is not None for b in bounds)
                                     for c in constraints)


_NON_FINITE_WORD = re.compile(r"^\s*[-+]?(?:inf|infinity|nan)\s*$", re.IGNORECASE)


def non_finite_text(text: str, annotations: list[Any]) -> str | None:
    """What is wrong with `inf`, `-inf` or `nan` (YAML 1.1 reads them bare as strings; .inf
    and .nan are its infinity and NaN) given for a number, and what is allowed; None for any
    other string. Where the key takes infinity (a layer's thickness_m), the way to write it."""
    if not _NON_FINITE_WORD.match(text):
        return None   # (1e400, which float() makes inf, is a number beyond the range)
    number = float(text)
    if math.isinf(number) and any(_admits_infinity(*n, number)
                                  for a in annotations for n in _numbers(a)):
        return (f"YAML reads a bare {text} as text; write {'-' if number < 0 else ''}.inf for "
                "infinity")
    return f"not a finite number; allowed: {allowed_numbers(annotations) or 'a finite number'}"


def allowed_numbers(annotations: list[Any], broken: dict[str, Any] | None = None) -> str:
    """The numbers the annotations allow, in words (`an integer 2 .. 100000`, `a number >= 0
    and < 90`, several joined by `or`); '' where they hold no number. broken: the bound a
    value broke, as pydantic's error context gives it ({'ge': 2}), to name only the numbers
    with that bound (those of a union's member the value was tried against)."""
    numbers = [n for a in annotations for n in _numbers(a)]
    if broken:
        numbers = [(kind, constraints) for kind, constraints in numbers
                   if any(getattr(c, name, None) == bound for c in constraints
                          for name, bound in broken.items())] or numbers
    return " or ".join(dict.fromkeys(_allowed_number(*n) for n in numbers))


def too_long_integer() -> str:
    """How a message shows an integer that str() and repr() refuse (more digits than
    sys.get_int_max_str_digits(), 4300 by default: a ValueError)."""
    return f"an integer of more than {sys.get_int_max_str_digits()} digits"


# the type of the error for a number given as a string (config/loading.py _describe)
QUOTED_NUMBER = "quoted_number"
# and for a value shown otherwise than as pydantic's repr of the input: inf or nan as written
# (strings, to YAML 1.1, not quoted), a 21-digit photon count as 1e+20. Its context holds the
# value as shown, what is wrong with it and, raised for a model, the key below its path
SHOWN_VALUE = "shown_value"


def shown_value_error(shown: str, problem: str, key: str | None = None) -> PydanticCustomError:
    context = {"value": shown, "problem": problem} | ({"key": key} if key is not None else {})
    return PydanticCustomError(SHOWN_VALUE, ("{key} = " if key is not None else "")
                               + "{value}: {problem}", context)


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_default=True)

    @model_validator(mode="before")
    @classmethod
    def _no_boolean_for_a_number(cls, data: Any) -> Any:
        # pydantic takes True for 1 and False for 0, and YAML reads yes, no, on, off, true and
        # false as booleans: `a: yes` would run with a = 1 (a boolean where a number, a list
        # or a table is expected is refused here, naming the key)
        if isinstance(data, dict):
            names = cls._input_names()
            cls._no_name_twice(data, names)
            for name, value in data.items():
                field = cls.model_fields.get(names.get(name, "")) if isinstance(name, str) \
                    else None
                if isinstance(value, bool) and field is not None \
                        and not _admits_boolean(field.annotation):
                    raise ValueError(f"{name} = {value}: expected "
                                     f"{_expected(field.annotation)} (YAML reads true, false, "
                                     "yes, no, on and off as booleans)")
                # pydantic reads the string '30' as 30: a number quoted in the YAML ran as the
                # number. Other strings are left to pydantic's message, as is a field whose own
                # validator reads strings (photons' '1e6'). The error's type tells
                # config/loading.py to name the key below the model's path
                found = _string_for_a_number(value, [field.rebuild_annotation()]) \
                    if field is not None and name not in cls._reads_strings() else None
                problem = non_finite_text(found[1], found[2]) if found is not None else None
                if problem is not None:   # `a: inf`, unquoted: not a quoted number
                    raise shown_value_error(found[1], problem, f"{name}{found[0]}")
                if found is not None:
                    raise PydanticCustomError(
                        QUOTED_NUMBER, "{key} = {value!r}: expected a number, got a string",
                        {"key": f"{name}{found[0]}", "value": found[1]})
        return data

    @classmethod
    def _reads_strings(cls) -> set[str]:
        """The fields with a validator of their own that runs before pydantic's."""
        return {name for decorator in cls.__pydantic_decorators__.field_validators.values()
                if decorator.info.mode in ("before", "wrap", "plain")
                for name in decorator.info.fields}

    @classmethod
    def _input_names(cls) -> dict[str, str]:
        """{a key the input may use: its field's name}: each field's own name, and the other
        names its validation_alias accepts (a gaussian profile's total_mg_m2 for integral)."""
        names = {}
        for field_name, field in cls.model_fields.items():
            names[field_name] = field_name
            for choice in getattr(field.validation_alias, "choices", ()):
                if isinstance(choice, str):
                    names[choice] = field_name
        return names

    @staticmethod
    def _no_name_twice(data: dict, names: dict[str, str]) -> None:
        """One quantity given under two of its names (integral and total_mg_m2) is refused
        as such: pydantic took the first and called the other an unknown key."""
        given: dict[str, list[str]] = {}
        for key in data:
            if isinstance(key, str) and key in names:
                given.setdefault(names[key], []).append(key)
        for field_name, keys in given.items():
            if len(keys) > 1:
                other = next(k for k in keys if k != field_name)
                raise ValueError(
                    f"{keys[0]} = {data[keys[0]]!r} and {keys[1]} = {data[keys[1]]!r}: the same "
                    f"quantity given twice ({other} is another name for {field_name}); give "
                    "one of them")


# A number written with an exponent: PyYAML reads YAML 1.1, where only one with a decimal
# point and a signed exponent (1.5e-3) is a float; 1e-3, 1e6 and 2.5e3 are read as strings
# (as yaml.safe_load reads them wherever a stored config or sweep is read back)
_EXPONENT_NUMBER = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$")
_YAML_RESOLVER = yaml.resolver.Resolver()


def _quoted_number(text: str) -> bool:
    """Whether a string given for a number is a number in quotes ('30', '0.5', '1.5e-3'), to be
    refused, rather than what PyYAML makes of an unquoted exponent number (1e-3, 2.5e3, 1e6:
    strings under YAML 1.1), let through for pydantic to read as the number, as it always was.
    The limitation: a quoted '1e-3' cannot be told from an unquoted 1e-3 and is read as the
    number too."""
    try:
        float(text)
    except ValueError:
        return False
    unquoted = _YAML_RESOLVER.resolve(yaml.ScalarNode, text, (True, False))
    return not (_EXPONENT_NUMBER.match(text) and unquoted == "tag:yaml.org,2002:str")


def exponent_number(value: Any) -> Any:
    """The number of a string that PyYAML (YAML 1.1) makes of an unquoted exponent number
    (1e-3, 2.5e3, 1e6: see _quoted_number), as the float; any other value as it is. For values
    read without a schema to judge them (a sweep's axes), where pydantic would read the string
    as the number. The same limitation: a quoted '1e-3' is read as the number too."""
    if isinstance(value, str) and _EXPONENT_NUMBER.match(value) and \
            _YAML_RESOLVER.resolve(yaml.ScalarNode, value, (True, False)) == \
            "tag:yaml.org,2002:str":
        return float(value)
    return value


Finite = Annotated[float, Field(allow_inf_nan=False)]
# The narrowest theta band accepted (deg): its 1 - cos, 1.5e-10, is resolved by float64
# direction cosines (spacing 1.1e-16 below 1) to 1e-6 relative; 1 - cos(1e-6 deg) = 1.5e-16 is not.
MIN_ANGLE_DEG = 0.001
NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]
# Absorption and scattering coefficients: the most turbid natural waters reach ~1e3 1/m; larger
# finite values (1e308) would overflow a + b and the optical depths.
MAX_COEFFICIENT = 1e6
Coefficient = Annotated[float, Field(ge=0.0, le=MAX_COEFFICIENT, allow_inf_nan=False)]
# Layer thicknesses and profile depths: larger finite values only overflow optical depths
# (c x thickness) without meaning anything.
MAX_THICKNESS_M = 1e6
Fraction = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]
# the units a scene key's name ends with (thickness_m, sun_zenith_deg, chl_mg_m3,
# wind_speed_m_s, b488_per_m), in CF's spelling, longest first where one ends another; and the
# IOP coefficients, whose names do not say them
UNIT_SUFFIXES = (("_per_m", "m-1"), ("_mg_m3", "mg m-3"), ("_atm_cm", "atm-cm"),
                 ("_m_s", "m s-1"), ("_deg", "degree"), ("_nm", "nm"), ("_pa", "Pa"),
                 ("_cm", "cm"), ("_m", "m"))
COEFFICIENT_KEYS = frozenset({"a", "b", "bb", "c", "a440", "a443", "b550"})


def key_units(name: str) -> str | None:
    """The units of the scene key `name` (its last path element: thickness_m -> m), or None
    where its name does not say (a reflectance, a count, a model's name)."""
    if name in COEFFICIENT_KEYS:
        return "m-1"
    return next((units for suffix, units in UNIT_SUFFIXES if name.endswith(suffix)), None)
# An asymmetry parameter (Henyey-Greenstein g, the Hapke grains', SPECTRL2's aerosols'): within
# 1e-6 of +-1, as nothing natural comes near; closer, the computations lose all precision (a
# Henyey-Greenstein g of 1 - 1e-10 gave NaN local estimates, SPECTRL2's aerosol factor of
# 1 - 1e-8 NaN irradiances). The bounds are the field's own, so that 1 and 0.9999995 are
# refused with the same range (a validator after > -1 and < 1 named two: a user's review)
MAX_ASYMMETRY = 1.0 - 1e-6
Asymmetry = Annotated[float, Field(ge=-MAX_ASYMMETRY, le=MAX_ASYMMETRY, allow_inf_nan=False)]


def _file_path(path: str) -> str:
    if not path.strip():   # (resolved against the config's folder, it would name the folder)
        raise ValueError("a file path cannot be empty")
    if "\0" in path:   # the operating system cannot take it (a ValueError deep in pathlib)
        raise ValueError("a file path cannot contain a NUL byte")
    return path


# a data file's path (relative to the YAML file's folder)
FilePath = Annotated[str, AfterValidator(_file_path)]
