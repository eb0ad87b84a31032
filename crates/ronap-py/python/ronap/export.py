"""Networks trained elsewhere, in ronap's weights file, to run at Rust speed as ``mlp:FILE``.

- ``export_policy(obj, path)``: a Stable-Baselines3 PPO, A2C or DQN model with an MLP policy and
  ``Discrete(3)`` actions, or a torch module made of ``Linear`` layers and activations: an
  ``nn.Sequential`` (in its order), or a module whose forward is code, taken as its ``Linear``
  layers in the order they were defined with its one kind of activation module between them.
- ``import_torch(file, path)``: a file ``torch.save`` wrote (a whole model, a ``state_dict`` or a
  checkpoint dict holding one), in the zip format of torch >= 1.6 or the legacy pickle format
  older projects used, the original RoNAP among them, or a TorchScript file ``torch.jit.save``
  wrote. It needs neither torch nor the classes of the program that saved the model: the file is
  read by a restricted unpickler that builds stand-ins for any class it names and never imports
  or runs code from it.
- ``mlp_outputs(path, observations)``: the network's outputs for a batch of observations, as the
  ``mlp:`` policy computes them (to check an export).

The weights file is described in ``policies/README.md``: ``Linear`` layers, one hidden activation
(``relu``, ``tanh``, ``rrelu``, ``leaky_relu:SLOPE``) after every layer but the last, and 3
outputs (LEFT, AHEAD, RIGHT) of which the policy takes the largest. Modules that change nothing
at inference (``Flatten``, ``Identity``, ``Dropout`` of a model saved in eval mode) are skipped; a
final ``Softmax`` or ``LogSoftmax`` is dropped, since it keeps the largest output the largest and
ronap's decision rules (``argmax``, ``sample:T``) act on the logits before it; the file's
``dropped`` metadata says so. What does not fit raises ``ModelError`` naming the layer (its key,
as ``state_dict`` names it, and its class): normalisation (``LayerNorm``, ``BatchNorm``),
convolution, ``Dropout`` in a model saved in training mode, two kinds of activation, an
activation after the last layer, a parameter used by a module's own code, another number of
outputs, continuous actions.

A ``state_dict`` holds no activations: ``activation=`` names the one between its layers, and
the caller vouches for it (one kind after every ``Linear`` layer but the last). What its keys do
show is checked: a key that is no ``Linear`` layer's ``weight`` or ``bias`` (a BatchNorm's
``running_mean``, a 1-D ``weight`` of a LayerNorm, the 3-D or 4-D ``weight`` of a convolution)
is refused by name, as are layers whose sizes do not chain.
"""

from __future__ import annotations

import errno
import io
import os
import pickle
import re
import zipfile
from collections import OrderedDict
from typing import Any, Iterator

import numpy as np

from . import _ronap
from ._ronap import ConfigError
from .config import MissingFileError

__all__ = ["MissingFileError", "ModelError", "export_policy", "import_torch", "mlp_outputs"]


class ModelError(ConfigError):
    """A model or file ronap cannot turn into its weights file: a layer it cannot represent (the
    message names it), or a file that is no readable ``torch.save`` file. A ``ConfigError`` and a
    ``ValueError``."""


# What the hidden activation modules are called in ronap's weights file.
_ACTIVATIONS = {"ReLU": "relu", "Tanh": "tanh", "RReLU": "rrelu", "LeakyReLU": "leaky_relu"}
# Modules that change nothing at inference, skipped.
_PASS = {"Flatten", "Identity"}
# Modules that change nothing in eval mode, skipped there (and refused in training mode).
_DROPOUT = {"Dropout", "Dropout1d", "Dropout2d", "AlphaDropout"}
# Final modules that keep the largest output the largest, dropped.
_MONOTONE = {"Softmax", "LogSoftmax"}
_RRELU_DEFAULT = (1.0 / 8.0, 1.0 / 3.0)
# How the refusal names what ronap's network lacks, by the start of a module's class name.
_WHAT = {
    "BatchNorm": "normalisation",
    "LayerNorm": "normalisation",
    "GroupNorm": "normalisation",
    "InstanceNorm": "normalisation",
    "RMSNorm": "normalisation",
    "Conv": "convolution",
    "MaxPool": "pooling",
    "AvgPool": "pooling",
}
_NETWORK = "ronap's network holds Linear layers with one kind of activation (ReLU, Tanh, LeakyReLU, RReLU) between them"


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


def _is_tensor(x: Any) -> bool:
    return isinstance(x, np.ndarray) or hasattr(x, "detach")


def _children(module: Any) -> list[tuple[str, Any]]:
    """A module's submodules with their names: torch's ``_modules`` (a live module or a pickled
    one), or, in a TorchScript file, the attributes that are modules."""
    mods = getattr(module, "_modules", None)
    if mods is None and _scripted(module):
        mods = {k: v for k, v in vars(module).items() if _scripted(v)}
    return [(str(k), m) for k, m in (mods or {}).items() if m is not None]


def _scripted(obj: Any) -> bool:
    """Whether ``obj`` stands for a module of a TorchScript file (its classes live in ``__torch__``)."""
    return isinstance(obj, _Stub) and type(obj)._origin.startswith("__torch__.")  # type: ignore[attr-defined]


def _own_tensors(module: Any) -> list[str]:
    """The names of the parameters and buffers a module holds itself (not its submodules')."""
    names = []
    for table in ("_parameters", "_buffers"):
        names += [k for k, v in (getattr(module, table, None) or {}).items() if v is not None]
    if isinstance(module, _Stub) and not hasattr(module, "_parameters"):  # TorchScript: attributes
        names += [k for k, v in vars(module).items() if _is_tensor(v)]
    return names


def _leaves(module: Any, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """The module's leaf modules with their keys (``fc1``, ``0``, ``net.2``: as its ``state_dict``
    names them), in the order they were defined. A module with submodules that holds a parameter
    or buffer of its own uses it in its code, which ronap cannot run: refused."""
    children = _children(module)
    if not children:
        yield prefix or "(the model itself)", module
        return
    own = _own_tensors(module)
    if own:
        key = f"{prefix}.{own[0]}" if prefix else own[0]
        raise ModelError(f"{key}: a tensor {_kind(module)} uses in its own code; {_NETWORK}")
    for name, child in children:
        yield from _leaves(child, f"{prefix}.{name}" if prefix else name)


def _activation_name(module: Any, key: str) -> str:
    kind = _kind(module)
    if kind == "LeakyReLU":
        slope = getattr(module, "negative_slope", None)
        if slope is None:
            raise ModelError(f"layer {key} ({kind}): its slope is compiled into TorchScript code; save the model with torch.save instead")
        return f"leaky_relu:{float(slope)!r}"
    if kind == "RReLU":
        lower, upper = getattr(module, "lower", None), getattr(module, "upper", None)
        if lower is None or upper is None:
            raise ModelError(f"layer {key} ({kind}): its bounds are compiled into TorchScript code; save the model with torch.save instead")
        if (float(lower), float(upper)) != _RRELU_DEFAULT:
            return f"leaky_relu:{(float(lower) + float(upper)) / 2.0!r}"
    return _ACTIVATIONS[kind]


def _refuse_layer(key: str, kind: str) -> ModelError:
    what = next((w for start, w in _WHAT.items() if kind.startswith(start)), None)
    return ModelError(f"layer {key} is {kind}{f' ({what})' if what else ''}; {_NETWORK}, and nothing else")


def _check_dropout(key: str, module: Any) -> None:
    """A dropout of a model saved in training mode: its outputs there are random, ronap's are
    eval mode's; refused rather than silently changed."""
    p = getattr(module, "p", None)
    if getattr(module, "training", False) and (p is None or float(p) > 0):
        raise ModelError(
            f"layer {key} is {_kind(module)} in training mode (the model was saved without .eval()): "
            "ronap runs it as eval mode does; call model.eval() before saving it"
        )


class _Net:
    """A network as ronap's weights file holds it: its layers, its hidden activation, and what
    was dropped on the way (for the file's metadata)."""

    def __init__(self, layers: list[tuple[np.ndarray, np.ndarray]], activation: str, dropped: list[str]) -> None:
        self.layers, self.activation, self.dropped = layers, activation, dropped

    def metadata(self) -> dict[str, str]:
        if not self.dropped:
            return {}
        return {
            "dropped": "; ".join(self.dropped)
            + ": it keeps the largest output the largest, and ronap's decision rules (argmax, sample:T) act on the logits before it"
        }


def _linear(key: str, module: Any) -> tuple[np.ndarray, np.ndarray]:
    params = getattr(module, "_parameters", None) or {}
    weight = params.get("weight", getattr(module, "weight", None))
    bias = params.get("bias", getattr(module, "bias", None))
    if weight is None:
        raise ModelError(f"layer {key} (Linear) has no weight")
    w = _array(weight)
    b = np.zeros(w.shape[0], np.float32) if bias is None else _array(bias)
    return w, b


def _network(modules: list[tuple[str, Any]], where: str, activation: str | None, ordered: bool = True) -> _Net:
    """The layers and the hidden activation of leaf modules (each with its key): in forward order
    (``ordered``, as an ``nn.Sequential`` runs them), Linear layers with one kind of activation
    between each two and none after the last; else (a module whose forward is code) Linear layers
    in the order they were defined and the one kind of activation module among them, a Softmax
    taken as applied to the outputs."""
    try:
        return _network_of(modules, activation, ordered)
    except ModelError as e:
        raise ModelError(f"{where}: {e}") from None


def _network_of(modules: list[tuple[str, Any]], activation: str | None, ordered: bool) -> _Net:
    dropped: list[str] = []
    kept: list[tuple[str, Any]] = []
    for k, (key, m) in enumerate(modules):
        kind = _kind(m)
        if kind in _PASS:
            continue
        if kind in _DROPOUT:
            _check_dropout(key, m)
            continue
        if kind in _MONOTONE:
            later = [(q, n) for q, n in modules[k + 1 :] if _kind(n) not in _PASS | _DROPOUT]
            if ordered and later:
                raise ModelError(f"layer {key} is {kind} with layer {later[0][0]} ({_kind(later[0][1])}) after it; ronap drops a {kind} only at the end")
            dropped.append(f"{kind} (layer {key})")
            continue
        if kind != "Linear" and kind not in _ACTIVATIONS:
            raise _refuse_layer(key, kind)
        kept.append((key, m))
    first_act: tuple[str, str, str] | None = None  # key, class, name in the weights file
    for key, m in kept:
        if _kind(m) in _ACTIVATIONS:
            name = _activation_name(m, key)
            if first_act is None:
                first_act = (key, _kind(m), name)
            elif name != first_act[2]:
                raise ModelError(
                    f"layer {key} is {_kind(m)} ({name}) but layer {first_act[0]} is {first_act[1]} ({first_act[2]}): "
                    "ronap's network has one kind of hidden activation"
                )
    if first_act is not None and activation is not None and activation != first_act[2]:
        raise ModelError(f"activation={activation!r} but layer {first_act[0]} is {first_act[1]} ({first_act[2]})")
    if not ordered:
        linears = [(k, m) for k, m in kept if _kind(m) == "Linear"]
        act = next(((k, m) for k, m in kept if _kind(m) in _ACTIVATIONS), None)
        kept = _interleaved(linears, act)
    layers: list[tuple[np.ndarray, np.ndarray]] = []
    pending: str | None = None  # the activation that followed the latest Linear
    for key, m in kept:
        if _kind(m) == "Linear":
            if layers and pending is None and activation is None and first_act is not None:
                raise ModelError(f"two Linear layers with no activation between them (layer {key})")
            layers.append(_linear(key, m))
            pending = None
        elif not layers:
            raise ModelError(f"layer {key} ({_kind(m)}) comes before the first Linear layer: ronap's network starts with a layer")
        else:
            pending = key
    if not layers:
        raise ModelError("no Linear layer")
    if pending is not None:
        raise ModelError(f"ends with an activation (layer {pending}) after its last Linear layer; ronap's outputs have none")
    if activation is None:
        if first_act is not None:
            activation = first_act[2]
        elif len(layers) == 1:
            activation = "relu"
        else:
            raise ModelError("no activation module (its forward applies one in code): say which with activation='relu' (or 'tanh', ...)")
    return _Net(layers, activation, dropped)


def _interleaved(linears: list[tuple[str, Any]], act: tuple[str, Any] | None) -> list[tuple[str, Any]]:
    """Linear layers with ``act`` between each two (none when ``act`` is None)."""
    out: list[tuple[str, Any]] = []
    for k, m in enumerate(linears):
        if k and act is not None:
            out.append(act)
        out.append(m)
    return out


def _write(path: str | os.PathLike[str], net: _Net, metadata: dict[str, str]) -> None:
    try:
        _ronap.write_mlp(
            os.fspath(path),
            [w for w, _ in net.layers],
            [b for _, b in net.layers],
            net.activation,
            {k: str(v) for k, v in {**metadata, **net.metadata()}.items()},
        )
    except ConfigError as e:  # another number of outputs, an unknown activation name
        raise ModelError(str(e)) from None


def _sb3_network(model: Any) -> tuple[list[tuple[str, Any]], str, str]:
    """The modules (forward order, with their keys), output kind and a description of an SB3
    model's policy."""
    policy = getattr(model, "policy", None)
    space = getattr(model, "action_space", None)
    name = type(model).__name__
    if space is None or type(space).__name__ != "Discrete" or int(space.n) != 3:
        raise ModelError(f"{name} with action space {space}: ronap's weights file holds Discrete(3) policies")
    obs_space = getattr(model, "observation_space", None)
    if obs_space is None or len(getattr(obs_space, "shape", ())) != 1:
        raise ModelError(f"{name} with observation space {obs_space}: expected ronap's flat Box observation")
    if hasattr(policy, "q_net"):
        extractor = policy.q_net.features_extractor
        modules = list(_leaves(policy.q_net.q_net, "q_net.q_net"))
        output = "q_values"
    elif hasattr(policy, "mlp_extractor") and hasattr(policy, "action_net"):
        extractor = getattr(policy, "pi_features_extractor", None) or policy.features_extractor
        modules = list(_leaves(policy.mlp_extractor.policy_net, "mlp_extractor.policy_net")) + [("action_net", policy.action_net)]
        output = "logits"
    else:
        raise ModelError(f"{name}: not an SB3 PPO, A2C or DQN model with an MLP policy")
    if _kind(extractor) != "FlattenExtractor":
        raise ModelError(f"{name}: features extractor {_kind(extractor)}; ronap runs MlpPolicy's FlattenExtractor")
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
    activations in forward order (a final ``Softmax``/``LogSoftmax`` dropped: the greedy action
    is the same, and the file's ``dropped`` metadata says so). ``activation`` names the hidden activation when the module applies it in
    code (no activation module); ``trained`` is kept as the file's ``trained`` metadata. Raises
    ``ModelError`` (a ``ConfigError`` and a ``ValueError``) naming the layer ronap cannot run."""
    if hasattr(obj, "policy") and hasattr(obj, "action_space"):
        modules, output, description = _sb3_network(obj)
        ordered = True
    else:
        description = f"torch {type(obj).__name__}"
        try:
            modules = list(_leaves(obj))
        except ModelError as e:
            raise ModelError(f"{description}: {e}") from None
        output, ordered = "logits", _kind(obj) == "Sequential"
    net = _network(modules, description, activation, ordered)
    _write(path, net, {"output": output, "trained": trained or f"exported from {description}"})


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
            raise ModelError(f"torch storage {name}: not a kind ronap reads")
        self.name = name
        self.itemsize = 2 if _DTYPES[name] == "bfloat16" else np.dtype(_DTYPES[name]).itemsize


class _Storage:
    """A tensor storage whose bytes may come after the pickle (legacy format)."""

    def __init__(self, kind: _StorageType, numel: int) -> None:
        self.kind, self.numel, self.data = kind, numel, None

    def array(self) -> np.ndarray:
        if self.data is None:
            raise ModelError("a tensor's storage is missing from the file")
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
            raise ModelError(f"a tensor of shape {self.size} reaches past its storage")
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
            raise ModelError(f"unknown persistent id {pid!r:.80}")
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
        raise ModelError(f"unknown storage type {kind!r:.80}")
    return kind


def _load_zip(data: bytes, file: str) -> Any:
    archive = zipfile.ZipFile(io.BytesIO(data))
    pkl = [n for n in archive.namelist() if n.endswith("data.pkl")]
    if not pkl:
        raise ModelError(f"{file}: a zip file with no data.pkl: not a torch.save file")
    prefix = pkl[0][: -len("data.pkl")]

    def load_storage(pid: tuple[Any, ...]) -> _Storage:
        _, _, key, _, numel = pid[:5]
        storage = _Storage(_kind_of(pid), int(numel))
        try:
            storage.data = archive.read(f"{prefix}data/{key}")
        except KeyError:
            raise ModelError(f"{file}: storage {key} is missing from the archive") from None
        return storage

    return _Unpickler(io.BytesIO(archive.read(pkl[0])), load_storage).load()


def _load_legacy(data: bytes, file: str) -> Any:
    f = io.BytesIO(data)
    no_storage = lambda pid: (_ for _ in ()).throw(ModelError(f"{file}: unexpected storage"))  # noqa: E731
    magic = _Unpickler(f, no_storage).load()
    if magic != _LEGACY_MAGIC:
        raise ModelError(f"{file}: not a torch.save file (no zip archive, no legacy magic number)")
    _Unpickler(f, no_storage).load()  # protocol version
    info = _Unpickler(f, no_storage).load()
    if isinstance(info, dict) and not info.get("little_endian", True):
        raise ModelError(f"{file}: saved on a big-endian machine")
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
            raise ModelError(f"{file}: storage {key} listed but never used")
        s = storages[key]
        numel = int.from_bytes(f.read(8), "little")
        s.data = f.read(numel * s.kind.itemsize)
        if len(s.data) != numel * s.kind.itemsize:
            raise ModelError(f"{file}: storage {key} is cut short")
    return result


def _read_torch(file: str) -> Any:
    try:
        with open(file, "rb") as f:
            data = f.read()
    except FileNotFoundError:
        raise MissingFileError(errno.ENOENT, "import_torch: no such file", file) from None
    except OSError as e:
        raise ModelError(f"{file}: cannot read it ({e.strerror})") from None
    try:
        if data[:4] == b"PK\x03\x04":
            obj = _load_zip(data, file)
        else:
            obj = _load_legacy(data, file)
    except ConfigError as e:
        message = str(e)
        raise ModelError(message if message.startswith(file) else f"{file}: {message}") from None
    except Exception as e:  # a damaged or foreign file: name it, whatever broke
        raise ModelError(f"{file}: not a readable torch.save file ({type(e).__name__}: {e})") from None
    return _resolve(obj)


# A state_dict's keys of a BatchNorm layer, which a Linear layer never has.
_RUNNING = ("running_mean", "running_var", "num_batches_tracked")


def _state_dict_layer(prefix: str, params: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """One layer of a state_dict (the tensors under ``prefix``) as a Linear layer's weight and
    bias, or ``ModelError`` naming the key that shows it is something else."""
    at = (lambda name: f"{prefix}.{name}") if prefix else (lambda name: name)
    for name in _RUNNING:
        if name in params:
            raise ModelError(f"layer {prefix or '(top)'} is a BatchNorm ({at(name)}); {_NETWORK}, and nothing else")
    for name, value in params.items():
        if not _is_tensor(value):
            raise ModelError(
                f"{at(name)} = {value!r:.40} is not a tensor: not a state_dict (a checkpoint's is read "
                "from its state_dict, model_state_dict, model, net or policy entry)"
            )
        if name not in ("weight", "bias"):
            raise ModelError(f"{at(name)}: not a Linear layer's weight or bias; {_NETWORK}, and nothing else")
    if "weight" not in params:
        raise ModelError(f"{at('bias')} without a weight: not a Linear layer")
    weight = np.asarray(params["weight"])
    if weight.ndim == 1:
        raise ModelError(
            f"layer {prefix or '(top)'} is a normalisation layer such as LayerNorm ({at('weight')} is 1-D); {_NETWORK}, and nothing else"
        )
    if weight.ndim in (3, 4, 5):
        raise ModelError(f"layer {prefix or '(top)'} is a Conv{weight.ndim - 2}d ({at('weight')} is {weight.ndim}-D); {_NETWORK}, and nothing else")
    if weight.ndim != 2:
        raise ModelError(f"{at('weight')} has shape {weight.shape}: not a Linear layer's")
    w = np.ascontiguousarray(weight, np.float32)
    bias = params.get("bias")
    if bias is not None and np.shape(bias) != (w.shape[0],):
        raise ModelError(f"{at('bias')} has shape {np.shape(bias)}, {at('weight')} {w.shape}: not a Linear layer's")
    b = np.zeros(w.shape[0], np.float32) if bias is None else np.ascontiguousarray(bias, np.float32)
    return w, b


def _from_state_dict(state: dict[str, Any], activation: str | None) -> _Net:
    """Linear layers from a state_dict, in its order: each layer's ``weight`` (2-D) with its
    ``bias``. The activation is the caller's word (``activation``); every key is checked to be a
    Linear layer's, and the layers to chain."""
    groups: dict[str, dict[str, Any]] = OrderedDict()
    for key, value in state.items():
        prefix, _, name = str(key).rpartition(".")
        groups.setdefault(prefix, {})[name] = value
    layers: list[tuple[np.ndarray, np.ndarray]] = []
    keys: list[str] = []
    for prefix, params in groups.items():
        layers.append(_state_dict_layer(prefix, params))
        keys.append(f"{prefix}.weight" if prefix else "weight")
        if len(layers) > 1 and layers[-1][0].shape[1] != layers[-2][0].shape[0]:
            raise ModelError(
                f"{keys[-1]} takes {layers[-1][0].shape[1]} inputs but {keys[-2]} gives {layers[-2][0].shape[0]} outputs: "
                "not one chain of Linear layers"
            )
    if not layers:
        raise ModelError("an empty state_dict")
    if activation is None:
        if len(layers) > 1:
            raise ModelError(
                "a state_dict does not say the activation: give activation='relu' (or 'tanh', 'rrelu', ...), "
                "the one after every Linear layer but the last"
            )
        activation = "relu"
    return _Net(layers, activation, [])


def import_torch(
    file: str | os.PathLike[str],
    path: str | os.PathLike[str],
    *,
    activation: str | None = None,
) -> None:
    """Converts ``file`` to ronap's weights file ``path``: what ``torch.save`` wrote (a whole
    model, a ``state_dict``, or a checkpoint dict with one under ``state_dict``,
    ``model_state_dict``, ``model``, ``net`` or ``policy``) in the zip format or the legacy pre-1.6
    pickle format, or a TorchScript file. Reads them without torch and without the saving
    program's classes (never running code from the file).

    ``activation`` names the hidden activation where the file does not show it: a ``state_dict``
    (which holds no activations: the caller vouches for the one given) or a model whose forward
    applies it in code. A final ``Softmax``/``LogSoftmax`` is dropped (the ``dropped`` metadata
    says so). Raises ``MissingFileError`` (a ``ConfigError`` and a ``FileNotFoundError``) when
    ``file`` does not exist, and ``ModelError`` (a ``ConfigError`` and a ``ValueError``) naming
    the layer or key ronap cannot represent, or what is wrong with the file."""
    file = os.fspath(file)
    obj = _read_torch(file)
    if isinstance(obj, dict):
        for key in ("state_dict", "model_state_dict", "model", "net", "policy"):
            if key in obj and (isinstance(obj[key], dict) or isinstance(obj[key], _Stub)):
                obj = obj[key]
                break
    metadata: dict[str, str] = {}
    if isinstance(obj, dict):
        try:
            net = _from_state_dict(obj, activation)
        except ModelError as e:
            raise ModelError(f"{file} (a state_dict): {e}") from None
        what = "a state_dict"
        metadata["activation_from"] = "the caller (activation=...): a state_dict holds no activations"
    elif isinstance(obj, _Stub):
        origin = type(obj)._origin  # type: ignore[attr-defined]
        script = origin.startswith("__torch__.")
        what = f"a {'TorchScript' if script else 'whole'} {re.sub(r'___torch_mangle_[0-9]+[.]', '', origin.removeprefix('__torch__.'))} model"
        where = f"{file} ({what})"
        try:
            modules = list(_leaves(obj))
        except ModelError as e:
            raise ModelError(f"{where}: {e}") from None
        net = _network(modules, where, activation, ordered=_kind(obj) == "Sequential")
    else:
        raise ModelError(f"{file}: holds a {type(obj).__name__}, not a model or a state_dict")
    metadata["trained"] = f"imported from {os.path.basename(file)} ({what})"
    _write(path, net, metadata)
