"""shipblock: seismic response of a free-standing ship on keel blocks.

The physics (all eight modes of motion, transitions, impacts and failure) is in
:mod:`shipblock.equations`, :mod:`shipblock.impact` and :mod:`shipblock.solver`; ground motions
in :mod:`shipblock.records`, :mod:`shipblock.processing`, :mod:`shipblock.scaling` and
:mod:`shipblock.intensity`; batch runs and fragility in :mod:`shipblock.fragility`.
"""

from __future__ import annotations

import importlib

from shipblock.modes import EventKind, Failure, Mode
from shipblock.result import Energy, Event, SimulationResult
from shipblock.system import ShipBlockSystem, system_restitution
from shipblock.version import __version__

# Heavier parts load on first use (numba and the solver, obspy, xarray, scipy.stats): a command
# that does not simulate does not import the solver.
_LAZY = {
    "simulate": "shipblock.solver",
    "simulate_batch": "shipblock.solver",
    "RecordSet": "shipblock.solver",
    "read_motion": "shipblock.records.reading",
    "GroundMotion": "shipblock.records.motion",
    "COMPONENT_KEY": "shipblock.records.motion",
    "rotate_to_azimuth": "shipblock.records.motion",
    "read_record": "shipblock.io",
    "read_motions": "shipblock.records.folders",
    "MotionSet": "shipblock.records.folders",
    "load_catalogue": "shipblock.records.catalogue",
    "ShipblockError": "shipblock.errors",
    "RecordError": "shipblock.errors",
    "UnitsError": "shipblock.errors",
    "intensity": "shipblock.intensity",
    "processing": "shipblock.processing",
    "scaling": "shipblock.scaling",
    "run_pipeline": "shipblock.fragility.pipeline",
    "rerun_case": "shipblock.fragility.pipeline",
}


def __getattr__(name):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'shipblock' has no attribute {name!r}")
    mod = importlib.import_module(module)
    return mod if module.endswith("." + name) else getattr(mod, name)


def __dir__():
    """The names loaded so far and those loaded on first use (``dir(shipblock)``, completion)."""
    return sorted(set(globals()) | set(_LAZY))


__all__ = [
    "ShipBlockSystem",
    "simulate",
    "simulate_batch",
    "RecordSet",
    "SimulationResult",
    "Event",
    "Energy",
    "Mode",
    "EventKind",
    "Failure",
    "system_restitution",
    "__version__",
    *_LAZY,
]
