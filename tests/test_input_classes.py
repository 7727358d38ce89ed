"""Classes of bad input refused by name (issue 33, item 5): control characters in names, deeply
nested TOML, a wrong type where a path or text is expected, an unknown keyword.

Each test is built from the class (every control character, every way TOML nests, every entry
point, every keyword), not from the one input the campaign met.
"""

import sys
import tomllib
import unicodedata

import numpy as np
import obspy
import pytest

import shipblock
from shipblock import ShipBlockSystem, checks, read_motion, read_motions, read_record
from shipblock.errors import (
    ParameterError,
    ParameterTypeError,
    RecordError,
    ShipblockError,
    TomlNestingError,
)
from shipblock.fragility.design import AnalysisDesign, IntensityDesign
from shipblock.fragility.limit_states import LimitState
from shipblock.fragility.pipeline import PipelineError, load_pipeline, rerun_case, run_pipeline
from shipblock.fragility.schema import load_system, parse_pipeline
from shipblock.fragility.store import open_results
from shipblock.io import check_reader_keywords, reader_keywords
from shipblock.processing import STEPS, ProcessingError
from shipblock.records.catalogue import load_catalogue
from shipblock.records.motion import GroundMotion
from shipblock.risk.selection import target_from_file
from shipblock.scaling import read_target_spectrum, scale_motion, scale_record

from .test_pipeline import write_pipeline

# -------------------------------------------------------------------------------------------
# names: printable characters only
# -------------------------------------------------------------------------------------------

#: Every control character (Unicode category Cc: C0, DEL, C1).
CONTROLS = [chr(c) for c in range(sys.maxunicode + 1) if unicodedata.category(chr(c)) == "Cc"]
#: One of each other kind that is not printable: format characters (zero-width space,
#: left-to-right mark, right-to-left override, byte-order mark, soft hyphen), line and
#: paragraph separators, spaces other than ASCII's, private use, unassigned.
OTHERS = ["\u200b", "\u200e", "\u202e", "\ufeff", "\u00ad", "\u2028", "\u2029", "\u00a0",
          "\u3000", "\ue000", "\u0378"]
#: What a pipeline test writes into its names: one from each group of the class.
IN_PIPELINE = ["\x00", "\t", "\n", "\x1b", "\x7f", "\x85", "\u200b", "\u202e", "\u2028",
               "\u00a0"]


def test_the_class_of_control_characters_is_complete():
    assert len(CONTROLS) == 65  # 32 C0, DEL, 32 C1
    assert all(not ch.isprintable() for ch in CONTROLS + OTHERS)


@pytest.mark.parametrize("where", ["start", "middle", "end", "alone"])
def test_label_refuses_every_non_printable_character_anywhere(where):
    for ch in CONTROLS + OTHERS:
        name = {"start": ch + "ls", "middle": "l" + ch + "s", "end": "ls" + ch,
                "alone": ch}[where]
        with pytest.raises(ParameterError) as info:
            checks.label(name, "limit state name")
        message = str(info.value)
        assert message.startswith("limit state name must be")
        if where != "alone" or ch.strip():  # a lone blank is refused as empty first
            assert f"U+{ord(ch):04X} at position {name.index(ch)}" in message


def test_label_keeps_printable_names_of_any_script():
    for name in ("ship_slip", "Gleiten über 5 mm", "滑り", "NP.1765/HN", "a b"):
        assert checks.label(name, "name") == name
    for bad in (None, 3, b"name"):
        with pytest.raises(ParameterTypeError, match="^name must be"):
            checks.label(bad, "name")


def test_limit_state_and_design_names_refuse_control_characters():
    system = ShipBlockSystem.example()
    for ch in CONTROLS + OTHERS:
        with pytest.raises(ParameterError, match="limit state name"):
            LimitState("slip" + ch, "peak_ship_slip", 0.01).validate()
        design = AnalysisDesign(("syn/S0", "syn/S1" + ch), IntensityDesign("cloud"), system)
        with pytest.raises(ParameterError, match=r"records\[1\] must be a record id"):
            design.validate()


def _toml_escape(ch: str) -> str:
    return f"\\u{ord(ch):04x}"


@pytest.mark.parametrize("ch", IN_PIPELINE, ids=[f"U+{ord(c):04X}" for c in IN_PIPELINE])
def test_pipeline_names_with_a_control_character_are_refused_naming_the_key(tmp_path, ch):
    """A name written with a TOML escape (the raw byte is refused as binary already)."""
    path = write_pipeline(tmp_path, ids='["syn/S0", "syn/S1"]')
    text = path.read_text()
    esc = _toml_escape(ch)
    edits = {
        "limit_states[1].name": text.replace('name = "any_failure"',
                                             f'name = "ship_slip{esc}"'),
        "records.ids[1]": text.replace('"syn/S1"]', f'"syn/S1{esc}"]'),
        "output": text.replace('output = "out/result.nc"', f'output = "out/result{esc}.nc"'),
        "histories.directory": text + f'\n[histories]\nexceeding = ["ship_slip"]\n'
                                      f'directory = "hist{esc}"\n',
    }
    for key, edited in edits.items():
        path.write_text(edited)
        with pytest.raises(PipelineError) as info:
            load_pipeline(path)
        assert info.value.key == key
        assert f"U+{ord(ch):04X}" in str(info.value)


def test_a_nul_in_an_input_file_name_or_a_key_is_refused_naming_the_key(tmp_path):
    path = write_pipeline(tmp_path)
    text = path.read_text()
    for edited, key in (
            (text.replace('catalogue = "records/catalogue.toml"',
                          'catalogue = "records/catalogue\\u0000.toml"'), "records.catalogue"),
            (text.replace("[fit]", '[sweep]\n"mu_ship\\u0000" = [0.3]\n[fit]'), "sweep"),
            (text.replace('title = "test"', '"title\\u0007" = "test"'), "")):
        path.write_text(edited)
        with pytest.raises(PipelineError) as info:
            load_pipeline(path)
        assert info.value.key == key


def test_catalogue_ids_with_a_control_character_are_refused_naming_the_id(tmp_path):
    write_pipeline(tmp_path)
    catalogue = tmp_path / "records" / "catalogue.toml"
    text = catalogue.read_text()
    for ch in IN_PIPELINE:
        catalogue.write_text(text.replace('id = "syn/S1"', f'id = "syn/S1{_toml_escape(ch)}"'))
        with pytest.raises(RecordError) as info:
            load_catalogue(catalogue)
        assert "id must be a record id of printable characters" in str(info.value)
        assert info.value.source == str(catalogue)


# -------------------------------------------------------------------------------------------
# TOML nested too deeply
# -------------------------------------------------------------------------------------------

N = checks.MAX_TOML_DEPTH

#: Every way TOML nests, as ``depth -> document``: inline arrays, inline tables, both
#: alternating, dotted keys, a table header, an array-of-tables header under dotted keys.
NESTINGS = {
    "arrays": lambda d: "a = " + "[" * d + "]" * d + "\n",
    "inline tables": lambda d: "a = " + "{b = " * d + "1" + "}" * d + "\n",
    "mixed": lambda d: "a = " + "[{b = " * (d // 2) + ("[]" if d % 2 else "1")
                       + "}]" * (d // 2) + "\n",
    "dotted keys": lambda d: ".".join(["k"] * (d + 1)) + " = 1\n",
    "table header": lambda d: "[" + ".".join(["t"] * d) + "]\nx = 1\n",
    "array of tables": lambda d: "[[" + ".".join(["t"] * (d - 1)) + "]]\nx = 1\n",
}


@pytest.mark.parametrize("kind", NESTINGS)
def test_nesting_up_to_the_limit_is_read_and_beyond_it_is_refused(kind):
    build = NESTINGS[kind]
    assert checks.toml_document(build(N)) == tomllib.loads(build(N))
    for depth in (N + 1, 2 * N, 5_000):
        with pytest.raises(TomlNestingError, match=f"nested deeper than {N} levels"):
            checks.toml_document("title = 'x'\n" + build(depth))


@pytest.mark.parametrize("quote", ['"', "'", '"""', "'''"])
def test_brackets_in_strings_and_comments_do_not_count(quote):
    brackets = "[{" * 5_000
    text = (f"a = {quote}{brackets}{quote}  # {brackets}\n# {brackets}\n"
            f'b = "escaped \\" [[[" \nc = """x\\""""\n')
    assert checks.toml_document(text) == tomllib.loads(text)


def test_every_toml_reader_names_the_file_for_deep_nesting(tmp_path):
    deep = tmp_path / "deep.toml"
    deep.write_text("schema_version = 1\n" + NESTINGS["arrays"](1_000))
    expected = f"{deep}: is nested deeper than {N} levels"
    readers = [(load_pipeline, PipelineError), (load_catalogue, RecordError),
               (ShipBlockSystem.from_toml, ParameterError),
               (lambda p: parse_pipeline(p.read_text(), source=str(p)), PipelineError)]
    for read, error in readers:
        with pytest.raises(error) as info:
            read(deep)
        assert str(info.value).startswith(expected)


#: A file no TOML reader can read, by what is wrong with it: (name, bytes or None for no file,
#: what the message says).
BAD_FILES = {
    "missing": ("missing.toml", None, "not found"),
    "not UTF-8": ("latin1.toml", "title = 'Ume\xe5'\n".encode("latin-1"),
                  "not UTF-8 text (byte 0xe5 at offset 12)"),
    "binary": ("nul.toml", b"schema_version = 1\x00\x01", "binary data (a NUL byte at offset 18)"),
    "not TOML": ("broken.toml", b"[[record]\n", "is not valid TOML"),
}


@pytest.mark.parametrize("bad", BAD_FILES)
def test_every_toml_file_reader_names_the_file_once_in_its_own_error(tmp_path, bad):
    """Pipelines, catalogues and system files are read by one reader
    (:func:`shipblock.checks.toml_text`): the same checks and messages, each reader's own error
    type, the file named once at the start (a system file read for 'simulate --system' named
    it twice, a catalogue's undecodable bytes were 'not valid TOML')."""
    name, data, says = BAD_FILES[bad]
    path = tmp_path / name
    if data is not None:
        path.write_bytes(data)
    readers = [(load_pipeline, PipelineError), (load_catalogue, RecordError),
               (ShipBlockSystem.from_toml, ParameterError), (load_system, PipelineError)]
    for read, error in readers:
        with pytest.raises(error) as info:
            read(path)
        message = str(info.value)
        assert message.startswith(f"{path}: "), message
        assert message.count(str(path)) == 1, message
        assert says in message, message


# -------------------------------------------------------------------------------------------
# a wrong type where a path or text is expected
# -------------------------------------------------------------------------------------------

#: Public entry points taking a path or a text, and the argument named when it is wrong.
ENTRY_POINTS = {
    "parse_pipeline": (parse_pipeline, "text"),
    "parse_pipeline base": (lambda v: parse_pipeline("x = 1", base=v), "base"),
    "parse_pipeline source": (lambda v: parse_pipeline("x = 1", source=v), "source"),
    "load_pipeline": (load_pipeline, "path"),
    "run_pipeline": (run_pipeline, "path"),
    "rerun_case": (lambda v: rerun_case(v, "syn/S0"), "path"),
    "load_catalogue": (load_catalogue, "path"),
    "read_motion": (read_motion, "paths_or_stream"),
    "read_motions": (read_motions, "source"),
    "read_record": (read_record, "path"),
    "ShipBlockSystem.from_toml": (ShipBlockSystem.from_toml, "path"),
    "read_target_spectrum": (lambda v: read_target_spectrum(v, "g"), "path"),
    "target_from_file": (target_from_file, "target"),
    "open_results": (open_results, "path"),
}


WRONG = {"None": None, "int": 3, "float": 2.5, "bytes": b"p.toml", "bool": True,
         "dict": {"a": 1}}


@pytest.mark.parametrize(("entry", "wrong"), [
    (entry, wrong) for entry in ENTRY_POINTS for wrong in WRONG
    if (entry, wrong) != ("load_catalogue", "None")])  # None: the shipped catalogue
def test_a_wrong_type_for_a_path_or_text_names_the_argument(entry, wrong):
    call, argument = ENTRY_POINTS[entry]
    value = WRONG[wrong]
    with pytest.raises(ParameterTypeError) as info:
        call(value)
    assert str(info.value).startswith(f"{argument} must be")
    assert isinstance(info.value, TypeError) and isinstance(info.value, ShipblockError)


# -------------------------------------------------------------------------------------------
# unknown keywords
# -------------------------------------------------------------------------------------------


def _misspellings(names):
    """Each keyword with its last letter dropped, and with two letters swapped."""
    for name in names:
        if len(name) >= 4:
            yield name, name[:-1]
            yield name, name[0] + name[2] + name[1] + name[3:]


def _motion() -> GroundMotion:
    t = np.arange(0.0, 10.0, 0.01)
    h = 0.5 * np.sin(2 * np.pi * t)
    return GroundMotion.from_arrays(h, 0.2 * h, 0.01)


#: Functions taking keywords they pass on: (call with keywords, its keywords, error type).
KEYWORD_FUNCTIONS = {
    "read_motion": (lambda kw: read_motion("no-such-record.mseed", **kw),
                    checks.keyword_names(read_motion, 1)),
    "read_record": (lambda kw: read_record("no-such-record.mseed", **kw),
                    checks.keyword_names(read_record, 1)),
    "read_motions": (lambda kw: read_motions("no-such-folder", **kw),
                     checks.keyword_names(read_motions, 1)),
    "scale_motion": (lambda kw: scale_motion(_motion(), **kw),
                     checks.keyword_names(scale_record, 3)),
}


@pytest.mark.parametrize("function", KEYWORD_FUNCTIONS)
def test_a_misspelt_keyword_is_refused_before_any_work_naming_the_closest(function):
    call, names = KEYWORD_FUNCTIONS[function]
    accepted = set(names) | (reader_keywords() if function.startswith("read") else set())
    tried = 0
    for right, wrong in _misspellings(names):
        if wrong in accepted:
            continue
        with pytest.raises(ParameterTypeError) as info:  # not a RecordError: nothing read
            call({wrong: 1})
        message = str(info.value)
        assert message.startswith(f"{function}() got an unknown keyword argument {wrong!r}")
        assert f"did you mean {right!r}?" in message
        tried += 1
    assert tried >= len(names)


def test_the_campaigns_unit_keyword():
    with pytest.raises(TypeError, match=r"'unit'; did you mean 'units'\?"):
        read_motion("no-such-record.mseed", unit="g")


def test_every_reader_keyword_is_accepted_and_only_those():
    known = reader_keywords()
    assert {"dt", "resample_rate", "resample_interval", "starttime", "headonly"} <= known
    assert {"reclen", "details", "byteorder"} <= known  # MiniSEED's, SAC's: obspy plug-ins
    check_reader_keywords(dict.fromkeys(known, 1), "read_record")
    with pytest.raises(ParameterTypeError, match="'reclens'; did you mean 'reclen'"):
        check_reader_keywords({"reclens": 512}, "read_record")


def test_a_misspelt_processing_parameter_names_the_closest():
    trace = obspy.Trace(np.sin(np.linspace(0.0, 20.0, 4000)))
    trace.stats.delta = 0.005
    stream = obspy.Stream([trace])
    tried = 0
    for name, step in STEPS.items():
        params = checks.keyword_names(step.__wrapped__, 1)
        for right, wrong in _misspellings(params):
            if wrong in params:
                continue
            with pytest.raises(ProcessingError) as info:
                step(stream, **{wrong: 1})
            assert info.value.step == name and info.value.parameter == wrong
            assert f"did you mean {right!r}?" in str(info.value)
            tried += 1
    assert tried > 20


def test_shipblock_exports_stay_importable():
    assert shipblock.read_motion is read_motion
