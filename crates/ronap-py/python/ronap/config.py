"""Configuration: the same fields as the CLI's TOML file, as a nested dict or keyword arguments."""

from __future__ import annotations

import json
from typing import Any, Mapping

from . import _ronap
from ._ronap import ConfigError


def default_config() -> dict[str, dict[str, Any]]:
    """Every field with its default, nested by section like ``ronap config`` prints it."""
    return json.loads(_ronap.default_config_json())


def _merge(into: dict, section: str, field: str, value: Any) -> None:
    if section not in into:
        raise ConfigError(f"unknown configuration section {section!r} (in {section}.{field})")
    into[section][field] = value


def checked_config(config: Mapping[str, Any] | None, fields: Mapping[str, Any]) -> _ronap.Config:
    """The configuration as the extension takes it: merged here, then checked once in Rust."""
    return _ronap.Config(json.dumps(_merged(config, fields)))


def make_config(config: Mapping[str, Any] | None = None, **fields: Any) -> dict[str, dict[str, Any]]:
    """A complete, checked configuration.

    ``config`` is nested (``{"maze": {"cols": 5}}``) or flat with dotted keys
    (``{"maze.cols": 5}``); keyword arguments name ``section_field`` (``maze_cols=5``) and win.
    Raises ``ConfigError`` naming the field and value for anything unknown or out of range.
    """
    return json.loads(checked_config(config, fields).json)


def _merged(config: Mapping[str, Any] | None, fields: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    merged = default_config()
    for key, value in (config or {}).items():
        if "." in key:
            section, field = key.split(".", 1)
            _merge(merged, section, field, value)
        elif isinstance(value, Mapping):
            if key not in merged:
                raise ConfigError(f"unknown configuration section {key!r}")
            for field, v in value.items():
                _merge(merged, key, field, v)
        else:
            raise ConfigError(f"configuration key {key!r}: expected a section (dict) or 'section.field'")
    for name, value in fields.items():
        section, _, field = name.partition("_")
        if not field:
            raise ConfigError(f"keyword {name!r}: expected section_field, e.g. maze_cols")
        _merge(merged, section, field, value)
    return merged
