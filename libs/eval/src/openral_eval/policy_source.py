"""Policies named by where their class is: ``path/to/file.py:ClassName`` or
``package.module:ClassName``, beside the registered names.

The class is built from a config the same way a registered policy is: when it has a
``config_type`` class attribute (a pydantic model or a dataclass), ``--param key=value``
fills that config's fields (:mod:`openral_eval.policy_config`) and the class is called with
it; without one, it takes no parameters and is called with none. A file is executed once
per process (a sweep's worker builds a policy per episode) under a module name derived
from its absolute path; a forked process (a sweep's worker) executes it again, so what a
file opens at import is opened after the fork, in the process that reads it. A
``module:Class`` is imported as any module is, once: a module that opens files at import
shares them with the forked workers, so open them in ``__init__`` or ``act`` instead.

Example::

    openral sim sweep --config robots/franka_panda/scenes/tabletop.yaml --seeds 0:4 \\
        --policy my_policy.py:Wave -p amplitude=0.2 --out out/mine
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib
import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

from openral_eval.policy import PolicyAdapter, PolicyConfigError
from openral_eval.policy_config import is_config_type

_LOADED: dict[Path, ModuleType] = {}
"""Files executed in this process, by absolute path."""


def _forget_loaded() -> None:
    """In a forked child: forget the files the parent executed, so the child executes each
    again and whatever a file opens at import (a ``np.load`` archive, a socket) is its own
    (one handle shared across the fork broke every worker's reads: "Bad CRC-32")."""
    for module in _LOADED.values():
        sys.modules.pop(module.__name__, None)
    _LOADED.clear()


os.register_at_fork(after_in_child=_forget_loaded)


@dataclasses.dataclass(frozen=True)
class NoConfig:
    """The config of a policy class with no ``config_type``: no parameters."""


def is_reference(name: str) -> bool:
    """Whether policy ``name`` names a class (``file.py:Class``, ``module:Class``)."""
    return ":" in name


def load_class(reference: str) -> tuple[type[Any], type[Any]]:
    """(class, config dataclass) of ``reference`` (see the module doc).

    Raises:
        PolicyConfigError: The file or module cannot be found or imported, it has no such
            class, or the class's ``config_type`` is neither a pydantic model nor a
            dataclass; one line each.
    """
    where, _, class_name = reference.rpartition(":")
    if not where or not class_name.isidentifier():
        raise PolicyConfigError(
            f"policy {reference!r}: expected FILE.py:CLASS or package.module:CLASS"
        )
    module = _module(reference, where)
    cls = getattr(module, class_name, None)
    if not isinstance(cls, type):
        defined = sorted(n for n, v in vars(module).items() if isinstance(v, type))
        raise PolicyConfigError(
            f"policy {reference!r}: {where} defines no class {class_name}; its classes: "
            f"{', '.join(defined) or 'none'}"
        )
    config_type = getattr(cls, "config_type", NoConfig)
    if not is_config_type(config_type):
        raise PolicyConfigError(
            f"policy {reference!r}: {class_name}.config_type must be a pydantic model or a "
            "dataclass of its parameters"
        )
    return cls, config_type


def build(cls: type[Any], config: object) -> PolicyAdapter:
    """An instance of ``cls`` from its parsed config (none for :class:`NoConfig`)."""
    policy: PolicyAdapter = cls() if isinstance(config, NoConfig) else cls(config)
    return policy


def _module(reference: str, where: str) -> ModuleType:
    """The module of a reference: a ``.py`` file (executed once) or an importable name."""
    try:
        if where.endswith(".py"):
            return _file_module(reference, Path(where))
        return importlib.import_module(where)
    except PolicyConfigError:
        raise
    except Exception as error:  # the policy's own module failed: its fault, in one line
        raise PolicyConfigError(
            f"policy {reference!r}: {where} does not import ({type(error).__name__}: {error})"
        ) from None


def _file_module(reference: str, path: Path) -> ModuleType:
    path = path.resolve()
    if path in _LOADED:
        return _LOADED[path]
    if not path.is_file():
        raise PolicyConfigError(f"policy {reference!r}: no file {path}")
    digest = hashlib.sha256(str(path).encode()).hexdigest()[:12]
    name = f"openral_policy_{path.stem}_{digest}"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None  # a .py file always has both
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses and pickling look the module up by name
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    _LOADED[path] = module
    return module
