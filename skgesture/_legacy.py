"""Import paths of skgesture 0.1, kept for one release (to be removed in 0.3).

Model files and joblib pickles written by skgesture 0.1 name classes by the
private module that defined them then (``skgesture._tagger.SequenceTagger``,
``skgesture._networks.MLPModule``, ...). Those modules moved into the
``skgesture._nn`` and ``skgesture._taggers`` subpackages (docs/design.md,
"Module map"). This module keeps the old paths importable: an old path is a
module whose attributes are looked up, in order, in the modules its names went
to.

Model files written now name the classes of the public API by their public
names (``skgesture.PoseDescriptor``), which no move changes; the classes they
name by a private path (network modules, losses and loaders in the manifest,
the placeholders of ``skgesture._persistence``, and every class in a joblib
pickle) keep working across a later move only if the old module path is added
to :data:`MOVED` (docs/persistence.md, "Names in a file").
"""

# SPDX-License-Identifier: BSD-3-Clause

import importlib
import importlib.abc
import importlib.util
import sys
import types

# Old module path -> the modules its names moved to, searched in order.
MOVED = {
    "skgesture._incremental": (
        "skgesture._stream",
        "skgesture.utils._buffers",
        "skgesture.utils._smoothing",
    ),
    "skgesture._tagger": (
        "skgesture._taggers._base",
        "skgesture._taggers._sequence",
        "skgesture._taggers._voting",
        "skgesture._nn._sequence_net",
    ),
    "skgesture._bilstm": ("skgesture._taggers._bilstm", "skgesture._nn._modules"),
    "skgesture._networks": ("skgesture._nn._training", "skgesture._nn._modules"),
    "skgesture._modules": ("skgesture._nn._modules",),
    "skgesture._mlp": ("skgesture._nn._mlp",),
    "skgesture._decoding": ("skgesture._taggers._decoding",),
    "skgesture._descriptor_kernel": ("skgesture._descriptor._kernel",),
}


# Names of 0.1 that a later class replaced: (old module, old name) -> (module,
# name). One train_split class replaced three.
RENAMED = {
    ("skgesture._networks", "_TrainOnly"): ("skgesture._nn._training", "SequenceSplit"),
    ("skgesture._tagger", "_HoldOutSequences"): (
        "skgesture._nn._training",
        "SequenceSplit",
    ),
    ("skgesture._bilstm", "_SequenceHoldout"): (
        "skgesture._nn._training",
        "SequenceSplit",
    ),
}


def _lookup(old, name):
    if (old, name) in RENAMED:
        module, new = RENAMED[old, name]
        return getattr(importlib.import_module(module), new)
    for target in MOVED[old]:
        module = importlib.import_module(target)
        if name in vars(module):
            return vars(module)[name]
    raise AttributeError(f"module {old!r} (moved) has no attribute {name!r}")


class _MovedModule(types.ModuleType):
    """An old module path: its attributes are those of the modules it went to."""

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return _lookup(self.__name__, name)


class _Loader(importlib.abc.Loader):
    def create_module(self, spec):
        return _MovedModule(spec.name)

    def exec_module(self, module):
        module.__doc__ = (
            f"Moved in skgesture 0.2 to {', '.join(MOVED[module.__name__])}; "
            f"kept for files written by 0.1."
        )


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        if fullname in MOVED:
            return importlib.util.spec_from_loader(fullname, _Loader())
        return None


def old_paths(cls):
    """The old module paths (keys of :data:`MOVED`) that resolve ``cls``.

    An old path resolves a name to the first of its modules that defines it,
    so a class is listed only where that lookup gives the class itself.
    """
    paths = []
    for old, new in MOVED.items():
        if cls.__module__ not in new:
            continue
        try:
            if _lookup(old, cls.__name__) is cls:
                paths.append(old)
        except AttributeError:
            pass
    return paths


def install():
    """Make the old paths importable (idempotent)."""
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.append(_Finder())
