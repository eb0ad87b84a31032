"""Configuration: the same fields as the CLI's TOML file, as a nested dict or keyword arguments,
on top of an optional scenario (a TOML file or a dict of the same structure)."""

from __future__ import annotations

import errno
import json
import math
import numbers
import os
from typing import Any, Mapping, Union

from . import _ronap
from ._ronap import ConfigError

ScenarioLike = Union[str, "os.PathLike[str]", Mapping[str, Any]]
"""A scenario: the path of a TOML scenario file (as ``ronap run --scenario`` takes) or a dict
nested like it (``{"scene": {"kind": "warehouse"}, "moving": [{"count": 5}]}``)."""

class MissingFileError(FileNotFoundError, ConfigError):
    """A file ronap was given does not exist: a ``FileNotFoundError`` (``errno``, ``filename``)
    that is also a ``ConfigError`` (so a ``RonapError`` and a ``ValueError``)."""

    # FileNotFoundError first: OSError's constructor, message and pickling come before the plain
    # exception's of ConfigError in the MRO.


MissingFileError.__module__ = "ronap"


def checked_path(name: str, path: str | os.PathLike[str] | None) -> str | None:
    """``path`` as text, or ``MissingFileError`` naming ``name`` and the path when no file is there."""
    if path is None:
        return None
    text = os.fspath(path)
    if not os.path.exists(text):
        raise MissingFileError(errno.ENOENT, f"{name}: no such file", text)
    return text


# Top-level entries of a configuration that are arrays of tables, not sections.
_ARRAYS = ("obstacles", "moving", "robots")
# Sections the configuration's JSON leaves out while they hold their defaults.
_OPTIONAL = ("team", "observation")


def default_config() -> dict[str, Any]:
    """Every field with its default, nested by section like ``ronap config`` prints it."""
    return json.loads(_ronap.default_config_json())


def _merge(into: dict, section: str, field: str, value: Any) -> None:
    if section not in into and section in _OPTIONAL:
        into[section] = {}
    if section not in into:
        raise ConfigError(f"unknown configuration section {section!r} (in {section}.{field})")
    if section in _ARRAYS:
        raise ConfigError(f"{section}.{field}: {section} is a list of entries; give the whole list ({section}=[{{...}}, ...] in config)")
    into[section][field] = value


def _plain(value: Any) -> Any:
    """A value json cannot write as it is: a path as its text, a numpy scalar or array as numbers."""
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if hasattr(value, "tolist"):
        return value.tolist()
    raise ConfigError(f"{value!r}: not a configuration value (expected numbers, strings, booleans, lists or dicts)")


def _check_finite(value: Any, at: str) -> None:
    """Refuses NaN and infinities anywhere in ``value``, naming the key (json would write them as
    words no configuration reader takes)."""
    if isinstance(value, Mapping):
        for key, v in value.items():
            _check_finite(v, f"{at}.{key}" if at else str(key))
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            _check_finite(v, f"{at}[{i}]")
    elif isinstance(value, (float, numbers.Real)) and not isinstance(value, (bool, int)):
        if not math.isfinite(float(value)):
            raise ConfigError(f"{at} = {float(value)}: must be a finite number")
    elif hasattr(value, "tolist") and not isinstance(value, (str, bytes)):
        _check_finite(value.tolist(), at)


def _json(value: Any) -> str:
    _check_finite(value, "")
    return json.dumps(value, default=_plain)


def load_scenario(scenario: ScenarioLike | _ronap.Scenario | None) -> _ronap.Scenario | None:
    """The scenario as the extension takes it, read (a file) or checked for unknown keys and
    wrong types (a dict); ``ConfigError`` names the file, line, key and value."""
    if scenario is None or isinstance(scenario, _ronap.Scenario):
        return scenario
    if isinstance(scenario, (str, os.PathLike)):
        return _ronap.Scenario.read(checked_path("scenario", scenario))
    if isinstance(scenario, Mapping):
        return _ronap.Scenario.from_json(_json(dict(scenario)))
    raise ConfigError(f"scenario {scenario!r}: expected the path of a TOML scenario file or a dict nested like one")


def init_arguments(arguments: dict[str, Any]) -> dict[str, Any]:
    """A constructor's arguments as ``locals()`` holds them on its first line (``self`` left out,
    ``**fields`` spread): what pickling needs to build the object again."""
    kept = {k: v for k, v in arguments.items() if k not in ("self", "__class__", "fields")}
    return {**kept, **arguments.get("fields", {})}


def located(error: Exception, config: _ronap.Config) -> Exception:
    """``error`` with the scenario file and line of the ``[[moving]]`` / ``[[crowd]]`` field it
    names in front (a crowd pattern that leaves the scene is found only once the scene is built),
    or ``error`` as it is."""
    at = config.line_of(str(error))
    return type(error)(f"{at}: {error}") if at else error


def checked_config(
    config: Mapping[str, Any] | None,
    fields: Mapping[str, Any],
    scenario: ScenarioLike | _ronap.Scenario | None = None,
) -> _ronap.Config:
    """The configuration as the extension takes it: the scenario (else the defaults), then
    ``config``, then ``fields``, merged here and checked once in Rust."""
    base = load_scenario(scenario)
    merged = _merged(config, fields, None if base is None else json.loads(base.json))
    return _ronap.Config(_json(merged), base)


def make_config(
    config: Mapping[str, Any] | None = None,
    *,
    scenario: ScenarioLike | None = None,
    **fields: Any,
) -> dict[str, Any]:
    """A complete, checked configuration.

    ``scenario`` (a TOML scenario file or a dict nested like one) gives the starting values,
    else the defaults. ``config`` is nested (``{"maze": {"cols": 5}}``, ``{"moving": [...]}``) or
    flat with dotted keys (``{"maze.cols": 5}``) and overrides it; keyword arguments name
    ``section_field`` (``maze_cols=5``) and win over both. Raises ``ConfigError`` naming the
    field and value for anything unknown or out of range, and the file and line for a bad value
    a scenario file sets.
    """
    return json.loads(checked_config(config, fields, scenario).json)


def _merged(
    config: Mapping[str, Any] | None,
    fields: Mapping[str, Any],
    base: dict[str, Any] | None = None,
) -> dict[str, Any]:
    merged = default_config() if base is None else base
    for key, value in (config or {}).items():
        if "." in key:
            section, field = key.split(".", 1)
            _merge(merged, section, field, value)
        elif key in _ARRAYS:
            if isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__iter__"):
                raise ConfigError(f"configuration key {key!r}: expected a list of entries (dicts), got {value!r}")
            merged[key] = list(value)
        elif isinstance(value, Mapping):
            if key not in merged and key not in _OPTIONAL:
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


_U64 = 2**64

SPLITS = ("test", "validation", "train")
"""The seed splits, three disjoint spaces of episode seeds: ``test`` 0..=499999 (what
``ronap run --seeds N`` plays by default), ``validation`` 500000..=999999, ``train`` 1000000 and
up (docs/model.md, "Seed splits")."""


def split_range(split: str) -> tuple[int, int]:
    """The first and last seed of a split; ``ConfigError`` for a name that is not one."""
    if split not in SPLITS:
        raise ConfigError(f"split = {split!r}: expected one of {', '.join(SPLITS)} (or None for seeds as given)")
    first, last = _ronap.split_range(split)
    return int(first), int(last)


def checked_split(split: str | None) -> str | None:
    """``split`` itself when it is a split's name or None, else ``ConfigError``."""
    if split is not None:
        split_range(split)
    return split


def split_seed(split: str | None, seed: int, name: str = "seed") -> int:
    """Episode seed ``seed`` of ``split`` (counted from the split's first seed), or ``seed`` as
    given with no split; ``ConfigError`` when the split has no such seed."""
    if split is None:
        return seed
    first, last = split_range(split)
    if seed > last - first:
        raise ConfigError(f"{name} = {seed}: the {split} split holds {last - first + 1} seeds ({first}..={last})")
    return first + seed


COPY_LIMIT = 100_000
"""Most steps since its last full reset a vector environment keeps to be copied by replaying
them (``pickle``, ``copy.deepcopy``); a longer stretch is not kept and a copy is refused, naming
why."""

COPY_BYTES = 64 * 2**20
"""Most bytes of actions (a byte a discrete action) and messages a vector environment keeps for
copies, beside ``COPY_LIMIT``: with int64 copies, a ``VecNavEnv(1024)`` kept 800 MB over 100,000
steps, and each step's fresh memory cost it about 4% of its speed."""


def check_split_seeds(split: str | None, seeds: Any) -> None:
    """Refuses episode seeds that have left ``split`` (a vector environment's next seeds, ``s +
    i + n``, run on past a split's end), naming the split and the first such seed."""
    if split is None or split == "train":
        return
    first, last = split_range(split)
    beyond = [int(s) for s in seeds if not first <= int(s) <= last]
    if beyond:
        raise ConfigError(
            f"episode seed {beyond[0]}: the environments' next seeds have run past the {split} split "
            f"({first}..={last}); reset() with a seed nearer its start, or fewer environments"
        )


def split_draw_limit(split: str | None, room: int = 1) -> int:
    """How far a random seed index may go in ``split`` leaving ``room`` seeds after it (2^63 with
    no split)."""
    if split is None:
        return 2**63
    first, last = split_range(split)
    return max(1, min(last - first + 2 - room, 2**63))


def _sb3_object(value: Any) -> bool:
    module = type(value).__module__ or ""
    return module == "stable_baselines3" or module.startswith("stable_baselines3.")


def refuse_sb3_thread_safe(policy: Any, thread_safe: bool) -> None:
    """Refuses ``thread_safe=True`` for a policy that calls a Stable-Baselines3 model: its
    ``predict`` shares one distribution object between calls, so calls at once change episodes
    (4 of 200 in a test). Looks at a bound method's object, a closure's cells and the globals a
    function names (``lambda obs: model.predict(obs)[0]``)."""
    if not thread_safe or not callable(policy) or isinstance(policy, str):
        return
    seen: list[Any] = [getattr(policy, "__self__", None), policy]
    code = getattr(policy, "__code__", None)
    for cell in getattr(policy, "__closure__", None) or ():
        try:
            seen.append(cell.cell_contents)
        except ValueError:  # an empty cell
            pass
    if code is not None:
        names = getattr(policy, "__globals__", {})
        seen.extend(names[n] for n in code.co_names if n in names)
    culprit = next((v for v in seen if v is not None and _sb3_object(v)), None)
    if culprit is not None:
        raise ConfigError(
            f"thread_safe=True with a Stable-Baselines3 {type(culprit).__name__}: its predict() shares one "
            "distribution object between calls, so calls at once change episodes; leave thread_safe off "
            "(calls take turns) or pass batch=N to decide many episodes in one call"
        )


def checked_int(name: str, value: Any, least: int = 0, below: int = _U64) -> int:
    """``value`` as an int in ``[least, below)``, else a ``ConfigError`` naming ``name`` and the
    value (bools, floats with a fraction and out-of-range numbers included)."""
    if isinstance(value, bool) or not hasattr(value, "__index__"):
        if not (isinstance(value, float) and value.is_integer()):
            raise ConfigError(f"{name} = {value!r}: expected a whole number")
    number = int(value)
    if not least <= number < below:
        high = "2^64 - 1" if below == _U64 else str(below - 1)
        raise ConfigError(f"{name} = {value!r}: must be between {least} and {high}")
    return number


def checked_seeds(seeds: Any, split: str | None = None) -> list[int]:
    """Episode seeds as a list of ints in ``[0, 2^64)``, counted from ``split``'s first seed when
    one is named; a ``ConfigError`` names the first bad one."""
    if isinstance(seeds, range) and len(seeds) > 0:
        # A range's seeds lie between its ends: when both are good, so is every seed (one by
        # one, a million seeds took a second). Else the loop below names the first bad one.
        first, last = (0, _U64 - 1) if split is None else split_range(split)
        if all(0 <= s <= last - first for s in (seeds[0], seeds[-1])):
            return list(range(seeds.start + first, seeds.stop + first, seeds.step))
    try:
        items = list(seeds)
    except TypeError:
        raise ConfigError(f"seeds = {seeds!r}: expected an iterable of whole numbers (e.g. range(1000))") from None
    return [split_seed(split, checked_int(f"seeds[{i}]", s), f"seeds[{i}]") for i, s in enumerate(items)]
