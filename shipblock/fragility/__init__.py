"""Fragility analysis: limit states on run summaries and lognormal fragility fitting.

See :mod:`shipblock.fragility.limit_states` (which runs exceed what) and
:mod:`shipblock.fragility.fit` (probability of exceedance as a function of IM).
"""

from shipblock.fragility.fit import (
    BootstrapResult,
    FragilityFit,
    FragilityFitError,
    IDACapacities,
    bootstrap,
    fit_cloud,
    fit_ida,
    fit_mle,
    fit_msa,
    ida_capacities,
    lognormal_fragility,
)
from shipblock.fragility.limit_states import (
    CONDITIONS,
    EDP_VARIABLES,
    FAILURE_CODES,
    EDPInfo,
    Exceedance,
    LimitState,
    evaluate_limit_states,
    exceedance,
    parse_limit_states,
)

__all__ = [
    "BootstrapResult",
    "CONDITIONS",
    "EDPInfo",
    "EDP_VARIABLES",
    "Exceedance",
    "FAILURE_CODES",
    "FragilityFit",
    "FragilityFitError",
    "IDACapacities",
    "LimitState",
    "bootstrap",
    "evaluate_limit_states",
    "exceedance",
    "fit_cloud",
    "fit_ida",
    "fit_mle",
    "fit_msa",
    "ida_capacities",
    "lognormal_fragility",
    "parse_limit_states",
]
