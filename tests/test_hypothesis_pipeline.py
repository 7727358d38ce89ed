"""Property test of pipeline-file values (issue #23, "keep it found").

Hypothesis changes one to three values of a valid pipeline (any key of the schema, or an
unknown one) to numbers (huge, tiny, negative, NaN, infinite), strings, booleans, lists or
tables, writes the file and loads it. Loading either gives a pipeline whose values lie within
the documented limits, or raises a :class:`~shipblock.fragility.pipeline.PipelineError` that
names the file and a key of a section that was changed: never another exception type or a hang.
"""

from __future__ import annotations

import json
import math
import time
import tomllib

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from shipblock.fragility.design import IM_LEVEL_RANGE, SWEEP_PARAMETERS
from shipblock.fragility.pipeline import (
    MAX_BOOTSTRAP,
    MAX_CHUNK_SIZE,
    MAX_RUNS,
    MAX_SEED,
    PipelineError,
    load_pipeline,
)

from .test_pipeline import write_pipeline

# every key of the schema, and a few that are not
KEYS = {
    "": ["output", "title", "schema_version", "colour"],
    "records": ["ids", "azimuth", "horizontal", "response", "catalogue", "station"],
    "system": ["ship_mass", "block_mass", "n_blocks", "half_width", "half_height",
               "mu_s_ground", "mu_k_ground", "mu_s_ship", "mu_k_ship", "restitution",
               "impact_rule", "block_inertia", "g", "slenderness", "mass_ratio", "mass"],
    "sweep": [*SWEEP_PARAMETERS, "friction"],
    "design": ["type", "measure", "period", "damping", "levels", "levels_g", "units",
               "vertical", "vertical_levels", "vertical_levels_g", "cloud_method", "stripes",
               "level"],
    "fit": ["bootstrap", "confidence", "seed", "ida_method", "seeds"],
    "solver": ["rtol", "atol", "zeno_omega", "tol"],
    "execution": ["chunk_size", "scheduler", "workers"],
    "histories": ["runs", "exceeding", "max_runs", "directory"],
}
#: A change in one section may surface as an error of another that depends on it.
DEPENDS = {"design": {"limit_states", "sweep"}, "records": {"design"}, "sweep": {"design"},
           "system": {"sweep"}}

NUMBERS = st.one_of(
    st.integers(-3, 3), st.integers(-(2**70), 2**70), st.floats(allow_nan=True),
    st.sampled_from([0.0, 1e300, -1e300, 1e-300, 5e-324, math.nan, math.inf, -math.inf, 1e6,
                     1e12, 0.5, 2.0, 150.0, 0.2, 0.8]),
)
TEXT = st.one_of(
    st.sampled_from(["", "all", "ida", "msa", "cloud", "pga", "pgv", "sa", "g", "m/s^2", "m/s",
                     "H1", "H2", "same", "independent", "mle", "moments", "probit", "momentum",
                     "tcp://127.0.0.1:1", "out/", "x.nc", "syn/S0", "records", "..", "/"]),
    st.text(st.characters(blacklist_categories=("Cs", "Cc")), max_size=12),
)
SCALARS = st.one_of(NUMBERS, TEXT, st.booleans())
VALUES = st.one_of(
    SCALARS,
    st.lists(NUMBERS, max_size=4),
    st.lists(TEXT, max_size=3),
    st.lists(st.lists(TEXT, max_size=2), max_size=2),
    st.dictionaries(st.sampled_from(["record", "im_level_g", "mu_ground", "x"]), SCALARS,
                    max_size=2),
    st.lists(st.dictionaries(st.sampled_from(["record", "im_level_g", "im_level"]), SCALARS,
                             max_size=2), max_size=2),
)


def _levels(low, high):
    return st.lists(st.floats(low, high), min_size=1, max_size=5, unique=True).map(sorted)


_IDS = st.sampled_from(["syn/S0", "syn/S1", "syn/S2"])
_FIELD = {
    "ship_mass": st.floats(1e3, 1e8), "block_mass": st.floats(100.0, 5000.0),
    "n_blocks": st.integers(1, 500), "half_width": st.floats(0.1, 1.0),
    "half_height": st.floats(0.2, 1.5), "mu_s_ground": st.floats(0.3, 0.9),
    "mu_k_ground": st.floats(0.0, 0.3), "mu_s_ship": st.floats(0.3, 0.9),
    "mu_k_ship": st.floats(0.0, 0.3), "restitution": st.floats(0.0, 1.0),
    "block_inertia": st.floats(1.0, 300.0), "g": st.floats(9.0, 10.0),
    "slenderness": st.floats(0.2, 1.0), "mass_ratio": st.floats(1e-3, 0.1),
    "mu_ground": st.floats(0.3, 0.9), "mu_ship": st.floats(0.3, 0.9),
}
#: Values a user might well write for each key: with them many changed files are valid.
PLAUSIBLE = {
    "output": st.sampled_from(["out/a.nc", "b.nc", "out/sub/c.nc"]),
    "title": st.text(max_size=10), "schema_version": st.just(1),
    "ids": st.just("all") | st.lists(_IDS, min_size=1, unique=True),
    "azimuth": st.floats(-360.0, 360.0), "horizontal": st.sampled_from(["H1", "H2"]),
    "response": st.just("sensitivity"), "catalogue": st.just("records/catalogue.toml"),
    "impact_rule": st.sampled_from(["momentum", "paper"]),
    **_FIELD,
    "type": st.sampled_from(["ida", "msa", "cloud"]),
    "measure": st.sampled_from(["pga", "pgv", "sa"]), "period": st.floats(0.05, 3.0),
    "damping": st.floats(0.0, 0.2), "levels": _levels(0.1, 50.0),
    "levels_g": _levels(0.01, 2.0), "units": st.sampled_from(["g", "m/s^2", "m/s"]),
    "vertical": st.sampled_from(["same", "independent", "unscaled", "zero"]),
    "vertical_levels": _levels(0.1, 20.0), "vertical_levels_g": _levels(0.01, 1.0),
    "cloud_method": st.sampled_from(["probit", "regression"]),
    "stripes": st.lists(st.lists(_IDS, min_size=1, max_size=2, unique=True), min_size=1,
                        max_size=5),
    "bootstrap": st.integers(0, 50), "confidence": st.floats(0.5, 0.99),
    "seed": st.integers(0, 2**63 - 1), "ida_method": st.sampled_from(["mle", "moments"]),
    "rtol": st.floats(1e-10, 1e-4), "atol": st.floats(1e-12, 1e-6),
    "zeno_omega": st.floats(0.0, 1e-3), "chunk_size": st.integers(1, 100),
    "scheduler": st.just("tcp://127.0.0.1:1"), "max_runs": st.integers(1, 10),
    "exceeding": st.just(["ship_slip"]), "directory": st.just("hist"),
    "runs": st.just([{"record": "S0", "im_level_g": 0.4}]),
}


def value_for(section: str, key: str):
    """Mostly a plausible value of the key (a list of them in [sweep]), else anything."""
    good = PLAUSIBLE.get(key, VALUES)
    if section == "sweep":
        good = st.lists(_FIELD.get(key, NUMBERS), min_size=1, max_size=3, unique=True)
    return st.sampled_from([True, True, True, False]).flatmap(
        lambda ok: good if ok else VALUES)


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def to_toml(doc: dict) -> str:
    lines = [f"{k} = {toml_value(v)}" for k, v in doc.items()
             if not isinstance(v, dict) and not (isinstance(v, list) and v
                                                 and all(isinstance(x, dict) for x in v))]
    for k, v in doc.items():
        if isinstance(v, dict):
            lines.append(f"[{k}]")
            lines += [f"{json.dumps(kk)} = {toml_value(vv)}" for kk, vv in v.items()]
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for entry in v:
                lines.append(f"[[{k}]]")
                lines += [f"{json.dumps(kk)} = {toml_value(vv)}" for kk, vv in entry.items()]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hypothesis_pipeline")
    path = write_pipeline(folder)
    doc = tomllib.loads(path.read_text())
    assert tomllib.loads(to_toml(doc)) == doc  # the writer round-trips
    load_pipeline(path)  # and the base is valid
    return folder, doc


@st.composite
def changes(draw):
    out = []
    for _ in range(draw(st.integers(1, 3))):
        section = draw(st.sampled_from(sorted(KEYS)))
        key = draw(st.sampled_from(KEYS[section]))
        out.append((section, key, draw(value_for(section, key))))
    return out


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(edits=changes())
def test_pipeline_values_load_within_limits_or_name_the_key(base, edits):
    folder, doc = base
    doc = json.loads(json.dumps(doc))  # a deep copy
    for section, key, value in edits:
        if section:
            doc.setdefault(section, {})[key] = value
        else:
            doc[key] = value
    path = folder / "mutated.toml"
    try:
        path.write_text(to_toml(doc), encoding="utf-8")
    except UnicodeEncodeError:  # pragma: no cover - the strategies draw no surrogates
        return
    t0 = time.perf_counter()
    try:
        pipe = load_pipeline(path)
    except PipelineError as exc:
        assert time.perf_counter() - t0 < 30, "a hang"
        section = exc.key.split(".")[0].split("[")[0]
        event(f"refused: {section or '<file>'}")
        changed = {s or k for s, k, _ in edits}  # a top-level key is its own section
        allowed = changed | set().union(*(DEPENDS.get(s, set()) for s in changed))
        assert str(path) in str(exc)
        assert section in allowed, f"{exc} (changed: {edits})"
        return
    except Exception as exc:  # noqa: BLE001 - any other type is the failure under test
        pytest.fail(f"{type(exc).__name__}: {exc} (changed: {edits})")
    assert time.perf_counter() - t0 < 30, "a hang"
    event("accepted")
    # accepted: every value within its documented limits
    intensity = pipe.design.intensity
    low, high = IM_LEVEL_RANGE[intensity.measure]
    assert all(low <= x <= high for x in intensity.levels)
    assert 0 <= pipe.fit["bootstrap"] <= MAX_BOOTSTRAP and 0 <= pipe.fit["seed"] <= MAX_SEED
    assert 0 < pipe.fit["confidence"] < 1
    assert 1 <= pipe.chunk_size <= MAX_CHUNK_SIZE and pipe.design.n_cases <= MAX_RUNS
    assert pipe.azimuth is None or -360 <= pipe.azimuth <= 360
    assert all(np.isfinite(v) for v in pipe.solver.values())
    assert not pipe.output.is_dir() and pipe.output.name
    assert np.isfinite(pipe.design.system.to_parameter_vector()).all()
    for system in pipe.design.systems():
        assert np.isfinite(system.to_parameter_vector()).all()
