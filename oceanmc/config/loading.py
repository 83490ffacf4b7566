"""Reading a scene from YAML or a dict into a SceneConfig, one ConfigError per bad scene, and
writing it back as YAML."""
from __future__ import annotations

import types
from pathlib import Path
from typing import Annotated, Any, Literal, Union, get_args, get_origin

import yaml
from pydantic import BaseModel, Tag, ValidationError

from .base import ConfigError
from .bottom import TableBottom
from .illumination import SkyMap
from .phase import Mixture, TablePhase
from .scene import SceneConfig


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
                    for key in ("model", "profile"):   # the discriminating keys
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


def _key_path(loc: tuple) -> str:
    path = ""
    for part in loc:
        if isinstance(part, int):
            path += f"[{part}]"
        elif part in _UNION_TAGS or str(part).startswith(("list[", "literal[")):
            continue  # pydantic's union-branch tags are not keys the user wrote
        else:
            path += ("." if path else "") + str(part)
    return path or "(top level)"


def _describe(error: dict) -> str:
    path = _key_path(tuple(error.get("loc", ())))
    kind = error.get("type", "")
    ctx = error.get("ctx") or {}
    msg = error.get("msg", "invalid")
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    if kind == "extra_forbidden":
        return f"{path}: unknown key (check its spelling and level)"
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
    if "input" in error and not isinstance(error["input"], dict):
        shown = repr(error["input"])
        if len(shown) > 80:
            shown = shown[:77] + "..."
        return f"{path} = {shown}: {msg}"
    return f"{path}: {msg}"


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
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise ConfigError(f"{origin}: no such file") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise ConfigError(f"{origin}: cannot read it ({exc})") from None
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise ConfigError(f"{origin}: not valid YAML ({str(exc).splitlines()[0]} "
                              f"{getattr(exc, 'problem_mark', '') or ''})".strip()) from None
        except RecursionError:
            raise ConfigError(f"{origin}: nested too deeply to be a scene") from None
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
    for key, value in (overrides or {}).items():
        if value is not None:
            data[key] = value
    try:
        config = SceneConfig.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors()
        first = _describe(errors[0])
        more = f" (and {len(errors) - 1} more problem{'s' if len(errors) > 2 else ''})" \
            if len(errors) > 1 else ""
        raise ConfigError(f"{origin}: {first}{more}") from None
    except RecursionError:
        raise ConfigError(f"{origin}: nested too deeply to be a scene") from None
    _resolve_files(config, base_dir, origin)
    return config


def _resolve_files(config: SceneConfig, base_dir: Path, origin: str) -> None:
    """Table files are relative to the config file's folder; they are checked when the scene is
    built (oceanmc/scene.py), which reports the file and the problem."""
    def resolve(item) -> None:
        item.file = str((base_dir / item.file).resolve())

    for layer in config.water.layers:
        phases = [c.phase for c in layer.phase.components] \
            if isinstance(layer.phase, Mixture) else [layer.phase]
        for component in layer.components or ():
            phases.append(getattr(component, "phase", None))
            if component.model == "table":
                resolve(component)
            for value in component.__dict__.values():
                if getattr(value, "profile", None) == "table":
                    resolve(value)
        for phase in phases:
            if isinstance(phase, TablePhase):
                resolve(phase)
    if isinstance(config.bottom, TableBottom):
        config.bottom.file = str((base_dir / config.bottom.file).resolve())
    if config.illumination.spectrum.model == "table":
        resolve(config.illumination.spectrum)
    if isinstance(config.illumination.sky, SkyMap):
        config.illumination.sky.map = str((base_dir / config.illumination.sky.map).resolve())


def config_to_yaml(config: SceneConfig) -> str:
    """The full resolved scene (defaults filled in) as YAML text; load_config reads it back."""
    return yaml.safe_dump(config.model_dump(), sort_keys=False, allow_unicode=True)
