"""Physical models behind one small interface (the model seam of the fragility studies).

* :mod:`shipblock.models.base`: the interface (:class:`Model`, :class:`Field`,
  :class:`EDPInfo`, :class:`FieldError`) and the registry by name (:func:`register_model`,
  :func:`get_model`);
* :mod:`shipblock.models.rigid`: the rigid ship-block model of the seed paper
  (``"rigid"``, registered here, the default of every study).
"""

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

register_model(RigidModel())

__all__ = ["DEFAULT_MODEL", "EDPInfo", "Field", "FieldError", "Model", "RigidModel",
           "get_model", "model_names", "register_model", "unregister_model"]
