"""Networks trained elsewhere, in ronap's weights file, to run at Rust speed as ``mlp:FILE``.

- ``export_policy(obj, path)``: a Stable-Baselines3 PPO, A2C or DQN model with an MLP policy and
  ``Discrete(3)`` actions, or a torch module made of ``Linear`` layers and activations: an
  ``nn.Sequential`` (in its order), or a module whose forward is code, taken as its ``Linear``
  layers in the order they were defined with its one kind of activation module between them.
- ``import_torch(file, path)``: a file ``torch.save`` wrote (a whole model, a ``state_dict`` or a
  checkpoint dict holding one), in the zip format of torch >= 1.6 or the legacy pickle format
  older projects used, the original RoNAP among them. It needs neither torch nor the classes of
  the program that saved the model: the file is read by a restricted unpickler that builds
  stand-ins for any class it names and never imports or runs code from it.
- ``mlp_outputs(path, observations)``: the network's outputs for a batch of observations, as the
  ``mlp:`` policy computes them (to check an export).

The weights file is described in ``policies/README.md``: ``Linear`` layers, one hidden activation
(``relu``, ``tanh``, ``rrelu``, ``leaky_relu:SLOPE``) after every layer but the last, and 3
outputs (LEFT, AHEAD, RIGHT) of which the policy takes the largest. What does not fit (another
number of outputs, continuous actions, two kinds of activation, an activation after the last
layer, a layer ronap does not know) raises ``ConfigError`` naming it.
"""

from __future__ import annotations

import io
import os
import pickle
import zipfile
from collections import OrderedDict
from typing import Any, Iterator

import numpy as np

from . import _ronap
from ._ronap import ConfigError

__all__ = ["export_policy", "import_torch", "mlp_outputs"]

# What the hidden activation modules are called in ronap's weights file.
_ACTIVATIONS = {"ReLU": "relu", "Tanh": "tanh", "RReLU": "rrelu", "LeakyReLU": "leaky_relu"}
# Modules that change nothing at inference, skipped.
_PASS = {"Flatten", "Identity", "Dropout"}
# Final modules that keep the largest output the largest, dropped.
_MONOTONE = {"Softmax", "LogSoftmax"}
_RRELU_DEFAULT = (1.0 / 8.0, 1.0 / 3.0)


def mlp_outputs(path: str | os.PathLike[str], observations: Any) -> np.ndarray:
    """The outputs (one row of 3 per observation) of the network in weights file ``path`` for each
    row of ``observations``, as ``ronap run --policy mlp:PATH`` computes them."""
    obs = np.ascontiguousarray(np.atleast_2d(np.asarray(observations, dtype=np.float32)))
    return _ronap.mlp_outputs(os.fspath(path), obs)


def _array(x: Any) -> np.ndarray:
    """A tensor (torch, or a numpy stand-in from a file) as a float32 numpy array."""
    if hasattr(x, "detach"):
        x = x.detach().cpu().numpy()
    return np.ascontiguousarray(np.asarray(x, dtype=np.float32))


def _kind(module: Any) -> str:
    return type(module).__name__


def _children(module: Any) -> list[Any]:
    mods = getattr(module, "_modules", None) or {}
    return [m for m in mods.values() if m is not None]


def _leaves(module: Any) -> Iterator[Any]:
    """The module's leaf modules, in the order they were defined."""
    children = _children(module)
    if not children:
        yield module
    for child in children:
        yield from _leaves(child)


def _activation_name(module: Any) -> str:
    kind = _kind(module)
    if kind == "LeakyReLU":
        return f"leaky_relu:{float(getattr(module, 'negative_slope', 0.01))!r}"
    if kind == "RReLU":
        lower, upper = float(getattr(module, "lower", _RRELU_DEFAULT[0])), float(getattr(module, "upper", _RRELU_DEFAULT[1]))
        if (lower, upper) != _RRELU_DEFAULT:
            return f"leaky_relu:{(lower + upper) / 2.0!r}"
    return _ACTIVATIONS[kind]


def _network(
    modules: list[Any], where: str, activation: str | None, ordered: bool = True
) -> tuple[list[tuple[np.ndarray, np.ndarray]], str]:
    """The layers and the hidden activation of a module list: in forward order (``ordered``, as an
    ``nn.Sequential`` runs them), Linear layers with one kind of activation between each two and
    none after the last; else (a module whose forward is code) Linear layers in the order they
    were defined and the one kind of activation module among them."""
    if not ordered:
        linears = [m for m in modules if _kind(m) == "Linear"]
        acts = [m for m in modules if _kind(m) in _ACTIVATIONS]
        others = [_kind(m) for m in modules if _kind(m) not in _ACTIVATIONS and _kind(m) not in _PASS and _kind(m) != "Linear"]
        if others:
            raise ConfigError(f"{where}: has a {others[0]}; ronap's network has Linear layers and one of {sorted(_ACTIVATIONS)}")
        kinds = sorted({_activation_name(m) for m in acts})
        if len(kinds) > 1:
            raise ConfigError(f"{where}: several activations ({', '.join(kinds)}); ronap's network has one")
        return _network(_interleaved(linears, acts[0] if acts else None), where, activation)
    layers: list[tuple[np.ndarray, np.ndarray]] = []
    found: set[str] = set()
    pending = False  # an activation followed the latest Linear
    for k, m in enumerate(modules):
        kind = _kind(m)
        if kind == "Linear":
            if layers and not pending and activation is None and found:
                raise ConfigError(f"{where}: two Linear layers with no activation between them (module {k})")
            params = getattr(m, "_parameters", {}) or {}
            weight = params.get("weight", getattr(m, "weight", None))
            bias = params.get("bias", getattr(m, "bias", None))
            if weight is None:
                raise ConfigError(f"{where}: Linear module {k} has no weight")
            w = _array(weight)
            b = np.zeros(w.shape[0], np.float32) if bias is None else _array(bias)
            layers.append((w, b))
            pending = False
        elif kind in _ACTIVATIONS:
            if not layers:
                raise ConfigError(f"{where}: {kind} before the first Linear layer: ronap's network starts with a layer")
            found.add(_activation_name(m))
            pending = True
        elif kind in _PASS:
            continue
        elif kind in _MONOTONE and k == len(modules) - 1:
            continue
        else:
            raise ConfigError(
                f"{where}: module {k} is {kind}; ronap's network has Linear layers and one of {sorted(_ACTIVATIONS)}"
            )
    if not layers:
        raise ConfigError(f"{where}: no Linear layer")
    if pending:
        raise ConfigError(f"{where}: ends with an activation after its last Linear layer; ronap's outputs have none")
    if len(found) > 1:
        raise ConfigError(f"{where}: several activations ({', '.join(sorted(found))}); ronap's network has one")
    if activation is None:
        if found:
            activation = found.pop()
        elif len(layers) == 1:
            activation = "relu"
        else:
            raise ConfigError(
                f"{where}: no activation module (its forward applies one in code): say which with activation='relu' (or 'tanh', ...)"
            )
    return layers, activation


def _interleaved(linears: list[Any], act: Any) -> list[Any]:
    """Linear layers with ``act`` between each two (none when ``act`` is None)."""
    out: list[Any] = []
    for k, m in enumerate(linears):
        if k and act is not None:
            out.append(act)
        out.append(m)
    return out


def _write(path: str | os.PathLike[str], layers: list[tuple[np.ndarray, np.ndarray]], activation: str, metadata: dict[str, str]) -> None:
    _ronap.write_mlp(
        os.fspath(path),
        [w for w, _ in layers],
        [b for _, b in layers],
        activation,
        {k: str(v) for k, v in metadata.items()},
    )


def _sb3_network(model: Any) -> tuple[list[Any], str, str]:
    """The modules (forward order), output kind and a description of an SB3 model's policy."""
    policy = getattr(model, "policy", None)
    space = getattr(model, "action_space", None)
    name = type(model).__name__
    if space is None or type(space).__name__ != "Discrete" or int(space.n) != 3:
        raise ConfigError(f"{name} with action space {space}: ronap's weights file holds Discrete(3) policies")
    obs_space = getattr(model, "observation_space", None)
    if obs_space is None or len(getattr(obs_space, "shape", ())) != 1:
        raise ConfigError(f"{name} with observation space {obs_space}: expected ronap's flat Box observation")
    if hasattr(policy, "q_net"):
        extractor = policy.q_net.features_extractor
        modules = list(policy.q_net.q_net)
        output = "q_values"
    elif hasattr(policy, "mlp_extractor") and hasattr(policy, "action_net"):
        extractor = getattr(policy, "pi_features_extractor", None) or policy.features_extractor
        modules = list(policy.mlp_extractor.policy_net) + [policy.action_net]
        output = "logits"
    else:
        raise ConfigError(f"{name}: not an SB3 PPO, A2C or DQN model with an MLP policy")
    if _kind(extractor) != "FlattenExtractor":
        raise ConfigError(f"{name}: features extractor {_kind(extractor)}; ronap runs MlpPolicy's FlattenExtractor")
    return modules, output, f"Stable-Baselines3 {name} ({type(policy).__name__})"


def export_policy(
    obj: Any,
    path: str | os.PathLike[str],
    *,
    activation: str | None = None,
    trained: str | None = None,
) -> None:
    """Writes ``obj``'s network to ``path`` in ronap's weights file: a Stable-Baselines3 PPO, A2C
    or DQN model (MlpPolicy, ``Discrete(3)`` actions; the greedy action of the exported file is
    the model's ``predict(obs, deterministic=True)``), or a torch module of ``Linear`` layers and
    activations in forward order. ``activation`` names the hidden activation when the module
    applies it in code (no activation module); ``trained`` is kept as the file's ``trained``
    metadata. Raises ``ConfigError`` for a network ronap cannot run."""
    if hasattr(obj, "policy") and hasattr(obj, "action_space"):
        modules, output, description = _sb3_network(obj)
        ordered = True
    else:
        modules, output, description = list(_leaves(obj)), "logits", f"torch {type(obj).__name__}"
        ordered = _kind(obj) == "Sequential"
    layers, act = _network(modules, description, activation, ordered)
    _write(path, layers, act, {"output": output, "trained": trained or f"exported from {description}"})


# --- torch files, read without torch -------------------------------------------------------

_DTYPES = {
    "FloatStorage": np.float32,
    "DoubleStorage": np.float64,
    "HalfStorage": np.float16,
    "BFloat16Storage": "bfloat16",
    "LongStorage": np.int64,
    "IntStorage": np.int32,
    "ShortStorage": np.int16,
    "CharStorage": np.int8,
    "ByteStorage": np.uint8,
    "BoolStorage": np.bool_,
}
_LEGACY_MAGIC = 0x1950A86A20F9469CFC6C


class _StorageType:
    def __init__(self, name: str) -> None:
        if name not in _DTYPES:
            raise ConfigError(f"torch storage {name}: not a kind ronap reads")
        self.name = name
        self.itemsize = 2 if _DTYPES[name] == "bfloat16" else np.dtype(_DTYPES[name]).itemsize


class _Storage:
    """A tensor storage whose bytes may come after the pickle (legacy format)."""

    def __init__(self, kind: _StorageType, numel: int) -> None:
        self.kind, self.numel, self.data = kind, numel, None

    def array(self) -> np.ndarray:
        if self.data is None:
            raise ConfigError("a tensor's storage is missing from the file")
        if _DTYPES[self.kind.name] == "bfloat16":
            return (np.frombuffer(self.data, np.uint16).astype(np.uint32) << 16).view(np.float32)
        return np.frombuffer(self.data, _DTYPES[self.kind.name])


class _Tensor:
    def __init__(self, storage: _Storage, offset: int, size: tuple[int, ...], stride: tuple[int, ...]) -> None:
        self.storage, self.offset, self.size, self.stride = storage, offset, tuple(size), tuple(stride)

    def array(self) -> np.ndarray:
        flat = self.storage.array()
        if not self.size:
            return flat[self.offset : self.offset + 1].reshape(()).copy()
        end = self.offset + sum((n - 1) * s for n, s in zip(self.size, self.stride)) + 1
        if self.offset < 0 or end > flat.size or min(self.stride) < 0:
            raise ConfigError(f"a tensor of shape {self.size} reaches past its storage")
        view = np.lib.stride_tricks.as_strided(
            flat[self.offset :], shape=self.size, strides=[s * flat.itemsize for s in self.stride], writeable=False
        )
        return view.copy()


def _rebuild_tensor(storage: _Storage, offset: int, size: Any, stride: Any, *rest: Any) -> _Tensor:
    return _Tensor(storage, offset, tuple(size), tuple(stride))


def _rebuild_parameter(data: Any, *rest: Any) -> Any:
    return data


class _Stub:
    """Stands for a class of the program that saved the file: keeps its pickled state."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        pass

    def __setstate__(self, state: Any) -> None:
        if isinstance(state, tuple) and len(state) == 2:
            state = {**(state[0] or {}), **(state[1] or {})}
        if isinstance(state, dict):
            self.__dict__.update(state)


_STUBS: dict[tuple[str, str], type] = {}


def _stub(module: str, name: str) -> type:
    key = (module, name)
    if key not in _STUBS:
        _STUBS[key] = type(name, (_Stub,), {"_origin": f"{module}.{name}"})
    return _STUBS[key]


class _Unpickler(pickle.Unpickler):
    """Builds numpy stand-ins for tensors and plain stand-ins for every other class; never imports
    a module the file names."""

    def __init__(self, file: Any, load_storage: Any) -> None:
        super().__init__(file)
        self._load_storage = load_storage

    def find_class(self, module: str, name: str) -> Any:
        if module == "collections" and name == "OrderedDict":
            return OrderedDict
        if module == "torch._utils" and name in ("_rebuild_tensor_v2", "_rebuild_tensor"):
            return _rebuild_tensor
        if module == "torch._utils" and name in ("_rebuild_parameter", "_rebuild_parameter_with_state"):
            return _rebuild_parameter
        if module == "torch" and name in _DTYPES:
            return _StorageType(name)
        if module == "torch" and name == "Size":
            return tuple
        if module in ("copyreg", "copy_reg") and name == "_reconstructor":
            return _reconstructor
        if module in ("builtins", "__builtin__") and name in ("set", "frozenset", "object", "tuple", "list", "dict"):
            return {"set": set, "frozenset": frozenset, "object": object, "tuple": tuple, "list": list, "dict": dict}[name]
        return _stub(module, name)

    def persistent_load(self, pid: Any) -> Any:
        if isinstance(pid, tuple) and len(pid) >= 2 and pid[0] == "module":
            return pid[1]  # the legacy format's record of a module's class and source: the class
        if not isinstance(pid, tuple) or not pid or pid[0] != "storage":
            raise ConfigError(f"unknown persistent id {pid!r:.80}")
        return self._load_storage(pid)


def _reconstructor(cls: Any, base: Any, state: Any) -> Any:
    return cls.__new__(cls) if isinstance(cls, type) else _Stub()


def _resolve(obj: Any, seen: set[int] | None = None) -> Any:
    """`obj` with every tensor stand-in turned into a numpy array."""
    seen = set() if seen is None else seen
    if isinstance(obj, _Tensor):
        return obj.array()
    if id(obj) in seen:
        return obj
    seen.add(id(obj))
    if isinstance(obj, dict):
        for k in list(obj):
            obj[k] = _resolve(obj[k], seen)
    elif isinstance(obj, list):
        obj[:] = [_resolve(x, seen) for x in obj]
    elif isinstance(obj, tuple):
        return tuple(_resolve(x, seen) for x in obj)
    elif isinstance(obj, _Stub):
        _resolve(obj.__dict__, seen)
    return obj


def _kind_of(pid: tuple[Any, ...]) -> _StorageType:
    kind = pid[1]
    if isinstance(kind, str):
        kind = _StorageType(kind)
    if not isinstance(kind, _StorageType):
        raise ConfigError(f"unknown storage type {kind!r:.80}")
    return kind


def _load_zip(data: bytes, file: str) -> Any:
    archive = zipfile.ZipFile(io.BytesIO(data))
    pkl = [n for n in archive.namelist() if n.endswith("data.pkl")]
    if not pkl:
        raise ConfigError(f"{file}: a zip file with no data.pkl: not a torch.save file")
    prefix = pkl[0][: -len("data.pkl")]

    def load_storage(pid: tuple[Any, ...]) -> _Storage:
        _, _, key, _, numel = pid[:5]
        storage = _Storage(_kind_of(pid), int(numel))
        try:
            storage.data = archive.read(f"{prefix}data/{key}")
        except KeyError:
            raise ConfigError(f"{file}: storage {key} is missing from the archive") from None
        return storage

    return _Unpickler(io.BytesIO(archive.read(pkl[0])), load_storage).load()


def _load_legacy(data: bytes, file: str) -> Any:
    f = io.BytesIO(data)
    no_storage = lambda pid: (_ for _ in ()).throw(ConfigError(f"{file}: unexpected storage"))  # noqa: E731
    magic = _Unpickler(f, no_storage).load()
    if magic != _LEGACY_MAGIC:
        raise ConfigError(f"{file}: not a torch.save file (no zip archive, no legacy magic number)")
    _Unpickler(f, no_storage).load()  # protocol version
    info = _Unpickler(f, no_storage).load()
    if isinstance(info, dict) and not info.get("little_endian", True):
        raise ConfigError(f"{file}: saved on a big-endian machine")
    storages: dict[str, _Storage] = {}

    def load_storage(pid: tuple[Any, ...]) -> _Storage:
        _, _, key, _, numel = pid[:5]
        if key not in storages:
            storages[key] = _Storage(_kind_of(pid), int(numel))
        return storages[key]

    result = _Unpickler(f, load_storage).load()
    keys = _Unpickler(f, no_storage).load()
    for key in keys:
        if key not in storages:
            raise ConfigError(f"{file}: storage {key} listed but never used")
        s = storages[key]
        numel = int.from_bytes(f.read(8), "little")
        s.data = f.read(numel * s.kind.itemsize)
        if len(s.data) != numel * s.kind.itemsize:
            raise ConfigError(f"{file}: storage {key} is cut short")
    return result


def _read_torch(file: str) -> Any:
    with open(file, "rb") as f:
        data = f.read()
    try:
        if data[:4] == b"PK\x03\x04":
            obj = _load_zip(data, file)
        else:
            obj = _load_legacy(data, file)
    except ConfigError as e:
        message = str(e)
        raise ConfigError(message if message.startswith(file) else f"{file}: {message}") from None
    except Exception as e:  # a damaged or foreign file: name it, whatever broke
        raise ConfigError(f"{file}: not a readable torch.save file ({type(e).__name__}: {e})") from None
    return _resolve(obj)


def _from_state_dict(state: dict[str, Any], where: str, activation: str | None) -> tuple[list[tuple[np.ndarray, np.ndarray]], str]:
    """Linear layers from a state_dict: each `name.weight` (2-D) with its `name.bias`, in order."""
    layers = []
    for key, value in state.items():
        if key.endswith(".weight") and isinstance(value, np.ndarray) and value.ndim == 2:
            bias = state.get(key[: -len("weight")] + "bias")
            b = np.zeros(value.shape[0], np.float32) if bias is None else np.asarray(bias, np.float32)
            layers.append((np.ascontiguousarray(value, np.float32), b))
    if not layers:
        raise ConfigError(f"{where}: a state_dict with no Linear weights")
    if activation is None:
        if len(layers) > 1:
            raise ConfigError(f"{where}: a state_dict does not say the activation: give activation='relu' (or 'tanh', 'rrelu', ...)")
        activation = "relu"
    return layers, activation


def import_torch(
    file: str | os.PathLike[str],
    path: str | os.PathLike[str],
    *,
    activation: str | None = None,
) -> None:
    """Converts ``file``, written by ``torch.save`` (a whole model, a ``state_dict``, or a
    checkpoint dict with one under ``state_dict``/``model_state_dict``/``model``), to ronap's
    weights file ``path``. Reads the zip format and the legacy pre-1.6 pickle format without torch
    and without the saving program's classes (never running code from the file). ``activation``
    names the hidden activation where the file does not show it (a ``state_dict``, or a model
    whose forward applies it in code)."""
    file = os.fspath(file)
    obj = _read_torch(file)
    if isinstance(obj, dict):
        for key in ("state_dict", "model_state_dict", "model", "net", "policy"):
            if key in obj and (isinstance(obj[key], dict) or isinstance(obj[key], _Stub)):
                obj = obj[key]
                break
    if isinstance(obj, dict):
        layers, act = _from_state_dict(obj, file, activation)
        what = "a state_dict"
    elif isinstance(obj, _Stub):
        where = f"{file} ({type(obj)._origin})"  # type: ignore[attr-defined]
        layers, act = _network(list(_leaves(obj)), where, activation, ordered=_kind(obj) == "Sequential")
        what = f"a whole {type(obj)._origin} model"  # type: ignore[attr-defined]
    else:
        raise ConfigError(f"{file}: holds a {type(obj).__name__}, not a model or a state_dict")
    _write(path, layers, act, {"trained": f"imported from {os.path.basename(file)} ({what})"})
