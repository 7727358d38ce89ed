"""Physical models behind one small interface (the model seam of the fragility studies).

* :mod:`shipblock.models.base`: the interface (:class:`Model`, :class:`Field`,
  :class:`EDPInfo`, :class:`FieldError`) and the registry by name (:func:`register_model`,
  :func:`get_model`);
* :mod:`shipblock.models.rigid`: the rigid ship-block model of the seed paper
  (``"rigid"``, registered here, the default of every study);
* :mod:`shipblock.models.section`: the dock-section model of :mod:`shipblock.section`
  (``"section"``, registered here).
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
from shipblock.models.section import SectionModel

#: The name of the model a study uses when it names none.
DEFAULT_MODEL = "rigid"

register_model(RigidModel())
register_model(SectionModel())

__all__ = ["DEFAULT_MODEL", "EDPInfo", "Field", "FieldError", "Model", "RigidModel",
           "SectionModel", "get_model", "model_names", "register_model", "unregister_model"]
