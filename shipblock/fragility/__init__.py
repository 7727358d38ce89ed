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
    fit_ida_intervals,
    fit_ida_levels,
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
    "fit_ida_intervals",
    "fit_ida_levels",
    "fit_mle",
    "fit_msa",
    "ida_capacities",
    "lognormal_fragility",
    "parse_limit_states",
]
from shipblock.fragility.batch import PreparedRecord, prepare_record, run_batch, run_chunk  # noqa: E402
from shipblock.fragility.design import AnalysisDesign, IntensityDesign, apply_parameters  # noqa: E402
from shipblock.fragility.store import ChunkStore, StoreError, open_results, write_dataset  # noqa: E402

__all__ += [
    "AnalysisDesign",
    "ChunkStore",
    "IntensityDesign",
    "PreparedRecord",
    "StoreError",
    "apply_parameters",
    "open_results",
    "prepare_record",
    "run_batch",
    "run_chunk",
    "write_dataset",
]
from shipblock.fragility.histories import (  # noqa: E402
    SelectionError,
    case_number,
    run_case,
    select_cases,
    write_histories,
)
from shipblock.fragility.keys import PipelineError  # noqa: E402
from shipblock.fragility.pipeline import run_pipeline  # noqa: E402
from shipblock.fragility.reruns import rerun_case  # noqa: E402
from shipblock.fragility.schema import HistoryRequest, load_pipeline, parse_pipeline  # noqa: E402

__all__ += ["HistoryRequest", "PipelineError", "SelectionError", "case_number", "load_pipeline",
            "parse_pipeline", "rerun_case", "run_case", "run_pipeline", "select_cases",
            "write_histories"]
