"""Safe model files: scikit-learn parts through skops, network weights as safetensors.

A model file is one zip archive with exactly three members:

* ``manifest.json``: the format, the skgesture version that wrote it, the input
  the model expects (frame shape, skeleton layout, descriptor joints, frame
  rate), how to rebuild each network, checksums of the other members, and user
  metadata;
* ``estimator.skops``: the estimator written by ``skops.io.dumps``, in which
  every skorch network is replaced by a placeholder and every class of the
  public API is named by its public name (``skgesture.PoseDescriptor``), so
  that moving a private module never breaks a file;
* ``weights.safetensors``: the tensors of every network (module and criterion
  state dicts, tensors among the net's parameters), always stored on the CPU.

Loading never unpickles anything: skops rebuilds the estimator from its schema
(refusing types nobody trusted; skgesture's trusted types are derived from the
public API table, ``skgesture._LAZY``), safetensors reads raw tensors, and a
network is rebuilt from its module class (which must belong to skgesture) and
its JSON keyword arguments, then given its weights. See ``docs/persistence.md``.

Longer than 1,000 lines because it is the one writer and reader of the file
format, and a security boundary: what a file may name, how it is written and
how each part is checked on reading are kept side by side, so that a change to
one is read against the others.
"""

# SPDX-License-Identifier: BSD-3-Clause

import functools
import hashlib
import importlib
import io
import json
import os
import re
import tempfile
import types
import warnings
import zipfile
import zlib
from pathlib import Path

import numpy as np

from skgesture._legacy import old_paths
from skgesture._version import __version__

__all__ = [
    "LayoutMismatchError",
    "ModelFileError",
    "ModelVersionError",
    "UntrustedTypesError",
    "load_model",
    "model_info",
    "save_model",
]

FORMAT = "skgesture-model"
FORMAT_VERSION = 1
MANIFEST = "manifest.json"
ESTIMATOR = "estimator.skops"
WEIGHTS = "weights.safetensors"
MEMBERS = (MANIFEST, ESTIMATOR, WEIGHTS)
MAX_MANIFEST_BYTES = 64 * 2**20  # a manifest is a few kB; refuse absurd ones

# Where classes named in a manifest may come from; a network's module class must
# come from skgesture itself.
_CLASS_PACKAGES = ("skgesture", "skorch", "torch")
_MODULE_PACKAGES = ("skgesture",)
# skorch attributes that initialize() rebuilds (or that only matter in training).
_SKORCH_ATTRIBUTES = {
    "callbacks_",
    "criterion_",
    "cuda_dependent_attributes_",
    "history_",
    "init_context_",
    "initialized_",
    "module_",
    "optimizer_",
    "prefixes_",
    "virtual_params_",
}
# Net parameters that only matter in training and are never stored.
_TRAINING_ONLY = {"callbacks", "train_split"}
# Classes that skgesture's estimators hold which are not in the public API
# table, by the public module that exports them (with the estimators of the
# table and the placeholders below, the only classes of skgesture that
# load_model trusts).
_SUPPORT_CLASSES = (
    ("skgesture.layouts", "DescriptorJoints"),
    ("skgesture.layouts", "SkeletonLayout"),
    ("skgesture.datasets", "SyntheticBackground"),  # a GesturePipeline's background
    ("skgesture.utils", "PoseNovelty"),  # a SequenceTagger's novelty_
)


class ModelFileError(ValueError):
    """A model file that cannot be read: not a model file, damaged or unsafe."""


class ModelVersionError(ModelFileError):
    """A model file written by another major.minor version of skgesture."""


class UntrustedTypesError(ModelFileError):
    """A model file holding types that nobody trusted.

    Attributes
    ----------
    types : list of str
        The untrusted types, to be passed in ``trusted`` if the file's origin
        is trusted.
    """

    def __init__(self, message, types):
        super().__init__(message)
        self.types = types


class LayoutMismatchError(ValueError):
    """Data whose skeleton layout differs from the one the model was trained on."""


class _NetSlot:
    """Placeholder of a skorch network inside the skops part of a model file."""

    def __init__(self, key):
        self.key = key


class _TensorSlot:
    """Placeholder of a torch tensor held directly by an estimator."""

    def __init__(self, key):
        self.key = key


class _NotEncodable(Exception):
    pass


# -- JSON encoding of network parameters ----------------------------------------


def _class_path(cls):
    return f"{cls.__module__}:{cls.__qualname__}"


def _class_allowed(cls, param):
    """Whether class ``cls`` may be the value of the net parameter ``param``.

    Each role takes its own kind of class: the module a torch module of
    skgesture, the criterion (and classes among module or criterion
    arguments) a torch module, the optimizer a torch optimizer, the iterators
    data loaders and the dataset a torch dataset. Nothing else is a class.
    """
    import torch

    top = cls.__module__.split(".")[0]
    if top not in _CLASS_PACKAGES:
        return False
    base = param.split("__")[0]
    if param == "module":
        return top in _MODULE_PACKAGES and issubclass(cls, torch.nn.Module)
    if base in ("module", "criterion"):
        return issubclass(cls, torch.nn.Module)
    if param == "optimizer":
        return issubclass(cls, torch.optim.Optimizer)
    if param in ("iterator_train", "iterator_valid"):
        return top != "torch" or issubclass(cls, torch.utils.data.DataLoader)
    if param == "dataset":
        return issubclass(cls, torch.utils.data.Dataset)
    return False


def _import_class(path, packages, what):
    """The class at ``"module:qualname"`` from ``packages``.

    Modules of skgesture may be imported; torch and skorch modules must already
    be imported (a model file never makes torch import a new module).
    """
    import sys

    import skorch  # noqa: F401 - makes skorch's own modules importable below
    import torch  # noqa: F401

    module_name, _, qualname = str(path).partition(":")
    top = module_name.split(".")[0]
    if top not in packages or not qualname:
        raise ModelFileError(
            f"{what} {path!r} is not allowed: only classes from "
            f"{', '.join(packages)} are rebuilt from a model file"
        )
    try:
        if top == "skgesture":
            obj = importlib.import_module(module_name)
        elif module_name in sys.modules:
            obj = sys.modules[module_name]
        else:
            raise ImportError(f"module {module_name} is not loaded")
        for part in qualname.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError) as exc:
        raise ModelFileError(
            f"{what} {path!r} does not exist in this installation ({exc})"
        ) from None
    if not isinstance(obj, type):
        raise ModelFileError(f"{what} {path!r} is not a class")
    return obj


def _encode(value, blobs, key, param=None):
    """JSON form of a net parameter; tensors and arrays go to ``blobs``.

    ``param`` names the net parameter (classes are allowed according to it).
    """
    import torch

    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if isinstance(value, tuple):
        return {
            "__tuple__": [
                _encode(v, blobs, f"{key}.{i}", param) for i, v in enumerate(value)
            ]
        }
    if isinstance(value, list):
        return [_encode(v, blobs, f"{key}.{i}", param) for i, v in enumerate(value)]
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value):
            raise _NotEncodable
        return {
            "__dict__": {
                k: _encode(v, blobs, f"{key}.{k}", param) for k, v in value.items()
            }
        }
    if isinstance(value, type):
        if param is None or not _class_allowed(value, param):
            raise _NotEncodable
        return {"__class__": _class_path(value)}
    if isinstance(value, torch.Tensor):
        blobs[key] = value.detach().cpu().clone().contiguous()
        return {"__tensor__": key}
    if isinstance(value, np.ndarray) and value.dtype.kind in "biuf":
        try:
            blobs[key] = torch.from_numpy(np.array(value, copy=True, order="C"))
        except TypeError:
            raise _NotEncodable from None
        return {"__ndarray__": key}
    raise _NotEncodable


def _decode(value, tensors, param=None):
    if isinstance(value, list):
        return [_decode(v, tensors, param) for v in value]
    if not isinstance(value, dict):
        return value
    if len(value) != 1:
        raise ModelFileError(f"malformed value in the manifest: {value!r:.80}")
    ((tag, inner),) = value.items()
    if tag == "__tuple__" and isinstance(inner, list):
        return tuple(_decode(v, tensors, param) for v in inner)
    if tag == "__dict__" and isinstance(inner, dict):
        return {k: _decode(v, tensors, param) for k, v in inner.items()}
    if tag == "__class__":
        cls = _import_class(inner, _CLASS_PACKAGES, f"class of {param}")
        if param is None or not _class_allowed(cls, param):
            raise ModelFileError(
                f"class {inner!r} is not allowed as the network parameter {param!r}"
            )
        return cls
    if tag in ("__tensor__", "__ndarray__") and isinstance(inner, str):
        if inner not in tensors:
            raise ModelFileError(f"tensor {inner!r} is missing from {WEIGHTS}")
        t = tensors[inner]
        return t.numpy() if tag == "__ndarray__" else t
    raise ModelFileError(f"malformed value in the manifest: {value!r:.80}")


# -- networks ------------------------------------------------------------------


def _net_spec(net, index, blobs, where):
    """Manifest entry of one fitted skorch net; its tensors go to ``blobs``."""
    prefix = f"net{index}"
    params = net.get_params(deep=False)
    module = params.get("module")
    if not (
        isinstance(module, type) and module.__module__.split(".")[0] in _MODULE_PACKAGES
    ):
        raise ValueError(
            f"cannot save {where}: its module {module!r} is not a class of "
            f"skgesture, and a model file only rebuilds skgesture networks (use "
            f"joblib for models whose code you trust)"
        )
    net_class = type(net)
    if net_class.__module__.split(".")[0] not in ("skorch", "skgesture"):
        raise ValueError(
            f"cannot save {where}: the network class {_class_path(net_class)} is "
            f"neither skorch's nor skgesture's"
        )
    encoded, dropped = {}, set()
    for name, value in params.items():
        if name.startswith("_") or name == "device":
            continue
        base = name.split("__")[0]
        if base in _TRAINING_ONLY:
            dropped.add(name)
            continue
        try:
            encoded[name] = _encode(value, blobs, f"{prefix}.params.{name}", param=name)
        except _NotEncodable:
            if base in ("module", "criterion"):
                raise ValueError(
                    f"cannot save {where}: its parameter {name}={value!r:.60} can "
                    f"not be written to a model file (JSON values, classes of "
                    f"{', '.join(_CLASS_PACKAGES)}, arrays and tensors can)"
                ) from None
            dropped.add(name)
    # A dropped component takes its keyword arguments with it (skorch defaults).
    for name in list(dropped):
        base = name.split("__")[0]
        for other in [k for k in encoded if k == base or k.startswith(base + "__")]:
            blobs.pop(f"{prefix}.params.{other}", None)
            dropped.add(other)
            del encoded[other]
    if not getattr(net, "initialized_", False):
        raise ValueError(f"cannot save {where}: the network is not initialised")
    states = {}
    for name in list(getattr(net, "_modules", ["module"])) + list(
        getattr(net, "_criteria", ["criterion"])
    ):
        component = getattr(net, name + "_", None)
        if component is None:
            continue
        key = f"{prefix}.{name}_."
        for pname, tensor in component.state_dict().items():
            blobs[key + pname] = tensor.detach().cpu().clone().contiguous()
        states[name + "_"] = key
    attributes = {}
    for name, value in vars(net).items():
        if not name.endswith("_") or name.startswith("_") or name in _SKORCH_ATTRIBUTES:
            continue
        if name in states:
            continue
        try:
            attributes[name] = _encode(value, blobs, f"{prefix}.attr.{name}")
        except _NotEncodable:
            dropped.add(name)
    history, history_blobs = None, {}
    try:
        history = _encode(list(net.history_), history_blobs, "history")
        json.dumps(history)
    except (_NotEncodable, AttributeError, TypeError, ValueError):
        history = None
    if history_blobs:  # arrays in the history: not worth the weights file
        history = None
    return {
        "class": _class_path(net_class),
        "params": encoded,
        "device": str(params.get("device", "cpu")),
        "states": states,
        "attributes": attributes,
        "history": history,
        "dropped": sorted(dropped),
    }


def _rebuild_net(spec, tensors, index):
    """A fitted skorch net, on the CPU, from its manifest entry and weights."""
    import torch
    from skorch import NeuralNet
    from skorch.history import History

    where = f"network {index}"
    try:
        net_class = _import_class(spec["class"], ("skorch", "skgesture"), where)
        if not issubclass(net_class, NeuralNet):
            raise ModelFileError(f"{where}: {spec['class']} is not a skorch NeuralNet")
        raw = spec["params"]
        module_path = (raw.get("module") or {}).get("__class__")
        module_class = _import_class(module_path, _MODULE_PACKAGES, f"{where} module")
        if not issubclass(module_class, torch.nn.Module):
            raise ModelFileError(f"{where}: {module_path} is not a torch module")
        params = {name: _decode(value, tensors, name) for name, value in raw.items()}
        params["device"] = "cpu"
        net = net_class(**params)
        with torch.random.fork_rng(devices=[]), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # e.g. skorch's notes on re-initialising
            net.initialize()
        net.saved_device_ = spec.get("device", "cpu")
        for attr, key in spec["states"].items():
            component = getattr(net, attr, None)
            if component is None:
                raise ModelFileError(f"{where} has no component {attr!r}")
            state = {k[len(key) :]: v for k, v in tensors.items() if k.startswith(key)}
            component.load_state_dict(state, strict=True)
        if spec.get("history") is not None:
            net.history_ = History(_decode(spec["history"], tensors))
        for name, value in spec.get("attributes", {}).items():
            setattr(net, name, _decode(value, tensors))
    except ModelFileError:
        raise
    except (KeyError, TypeError, ValueError, RuntimeError, AttributeError) as exc:
        raise ModelFileError(f"cannot rebuild {where}: {exc}") from None
    return net


def _deferrable(spec):
    """The plain ``module__*`` parameters of a network whose prediction needs
    no torch (a :class:`~skgesture.TorchMLPClassifier`'s MLP), else None."""
    module = (spec.get("params") or {}).get("module")
    path = module.get("__class__") if isinstance(module, dict) else None
    if not isinstance(path, str) or not path.startswith("skgesture."):
        return None
    if path.rpartition(":")[2] != "MLPModule":
        return None
    params = {}
    for name, value in spec["params"].items():
        if name.startswith("module__"):
            if not _is_plain(value):
                return None
            params[name] = _decode(value, {}, name)
    return params


def _is_plain(value):
    """Whether a manifest value decodes without classes or tensors."""
    if isinstance(value, list):
        return all(_is_plain(v) for v in value)
    if not isinstance(value, dict):
        return True
    if len(value) != 1:
        return False
    ((tag, inner),) = value.items()
    if tag == "__tuple__":
        return _is_plain(inner)
    if tag == "__dict__" and isinstance(inner, dict):
        return all(_is_plain(v) for v in inner.values())
    return False


def _built(net):
    """A skorch net, built if it is a network of a model file not built yet."""
    from skgesture._nn._deferred import DeferredNet

    return net.materialize() if isinstance(net, DeferredNet) else net


def _load_nets(path, specs, weights):
    """``({index: net}, tensors)`` of a model file's networks and weights.

    When every network is an MLP and no bare tensor is stored (Methods A and
    B), the weights are read as numpy arrays and each network is a
    :class:`~skgesture._nn._deferred.DeferredNet`, built with torch only if
    something other than prediction asks for it: loading and predicting then
    never import torch. Otherwise every network is rebuilt now.
    """
    deferred = [_deferrable(spec) for spec in specs]
    arrays = None
    if all(p is not None for p in deferred):
        import safetensors.numpy

        try:
            arrays = safetensors.numpy.load(weights)
        except Exception:  # e.g. a dtype numpy lacks: read it with torch below
            arrays = None
    if arrays is not None and all(k.startswith("net") for k in arrays):
        from skgesture._nn._deferred import DeferredNet

        nets = {}
        for i, (spec, params) in enumerate(zip(specs, deferred)):
            key = (spec.get("states") or {}).get("module_")
            if not isinstance(key, str):
                raise ModelFileError(f"{path}: network {i} has no module state")
            own = {k: v for k, v in arrays.items() if k.startswith(f"net{i}.")}
            module = {k[len(key) :]: v for k, v in own.items() if k.startswith(key)}
            nets[i] = DeferredNet(
                module, params, functools.partial(_rebuild_from_arrays, spec, own, i)
            )
        return nets, arrays
    import safetensors.torch

    try:
        tensors = safetensors.torch.load(weights)
    except Exception as exc:  # safetensors raises its own error types
        raise ModelFileError(f"{path}: unreadable weights ({exc})") from None
    return {i: _rebuild_net(spec, tensors, i) for i, spec in enumerate(specs)}, tensors


def _rebuild_from_arrays(spec, arrays, index):
    import torch

    tensors = {k: torch.from_numpy(v.copy()) for k, v in arrays.items()}
    return _rebuild_net(spec, tensors, index)


def _skops_io():
    """``skops.io``, imported without importing torch.

    skops lists the scikit-learn types it trusts with
    ``sklearn.utils.all_estimators``, whose walk over scikit-learn's packages
    imports ``sklearn.externals.array_api_compat.torch`` (and its siblings for
    other array libraries), hence torch: two seconds, for modules that hold
    no estimator and that the walk then skips. They are refused while skops
    is imported, and import as usual afterwards.
    """
    import sys

    if "skops.io" not in sys.modules:
        finder = _SkipArrayBackends()
        sys.meta_path.insert(0, finder)
        try:
            import skops.io  # noqa: F401
        finally:
            sys.meta_path.remove(finder)
    return sys.modules["skops.io"]


class _SkipArrayBackends:
    """An import hook refusing scikit-learn's vendored array-library adapters."""

    PREFIX = "sklearn.externals.array_api_compat."
    BACKENDS = {"torch", "cupy", "dask", "jax"}

    def find_spec(self, name, path=None, target=None):
        if name.startswith(self.PREFIX) and (
            name[len(self.PREFIX) :].split(".")[0] in self.BACKENDS
        ):
            raise ImportError(f"{name} is not imported while skops is")
        return None


# -- walking an estimator --------------------------------------------------------

# Objects whose attributes are not part of an estimator's state.
_OPAQUE = (
    types.ModuleType,
    types.FunctionType,
    types.BuiltinFunctionType,
    types.MethodType,
)


def _find_torch_objects(root):
    """Skorch nets and bare tensors reachable from ``root``, with a path to each."""
    import torch
    from skorch import NeuralNet

    from skgesture._nn._deferred import DeferredNet

    nets, tensors, seen = {}, {}, set()
    stack = [(root, "estimator")]
    while stack:
        obj, where = stack.pop()
        if obj is None or isinstance(obj, (str, bytes, int, float, np.ndarray, type)):
            continue
        if id(obj) in seen:
            continue
        seen.add(id(obj))
        if isinstance(obj, (NeuralNet, DeferredNet)):
            nets.setdefault(id(obj), (obj, where))
        elif isinstance(obj, torch.Tensor):
            tensors.setdefault(id(obj), (obj, where))
        elif isinstance(obj, (torch.nn.Module, torch.optim.Optimizer)):
            raise ValueError(
                f"cannot save {where}: a bare {type(obj).__name__} outside a skorch "
                f"network cannot be written to a model file"
            )
        elif isinstance(obj, (list, tuple, set, frozenset)):
            stack += [(v, f"{where}[{i}]") for i, v in enumerate(obj)]
        elif isinstance(obj, dict):
            stack += [(v, f"{where}[{k!r}]") for k, v in obj.items()]
        elif hasattr(obj, "__dict__") and not isinstance(obj, _OPAQUE):
            stack += [(v, f"{where}.{k}") for k, v in vars(obj).items()]
    return list(nets.values()), list(tensors.values())


def _fill_slots(obj, nets, tensors, seen, deferred_ok=False):
    """Replace the placeholders under ``obj`` (in place); return ``obj``'s value.

    A network stays deferred (:class:`~skgesture._nn._deferred.DeferredNet`)
    only as the ``net_`` of a :class:`~skgesture.TorchMLPClassifier`, whose
    prediction reads its arrays; anywhere else it is built.
    """
    if isinstance(obj, _NetSlot):
        return nets[obj.key] if deferred_ok else _built(nets[obj.key])
    if isinstance(obj, _TensorSlot):
        return tensors[obj.key]
    if obj is None or isinstance(obj, (str, bytes, int, float, np.ndarray, type)):
        return obj
    if id(obj) in seen:
        return obj
    seen.add(id(obj))
    if isinstance(obj, list):
        for i, v in enumerate(obj):
            obj[i] = _fill_slots(v, nets, tensors, seen)
    elif isinstance(obj, tuple):
        new = tuple(_fill_slots(v, nets, tensors, seen) for v in obj)
        if any(a is not b for a, b in zip(new, obj)):
            return type(obj)(new) if type(obj) is tuple else type(obj)(*new)
    elif isinstance(obj, dict):
        for k, v in obj.items():
            obj[k] = _fill_slots(v, nets, tensors, seen)
    elif hasattr(obj, "__dict__") and not isinstance(obj, _OPAQUE):
        from skgesture._nn._mlp import TorchMLPClassifier

        mlp = isinstance(obj, TorchMLPClassifier)
        for k, v in list(vars(obj).items()):
            new = _fill_slots(v, nets, tensors, seen, mlp and k == "net_")
            if new is not v:
                vars(obj)[k] = new
    return obj


def _input_layout(estimator):
    """What the model takes: frame shape, layout, descriptor joints, frame rate."""
    from sklearn.pipeline import Pipeline

    first = estimator
    while isinstance(first, Pipeline) and first.steps:
        first = first.steps[0][1]
    shape = getattr(first, "frame_shape_in_", None)
    from skgesture._concat import ConcatFeatures

    if isinstance(first, ConcatFeatures) and first.transformers:
        # features side by side read the same raw skeletons: the first's
        # layout and joints are the model's
        first = getattr(first, "transformers_", first.transformers)[0][1]
    fps = getattr(estimator, "fps_", None)  # a GesturePipeline's training rate
    info = {
        "frame_shape": None if shape is None else [int(s) for s in shape],
        "layout": None,
        "joints": None,
        "fps": None if fps is None else float(fps),
    }
    from skgesture._descriptor._estimator import PoseDescriptor
    from skgesture._features import JointFeatures

    if isinstance(first, (PoseDescriptor, JointFeatures)):
        # Both read raw Kinect v1 skeletons (other layouts are mapped first).
        from skgesture.layouts import KINECT_V1

        info["layout"] = KINECT_V1.name
        joints = first.joints
        if isinstance(joints, str):
            info["joints"] = joints
        elif hasattr(joints, "name"):  # a DescriptorJoints
            info["joints"] = joints.name
        else:  # JointFeatures: a list of joint names
            info["joints"] = [str(j) for j in joints]
    return info


def _classes(estimator):
    classes = getattr(estimator, "classes_", None)
    if classes is None and hasattr(estimator, "steps"):
        classes = getattr(estimator.steps[-1][1], "classes_", None)
    if classes is None:
        return None
    try:
        return [c.item() if hasattr(c, "item") else c for c in classes]
    except TypeError:
        return None


def _sha256(data):
    return hashlib.sha256(data).hexdigest()


# -- public API -------------------------------------------------------------------


def save_model(estimator, path, *, metadata=None, overwrite=False):
    """Write an estimator to one safe model file (skops + safetensors).

    Any scikit-learn estimator or pipeline of skgesture can be saved, fitted or
    not. Its scikit-learn parts are written with ``skops.io``; every skorch
    network inside (those of :class:`TorchMLPClassifier`, :class:`BiLSTMTagger`
    and the other taggers) is written as its module class, its JSON keyword
    arguments and its weights in safetensors format, so that
    :func:`load_model` never needs pickle. The file also records the skgesture
    version and the input the model expects (see ``docs/persistence.md``).

    Parameters
    ----------
    estimator : estimator
        The estimator to save; it is not modified.
    path : str or path-like
        The file to write (``.skg`` by convention). It is written to a temporary
        file first and moved into place, so a failure never leaves half a file.
    metadata : dict or None, default=None
        JSON-serialisable information stored with the model (for example the
        class names and the data it was trained on); ``model_info`` reads it.
    overwrite : bool, default=False
        Replace an existing file. By default an existing ``path`` raises
        ``FileExistsError``, as the command line refuses to overwrite without
        ``--overwrite``: a model is never replaced by accident.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        If a part of the estimator cannot be written safely: a network whose
        module class is not skgesture's, a torch module outside a skorch
        network, or non-JSON ``metadata``.
    FileExistsError
        If ``path`` exists and ``overwrite`` is False.

    See Also
    --------
    load_model : Read the file back.
    model_info : Read the manifest of a file without loading the model.

    Notes
    -----
    Classes of skgesture's public API are recorded under their public
    names (``skgesture.PoseDescriptor``), so moving a private module never
    breaks a file. Network parameters that only matter in training
    (callbacks, the validation split, components whose arguments are not
    JSON values) are not stored: a loaded network predicts exactly as the
    saved one, and ``fit`` of the loaded estimator builds new networks as
    usual. Weights are
    always stored on the CPU; a network trained with ``device="cuda"`` loads
    on a machine without CUDA.

    Examples
    --------
    >>> import tempfile, os
    >>> import numpy as np
    >>> from skgesture import TorchMLPClassifier, save_model, load_model
    >>> X = np.r_[np.zeros((20, 2)), np.ones((20, 2))]
    >>> y = np.r_[np.zeros(20, int), np.ones(20, int)]
    >>> clf = TorchMLPClassifier(hidden_layer_sizes=(4,), activations=("tanh",),
    ...                          max_epochs=20, random_state=0).fit(X, y)
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = save_model(clf, os.path.join(folder.name, "clf.skg"))
    >>> loaded = load_model(path)
    >>> bool((loaded.predict_proba(X) == clf.predict_proba(X)).all())
    True
    >>> folder.cleanup()
    """
    import copy

    import safetensors.torch
    import skops.io as sio

    path = Path(path).expanduser()
    if path.is_dir():
        raise IsADirectoryError(f"{path} is a folder; give the path of a model file")
    if not overwrite and path.exists():
        raise FileExistsError(f"{path} exists; pass overwrite=True to replace it")
    if metadata is not None:
        try:
            json.dumps(metadata, allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"metadata must be JSON-serialisable: {exc}") from None
    nets, bare_tensors = _find_torch_objects(estimator)
    blobs, specs, memo = {}, [], {}
    for i, (net, where) in enumerate(nets):
        specs.append(_net_spec(_built(net), i, blobs, where))
        memo[id(net)] = _NetSlot(i)
    for i, (tensor, _) in enumerate(bare_tensors):
        key = f"tensor{i}"
        blobs[key] = tensor.detach().cpu().clone().contiguous()
        memo[id(tensor)] = _TensorSlot(key)
    # deepcopy with the placeholders pre-set in its memo: the copy holds slots
    # where the nets and tensors were, the estimator itself is untouched
    stripped = copy.deepcopy(estimator, memo)
    try:
        skops_bytes = sio.dumps(stripped, compression=zipfile.ZIP_DEFLATED)
    except Exception as exc:  # skops raises many types for unsupported objects
        raise ValueError(f"cannot write the estimator with skops: {exc}") from exc
    skops_bytes = _with_public_names(skops_bytes)
    weights_bytes = safetensors.torch.save(blobs)
    import sklearn
    import skops
    import torch

    manifest = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "skgesture_version": __version__,
        "created_with": {
            "scikit-learn": sklearn.__version__,
            "skops": skops.__version__,
            "torch": torch.__version__,
        },
        "estimator": _public_class_path(type(estimator)),
        "input": _input_layout(estimator),
        "classes": _classes(estimator),
        "nets": specs,
        "metadata": metadata,
        "sha256": {ESTIMATOR: _sha256(skops_bytes), WEIGHTS: _sha256(weights_bytes)},
    }
    manifest_bytes = json.dumps(manifest, indent=1).encode()
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh, zipfile.ZipFile(fh, "w") as zf:
            zf.writestr(MANIFEST, manifest_bytes, compress_type=zipfile.ZIP_DEFLATED)
            zf.writestr(ESTIMATOR, skops_bytes, compress_type=zipfile.ZIP_DEFLATED)
            zf.writestr(WEIGHTS, weights_bytes, compress_type=zipfile.ZIP_DEFLATED)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _read_members(path):
    """The three members of a model file, checked against the format."""
    path = Path(path).expanduser()
    if not path.exists():
        raise FileNotFoundError(f"model file {path} does not exist")
    if path.is_dir():
        raise IsADirectoryError(f"{path} is a folder, not a model file")
    try:
        with zipfile.ZipFile(path) as zf:
            names = zf.namelist()
            extra = sorted(set(names) - set(MEMBERS))
            missing = [m for m in MEMBERS if m not in names]
            if extra or missing or len(names) != len(MEMBERS):
                what = []
                if missing:
                    what.append(f"missing {', '.join(missing)}")
                if extra:
                    more = f" and {len(extra) - 3} more" if len(extra) > 3 else ""
                    what.append(f"unexpected {', '.join(extra[:3])}{more}")
                if len(names) != len(set(names)):
                    what.append("duplicate members")
                raise ModelFileError(
                    f"{path} is not a skgesture model file, or is damaged "
                    f"({'; '.join(what)})"
                )
            if zf.getinfo(MANIFEST).file_size > MAX_MANIFEST_BYTES:
                raise ModelFileError(f"{path}: its manifest is implausibly large")
            data = {name: zf.read(name) for name in MEMBERS}
    except ModelFileError:
        raise
    except OSError as exc:
        if exc.errno is not None:  # a real I/O error (permissions, ...)
            raise
        raise ModelFileError(f"{path} is damaged: {exc}") from None
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError) as exc:
        raise ModelFileError(
            f"{path} is not a skgesture model file or is damaged (truncated?): {exc}"
        ) from None
    except (zlib.error, ValueError, RuntimeError, NotImplementedError) as exc:
        raise ModelFileError(f"{path} is damaged: {exc}") from None
    try:
        manifest = json.loads(data[MANIFEST])
    except (ValueError, UnicodeDecodeError) as exc:
        raise ModelFileError(f"{path}: unreadable manifest ({exc})") from None
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise ModelFileError(f"{path} is not a skgesture model file")
    version = manifest.get("format_version")
    if not isinstance(version, int) or version > FORMAT_VERSION:
        raise ModelVersionError(
            f"{path} uses model-file format {version!r}, newer than this "
            f"skgesture ({__version__}) reads ({FORMAT_VERSION}); upgrade skgesture"
        )
    sums = manifest.get("sha256") or {}
    for name in (ESTIMATOR, WEIGHTS):
        if sums.get(name) != _sha256(data[name]):
            raise ModelFileError(f"{path} is damaged: {name} fails its checksum")
    return path, manifest, data


def _major_minor(version):
    match = re.match(r"^\s*(\d+)\.(\d+)", str(version))
    return (int(match.group(1)), int(match.group(2))) if match else None


def _check_version(path, manifest, allow_version_mismatch):
    saved = manifest.get("skgesture_version")
    if _major_minor(saved) == _major_minor(__version__):
        return
    message = (
        f"{path} was written by skgesture {saved}, this is skgesture {__version__}: "
        f"models are only guaranteed to load in the same major.minor version"
    )
    if not allow_version_mismatch:
        raise ModelVersionError(
            message + " (pass allow_version_mismatch=True, or --allow-version-"
            "mismatch on the command line, to load it anyway)"
        )
    warnings.warn(message, UserWarning, stacklevel=3)


def _layout_text(info):
    shape = info.get("frame_shape")
    shape = "unknown shape" if shape is None else str(tuple(shape))
    return f"{info.get('layout') or 'frames'} {shape}"


def _check_layout(path, manifest, layout):
    if layout is None:
        return
    info = manifest.get("input") or {}
    if isinstance(layout, str):
        from skgesture.streaming import get_adapter

        get_adapter(layout)  # a misspelt layout name is an error, not a pass
        if info.get("layout") is not None and info["layout"] != layout:
            raise LayoutMismatchError(
                f"{path} expects skeletons of layout {info['layout']!r}, the data "
                f"has layout {layout!r}; map it first (see skgesture.streaming "
                f"adapters or load_recordings(layout=...))"
            )
        return
    shape = [int(s) for s in layout]
    if info.get("frame_shape") is not None and info["frame_shape"] != shape:
        raise LayoutMismatchError(
            f"{path} expects frames of shape {tuple(info['frame_shape'])} "
            f"({_layout_text(info)}), the data has frames of shape {tuple(shape)}"
        )


# -- the classes of skgesture a model file names ------------------------------------


@functools.cache
def _skgesture_classes():
    """``{class: stable name}`` of every class of skgesture a model file may hold.

    The estimators of the public API table (``skgesture._LAZY``: the public
    classes that are scikit-learn estimators) under their public names
    (``skgesture.PoseDescriptor``), the classes they hold that the table does
    not list (:data:`_SUPPORT_CLASSES`) under their public module, and the
    placeholders of this module under their own path (:func:`_stable_name`).
    It imports every module of the table; reading a file needs only
    :func:`_is_trusted_name`, which imports the modules the file names.
    """
    import skgesture

    candidates = [getattr(skgesture, name) for name in skgesture._LAZY]
    candidates += [getattr(importlib.import_module(m), n) for m, n in _SUPPORT_CLASSES]
    candidates += [_NetSlot, _TensorSlot]
    names = {obj: _stable_name(obj) for obj in candidates if isinstance(obj, type)}
    return {cls: name for cls, name in names.items() if name is not None}


def _stable_name(cls):
    """The name under which a model file of this version names ``cls``, or
    None when ``cls`` is not a class of skgesture that a file may hold."""
    from sklearn.base import BaseEstimator

    import skgesture

    if cls in (_NetSlot, _TensorSlot):
        return f"{cls.__module__}.{cls.__qualname__}"
    for module, name in _SUPPORT_CLASSES:
        if cls.__name__ == name and _resolve(f"{module}.{name}") is cls:
            return f"{module}.{name}"
    name = cls.__name__
    if (
        name in skgesture._LAZY
        and getattr(skgesture, name) is cls
        and issubclass(cls, BaseEstimator)
    ):
        return f"skgesture.{name}"
    return None


def _resolve(type_name):
    """The object at the dotted path ``type_name``, found as skops finds it."""
    module_name, _, name = type_name.rpartition(".")
    try:
        return getattr(importlib.import_module(module_name), name)
    except (ImportError, AttributeError):
        return None


def _names_of(cls, stable):
    """Every name under which ``load_model`` trusts ``cls`` (stable name ``stable``).

    Its stable name (files of this version), the module that defines it and
    the packages above that module that export it (files written before public
    names were recorded; 0.1's ``skgesture._descriptor`` was a module), the
    module the API table names for it, and its module paths of 0.1
    (``skgesture._legacy.MOVED``). A name is trusted only if it imports that
    very class, so nothing outside the table is reachable through one.
    """
    import skgesture

    name, module = cls.__name__, cls.__module__
    parts = module.split(".")
    candidates = {stable, f"{module}.{name}"}
    candidates |= {".".join(parts[:i]) + f".{name}" for i in range(2, len(parts))}
    if name in skgesture._LAZY:
        candidates.add(f"{skgesture._LAZY[name]}.{name}")
    candidates |= {f"{old}.{name}" for old in old_paths(cls)}
    return {c for c in candidates if _resolve(c) is cls}


@functools.cache
def _trusted_type_names():
    """Every type name under which ``load_model`` trusts a class of skgesture."""
    names = set()
    for cls, stable in _skgesture_classes().items():
        names |= _names_of(cls, stable)
    return frozenset(names)


@functools.cache
def _is_trusted_name(type_name):
    """Whether ``type_name`` is one of :func:`_trusted_type_names`, importing
    only the skgesture module that it names (not torch with the taggers)."""
    if not type_name.startswith("skgesture."):
        return False
    cls = _resolve(type_name)
    if not isinstance(cls, type):
        return False
    stable = _stable_name(cls)
    return stable is not None and type_name in _names_of(cls, stable)


def _renamed_modules():
    """``{"module.Class": public module}`` for the classes that have a public
    name other than the path that defines them."""
    renames = {}
    for cls, stable in _skgesture_classes().items():
        module, _, name = stable.rpartition(".")
        here = f"{cls.__module__}.{cls.__name__}"
        if name == cls.__name__ and stable != here:
            renames[here] = module
    return renames


def _with_public_names(skops_bytes):
    """The skops archive ``skops_bytes`` with its classes named by public names.

    Every node of the schema whose ``__module__`` and ``__class__`` name a
    class of :func:`_renamed_modules` gets the public module (``skgesture``
    for ``skgesture._descriptor._estimator.PoseDescriptor``); skops imports
    the class from there when loading (``skgesture`` resolves it lazily).
    """
    renames = _renamed_modules()
    with zipfile.ZipFile(io.BytesIO(skops_bytes)) as zf:
        members = [(info, zf.read(info)) for info in zf.infolist()]
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as out:
        for info, blob in members:
            if info.filename == "schema.json":
                schema = json.loads(blob)
                stack = [schema]
                while stack:
                    node = stack.pop()
                    if isinstance(node, list):
                        stack.extend(node)
                    elif isinstance(node, dict):
                        module, name = node.get("__module__"), node.get("__class__")
                        if isinstance(module, str) and isinstance(name, str):
                            node["__module__"] = renames.get(f"{module}.{name}", module)
                        stack.extend(node.values())
                blob = json.dumps(schema, indent=2).encode()
            out.writestr(info.filename, blob, compress_type=info.compress_type)
    return buffer.getvalue()


def _public_class_path(cls):
    """``module:qualname`` of ``cls``, by its public name where it has one."""
    stable = _skgesture_classes().get(cls)
    if stable is not None and f"{cls.__module__}.{cls.__name__}" in _renamed_modules():
        module, _, name = stable.rpartition(".")
        return f"{module}:{name}"
    return _class_path(cls)


def model_info(path):
    """Read the manifest of a model file, without loading the model.

    The manifest is plain JSON: reading it builds nothing, so it is safe on
    any file. It says what the model is and what it expects.

    Parameters
    ----------
    path : str or path-like
        A file written by :func:`save_model`.

    Returns
    -------
    dict
        ``skgesture_version``, ``estimator`` (class path), ``input``
        (``frame_shape``, ``layout``, ``joints``), ``classes``, ``metadata``
        and the description of every network (``nets``).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ModelFileError
        If it is not a model file or is damaged.

    See Also
    --------
    save_model : Writes the manifest (``metadata`` goes into it).
    load_model : Loads the model itself.

    Examples
    --------
    >>> import tempfile, os
    >>> from skgesture import make_method_b, save_model
    >>> from skgesture._persistence import model_info
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = save_model(make_method_b(), os.path.join(folder.name, "b.skg"),
    ...                   metadata={"note": "unfitted"})
    >>> info = model_info(path)
    >>> info["estimator"], info["metadata"]
    ('skgesture:GesturePipeline', {'note': 'unfitted'})
    >>> folder.cleanup()
    """
    return _read_members(path)[1]


def load_model(path, *, trusted=None, layout=None, allow_version_mismatch=False):
    """Read a model file written by :func:`save_model`, without pickle.

    The file is checked (format, checksums, skgesture version, and the input
    layout when ``layout`` is given) before anything is built. scikit-learn
    parts are rebuilt by ``skops.io.loads`` and networks from their module
    class (only classes of skgesture are accepted) and their safetensors
    weights, on the CPU.

    Parameters
    ----------
    path : str or path-like
        The model file.
    trusted : list of str or None, default=None
        Further types to trust, as listed by the error (or by
        ``skops.io.get_untrusted_types``). Types that skops trusts by
        default (scikit-learn, numpy, scipy), the estimators of skgesture's
        public API (the classes of ``skgesture.__all__``, under their public
        name, their module path or their 0.1 path) and the few classes they
        hold (``skgesture.layouts.DescriptorJoints`` and ``SkeletonLayout``)
        are always trusted; anything else in the file is refused unless named
        here.
    layout : str, tuple of int or None, default=None
        The skeleton layout name (e.g. ``"kinect_v1"``) or frame shape (e.g.
        ``(20, 3)``) of the data the model will be used on; a model trained on
        another layout raises ``LayoutMismatchError``, and a name that is no
        known layout (``skgesture.streaming.get_adapter``) a ``ValueError``.
    allow_version_mismatch : bool, default=False
        Load a file written by another major.minor version of skgesture (with
        a warning) instead of raising ``ModelVersionError``.

    Returns
    -------
    estimator
        The estimator, ready to predict.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ModelFileError
        If the file is not a model file, is truncated or damaged, or a network
        cannot be rebuilt.
    ModelVersionError
        If the file comes from another skgesture version (see
        ``allow_version_mismatch``).
    UntrustedTypesError
        If the file holds types that are not trusted; its ``types`` attribute
        lists them.
    LayoutMismatchError
        If ``layout`` differs from the model's input layout.

    See Also
    --------
    save_model : Write a model file.
    model_info : Read only the manifest.

    Notes
    -----
    joblib and pickle keep working for estimators whose origin you trust, but
    they run code from the file; use model files to exchange models.

    Examples
    --------
    >>> import tempfile, os
    >>> from skgesture import make_method_c, save_model, load_model
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> pipe = make_method_c(random_state=0).set_params(
    ...     tagger__hidden_sizes=(8,), tagger__max_epochs=2).fit([X], [y])
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = save_model(pipe, os.path.join(folder.name, "c.skg"))
    >>> loaded = load_model(path, layout=(20, 3))
    >>> bool((loaded.predict([X])[0] == pipe.predict([X])[0]).all())
    True
    >>> folder.cleanup()
    """
    sio = _skops_io()
    path, manifest, data = _read_members(path)
    _check_version(path, manifest, allow_version_mismatch)
    _check_layout(path, manifest, layout)
    try:
        found = sio.get_untrusted_types(data=data[ESTIMATOR])
    except Exception as exc:  # a damaged skops archive or schema
        raise ModelFileError(f"{path}: unreadable estimator ({exc})") from None
    user_trusted = set(trusted or ())
    refused = [t for t in found if t not in user_trusted and not _is_trusted_name(t)]
    if refused:
        raise UntrustedTypesError(
            f"{path} holds types that are not trusted: {', '.join(refused)}. If "
            f"you trust the file's origin, pass trusted=[...] naming them",
            refused,
        )
    nets, tensors = _load_nets(path, manifest.get("nets") or [], data[WEIGHTS])
    try:
        estimator = sio.loads(data[ESTIMATOR], trusted=found)
    except Exception as exc:  # skops raises many types on a damaged schema
        raise ModelFileError(f"{path}: cannot rebuild the estimator ({exc})") from None
    try:
        return _fill_slots(estimator, nets, tensors, set())
    except KeyError as exc:
        raise ModelFileError(
            f"{path}: the estimator refers to a missing {exc}"
        ) from None
