"""The pipeline keys are declared once: parsing, checks, errors and the docs' table follow.

:mod:`shipblock.fragility.keys` declares every key; these tests check that the declarations
are what the parser applies (ranges, choices, defaults), that errors carry the key as data,
and that the table of keys in the docs (written from the declarations at every build by the
``pipeline-keys`` directive) lists every key the parser accepts.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from shipblock.fragility import keys
from shipblock.fragility.keys import SECTIONS, PipelineError, key_table, section_fields, value
from shipblock.models import Field, FieldError, get_model
from shipblock.scaling import MATCH_MODES
from shipblock.system import FIELD_LIMITS

from .test_pipeline import write_pipeline

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_the_table_lists_every_key_the_parser_accepts():
    table = key_table()
    listed = set(re.findall(r"\* - ``([^`]+)``", table))
    declared = {f"{s}.{k}" if s else k for s in [*SECTIONS, "system", "solver", "sweep"]
                for k in section_fields(s)}
    assert listed == declared
    # and the user guide renders it at build time
    assert ".. pipeline-keys::" in (DOCS / "user_guide" / "fragility.rst").read_text()
    assert "PipelineKeys" in (DOCS / "conf.py").read_text()


def test_declarations_of_the_model_keys_follow_the_model():
    rigid = get_model("rigid")
    system = section_fields("system")
    for name, (low, high, units) in FIELD_LIMITS.items():
        assert (system[name].low, system[name].high) == (low, high)
    assert list(section_fields("solver")) == ["rtol", "atol", "zeno_omega"]
    assert set(section_fields("sweep")) == set(rigid.sweep_parameters)
    assert keys.MATCH_MODES == MATCH_MODES  # written out to keep obspy out of the parser


@pytest.mark.parametrize(
    ("section", "key", "given", "problem"),
    [
        ("fit", "bootstrap", 10_001, "must be an integer in [0, 10000], got 10001"),
        ("fit", "confidence", 1.0, "must be a finite number in (0, 1), got 1.0"),
        ("fit", "confidence", math.nan, "must be a finite number in (0, 1), got nan"),
        ("records", "azimuth", 400.0, "must be a finite number in [-360, 360] [deg], got 400.0"),
        ("design", "measure", "pgd", "must be one of 'pga', 'pgv', 'sa', got 'pgd'"),
        ("design", "max_scale_factor", 0.5, "must be a finite number >= 1, got 0.5"),
        ("execution", "chunk_size", 0, "must be an integer in [1, 1000000], got 0"),
    ],
)
def test_values_are_checked_by_their_declaration_and_name_the_key(section, key, given, problem):
    with pytest.raises(PipelineError) as info:
        value({key: given}, section, key, "p.toml")
    assert info.value.key == f"{section}.{key}" == info.value.field
    assert info.value.problem == problem
    assert str(info.value) == f"p.toml: [{section}.{key}] {problem}"


def test_defaults_come_from_the_declarations(tmp_path):
    from shipblock.fragility.schema import load_pipeline

    text = write_pipeline(tmp_path).read_text()
    path = tmp_path / "defaults.toml"
    path.write_text(text.replace("bootstrap = 20\nseed = 3\n", "").replace(
        'horizontal = "H1"\n', ""))
    pipe = load_pipeline(path)
    fit = SECTIONS["fit"]
    assert pipe.fit["bootstrap"] == fit["bootstrap"].default == 200
    assert pipe.fit["seed"] == fit["seed"].default == 0
    assert pipe.fit["confidence"] == fit["confidence"].default == 0.9
    assert pipe.horizontal == SECTIONS["records"]["horizontal"].default == "H1"
    assert pipe.solver == {k: f.default for k, f in section_fields("solver").items()}


def test_a_field_error_carries_its_field_and_pickles():
    import pickle

    field = Field("n", (int,), "a count", low=1, high=3)
    with pytest.raises(FieldError) as info:
        field.check(True)  # a bool is not an integer
    assert info.value.field == "n" and str(info.value) == "must be an integer, got bool True"
    again = pickle.loads(pickle.dumps(info.value))
    assert (again.field, str(again)) == ("n", str(info.value))
    error = pickle.loads(pickle.dumps(PipelineError("fit.seed", "bad", "p.toml")))
    assert (error.key, str(error)) == ("fit.seed", "p.toml: [fit.seed] bad")
