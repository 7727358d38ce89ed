"""Physical models behind one small interface (the model seam of the fragility studies).

* :mod:`shipblock.models.base`: the interface (:class:`Model`, :class:`Field`,
  :class:`EDPInfo`, :class:`FieldError`) and the registry by name (:func:`register_model`,
  :func:`get_model`);
* :mod:`shipblock.models.rigid`: the rigid ship-block model of the seed paper
  (``"rigid"``, registered here, the default of every study);
* :mod:`shipblock.models.section`: the dock-section model of :mod:`shipblock.section`
  (``"section"``, registered here by its path: its module, the section package and its
  compiled kernel are imported when a study first asks for the model, not by a study of the
  rigid model; ``shipblock.models.SectionModel`` loads them too).
"""

from __future__ import annotations

import importlib

from shipblock.models.base import (
    EDPInfo,
    Field,
    FieldError,
    Model,
    get_model,
    model_names,
    register_model,
    unregister_model,
)
from shipblock.models.rigid import RigidModel

#: The name of the model a study uses when it names none.
DEFAULT_MODEL = "rigid"

#: Classes of the models registered by their path, made importable from this package on first
#: use (name -> module).
_LAZY = {"SectionModel": "shipblock.models.section"}

register_model(RigidModel())
register_model("shipblock.models.section:SectionModel", name="section")


def __getattr__(name):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'shipblock.models' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)


def __dir__():
    """The names loaded so far and those loaded on first use (``dir``, completion)."""
    return sorted(set(globals()) | set(_LAZY))


__all__ = ["DEFAULT_MODEL", "EDPInfo", "Field", "FieldError", "Model", "RigidModel",
           "SectionModel", "get_model", "model_names", "register_model", "unregister_model"]
