"""From fragility to a decision: site hazard, risk over a docking period, record selection.

* :mod:`shipblock.risk.hazard`: site hazard curves (OpenQuake, USGS nshmp-haz CSV, USGS hazard
  service JSON, two-column tables) read into SI with their provenance.
* :mod:`shipblock.risk.integral`: the risk integral of a lognormal fragility on a hazard curve,
  its deaggregation, and the probability during a docking period.
* :mod:`shipblock.risk.study`: the same for every fit of a fragility result (with the bootstrap
  band), written as a copy of the result (:func:`run_risk`, ``shipblock risk``).
* :mod:`shipblock.risk.selection`: the records of a catalogue that best match a target
  spectrum (``shipblock select``).

A studies-layer package: it reads results of :mod:`shipblock.fragility` and uses
:mod:`shipblock.intensity`; figures are in :mod:`shipblock.plot_risk`.
"""

from shipblock.risk.hazard import HAZARD_FORMATS, HazardCurve, HazardError, read_hazard_curve
from shipblock.risk.integral import (
    DAYS_PER_YEAR,
    RiskIntegral,
    period_probability,
    risk_integral,
)
from shipblock.risk.selection import (
    RecordMatch,
    Selection,
    select_records,
    selection_toml,
    target_from_file,
)
from shipblock.risk.study import bootstrap_replicates, risk_dataset, run_risk, study_measure

__all__ = [
    "DAYS_PER_YEAR",
    "HAZARD_FORMATS",
    "HazardCurve",
    "HazardError",
    "RecordMatch",
    "RiskIntegral",
    "Selection",
    "bootstrap_replicates",
    "period_probability",
    "read_hazard_curve",
    "risk_dataset",
    "risk_integral",
    "run_risk",
    "select_records",
    "selection_toml",
    "study_measure",
    "target_from_file",
]
