"""SAC and StationXML header fields fuzzed: only project errors or correct reads (issue 23, item 5).

Every case reads a file whose one header field holds an absurd, a damaged or simply another value
(:func:`tests.reader_fuzz.sac_field_mutations`, :func:`tests.reader_fuzz.stationxml_field_mutations`,
plus a few hypothesis-drawn floats), through :func:`shipblock.records.reading.read_motion`. The test knows
what a correct read of each file is, from the formats' definitions (SAC: samples x SCALE in the
unit of KUSER0 or IDEP, IACC = nm/s^2; time of the first sample = reference time + B; StationXML:
counts / sensitivity in the sensitivity's input unit), and requires either exactly that, or a
:class:`~shipblock.errors.ShipblockError`. A correct read must exist within the plausibility
limits (sampling interval 1e-4..1 s, start 1900-2200, one count = 1e-12..1e3 SI units, samples
under 100 g); outside them, only the error is right. Never a crash, NaN samples or a silent scale.

The SAC file is made here (synthetic 1 Hz sine, peak 0.5, 100 Hz, 2000 samples); the StationXML is
the shipped ``records/south-napa-2014/NP.1737.xml`` (USGS), its first channel (HNZ, 213473.004110264
counts/(M/S**2)) patched.
"""

from __future__ import annotations

import io
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from obspy import Trace, UTCDateTime

from shipblock.errors import ShipblockError
from shipblock.io._common import PolarityReversalWarning
from shipblock.records.reading import read_motion
from tests.reader_fuzz import (
    sac_field_mutations,
    sac_patch,
    stationxml_field_mutations,
    stationxml_patch,
)

NAPA = Path(__file__).parent.parent / "records" / "south-napa-2014"
G = 9.80665  # standard gravity [m/s^2] (exact by definition)
START = UTCDateTime(2020, 1, 1)
SAMPLES = (0.5 * np.sin(2 * np.pi * np.arange(2000) / 100.0)).astype(np.float32)
SENSITIVITY = 213473.004110264  # NP.1737 HNZ, counts/(M/S**2)
#: Exact factors to SI of the unit words used below (SAC manual: IACC is nm/s^2).
UNIT_SI = {"gal": 0.01, "g": G, "cm/s2": 0.01, "nm/s^2": 1e-9, "M/S**2": 1.0, "CM/S**2": 0.01,
           "NM/S**2": 1e-9, "G": G}
PLAUSIBLE = dict(delta=(1e-4, 1.0), count=(1e-12, 1e3), peak=100 * G)
#: Range of start times a record may have (the oldest strong-motion records are of 1933).
EARLIEST, LATEST = UTCDateTime(1900, 1, 1), UTCDateTime(2200, 1, 1)


def _sac_bytes() -> bytes:
    trace = Trace(SAMPLES.copy())
    trace.stats.update({"delta": 0.01, "station": "SYN", "network": "XX", "channel": "HNN",
                        "starttime": START})
    buffer = io.BytesIO()
    trace.write(buffer, format="SAC")
    return buffer.getvalue()


def _read(path, **kwargs):
    """read_motion's result, or the project error (anything else propagates and fails)."""
    try:
        return read_motion(path, **kwargs)
    except ShipblockError as exc:
        return exc


def _expected_sac(field, value):
    """``(dt, start, horizontal [m/s^2], units)`` of a correct read, or ``None`` if none exists."""
    f32 = float(np.float32(value)) if isinstance(value, float) else value
    dt, start, factor, units = 0.01, START, UNIT_SI["gal"], "gal"
    if field == "delta":
        if not (math.isfinite(f32) and PLAUSIBLE["delta"][0] <= f32 <= PLAUSIBLE["delta"][1]):
            return None
        dt = f32
    elif field == "npts" and value != SAMPLES.size:
        return None  # the header no longer matches the data: no correct read
    elif field == "b":
        # The first sample is at the reference time + B; the readers accept starts in 1900-2200
        # (a rule on the resulting time, not on B: B = 1e9 s is a start in 2051).
        seconds = START.timestamp + f32 if math.isfinite(f32) else math.nan
        if not EARLIEST.timestamp <= seconds < LATEST.timestamp:
            return None
        start = START + f32
    elif field == "scale":
        count = f32 * UNIT_SI["gal"]
        if not (math.isfinite(count) and PLAUSIBLE["count"][0] <= abs(count)
                <= PLAUSIBLE["count"][1]):
            return None
        factor = count
    elif field == "idep":
        if value != 8:  # only IACC states an acceleration unit (IVEL needs differentiate=True)
            return None
        factor, units = UNIT_SI["nm/s^2"], None
    elif field == "kuser0":
        if value not in ("g", "cm/s2"):
            return None  # a velocity, a length or no unit: refused (no IDEP unit either)
        factor, units = UNIT_SI[value], None
    data = SAMPLES.astype(np.float64) * factor
    if np.max(np.abs(data)) > PLAUSIBLE["peak"]:
        return None
    return dt, start, data, units


def _check_sac(tmp_path, field, value):
    path = tmp_path / "fuzz.sac"
    path.write_bytes(sac_patch(_sac_bytes(), field, value))
    expected = _expected_sac(field, value)
    units = "gal" if expected is None or expected[3] is not None else None
    if field in ("idep", "kuser0"):
        units = None
    got = _read(path, units=units)
    case = f"SAC {field}={value!r}"
    if expected is None:
        assert isinstance(got, ShipblockError), f"{case}: read, but no correct read exists"
        assert "fuzz.sac" in str(got), f"{case}: the error does not name the file: {got}"
        return
    assert not isinstance(got, ShipblockError), f"{case}: refused a correct file: {got}"
    dt, start, data, _ = expected
    assert got.dt == pytest.approx(dt, rel=1e-6), case
    assert abs(got.starttime - start) < 1e-3, case
    np.testing.assert_allclose(got.horizontal, data, rtol=1e-6, atol=0, err_msg=case)


@pytest.mark.parametrize(("field", "value"), list(sac_field_mutations()))
def test_sac_header_field(tmp_path, field, value):
    _check_sac(tmp_path, field, value)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(field=st.sampled_from(["delta", "scale", "b"]),
       value=st.floats(allow_nan=True, allow_infinity=True, width=32))
@example(field="b", value=1e9)  # a start in 2051: read (the old rule |B| < 1e9 refused it)
@example(field="b", value=5.7e9)  # a start after 2200: refused
@example(field="b", value=-3.8e9)  # a start before 1900: refused
def test_sac_header_float_drawn(tmp_path, field, value):
    _check_sac(tmp_path, field, value)


# ------------------------------------------------------------------------------- StationXML


@pytest.fixture(scope="module")
def napa_reference():
    gm = read_motion(NAPA / "NP.1737.mseed", inventory=NAPA / "NP.1737.xml")
    return gm.components


def _expected_vertical(element, value, reference):
    """The vertical of a correct read with the patched field, or ``None`` if none exists."""
    if element in ("Frequency", "SampleRate"):
        return reference["V"]  # not used by the sensitivity path: the read must not change
    sensitivity, unit = SENSITIVITY, "M/S**2"
    if element == "Value":
        try:
            sensitivity = float(value)
        except ValueError:
            return None
    else:
        unit = value
        if unit not in UNIT_SI:
            return None  # not an acceleration (a velocity needs differentiate=True)
    if sensitivity < 0:
        return None  # NP.1737's stage gains are positive: a negative overall value is damaged
    count = UNIT_SI[unit] / sensitivity if sensitivity else math.inf
    if not (math.isfinite(count) and PLAUSIBLE["count"][0] <= abs(count) <= PLAUSIBLE["count"][1]):
        return None
    vertical = reference["V"] * (count * SENSITIVITY)  # counts x new value of one count
    return None if np.max(np.abs(vertical)) > PLAUSIBLE["peak"] else vertical


def _check_xml(tmp_path, element, value, reference):
    path = tmp_path / "NP.1737.xml"
    path.write_text(stationxml_patch((NAPA / "NP.1737.xml").read_text(), element, value))
    got = _read(NAPA / "NP.1737.mseed", inventory=path)
    expected = _expected_vertical(element, value, reference)
    case = f"StationXML {element}={value!r}"
    if expected is None:
        assert isinstance(got, ShipblockError), f"{case}: read, but no correct read exists"
        assert "NP.1737" in str(got), f"{case}: the error does not name the file: {got}"
        return
    if isinstance(got, ShipblockError):
        # A field the sensitivity path does not use may still be one the XML parser refuses.
        assert element in ("Frequency", "SampleRate") and "NP.1737.xml" in str(got), (case, got)
        return
    np.testing.assert_allclose(got.components["V"], expected, rtol=1e-12, err_msg=case)
    for component in ("H1", "H2"):
        np.testing.assert_array_equal(got.components[component], reference[component])


@pytest.mark.parametrize(("element", "value"),
                         [*stationxml_field_mutations(), ("Value", f"{-SENSITIVITY!r}")])
def test_stationxml_field(tmp_path, napa_reference, element, value):
    _check_xml(tmp_path, element, value, napa_reference)


def _first_channel_xml(text: str, flip_stage: bool = False, drop_stages: bool = False) -> str:
    """NP.1737.xml with its first channel's overall sensitivity negated, and optionally its first
    stage gain negated too (a documented reversed channel) or its stages removed."""
    text = stationxml_patch(text, "Value", f"{-SENSITIVITY!r}")
    head, sep, rest = text.partition("</Channel>")  # the first channel only
    if flip_stage:
        head = re.sub(r"(<StageGain>\s*<Value>)([^<]*)", lambda m: m.group(1) + f"-{m.group(2)}",
                      head, count=1)
    if drop_stages:
        head = re.sub(r"<Stage number=.*?</Stage>\s*", "", head, flags=re.DOTALL)
    return head + sep + rest


def test_negative_sensitivity_against_stage_gains(tmp_path, napa_reference):
    """A negative overall sensitivity is a reversed channel only if the stage gains say so too:
    with positive stage gains it is a damaged sign, refused."""
    path = tmp_path / "NP.1737.xml"
    original = (NAPA / "NP.1737.xml").read_text()
    path.write_text(_first_channel_xml(original))
    got = _read(NAPA / "NP.1737.mseed", inventory=path)
    assert isinstance(got, ShipblockError) and "stage gains" in str(got), got
    path.write_text(_first_channel_xml(original, flip_stage=True))  # as BK.VALB documents it
    gm = read_motion(NAPA / "NP.1737.mseed", inventory=path)
    np.testing.assert_allclose(gm.components["V"], -napa_reference["V"], rtol=1e-12)
    assert "polarity is reversed" in gm.metadata["units"]["V"]


def test_negative_sensitivity_without_stages_is_said_and_refusable(tmp_path, napa_reference):
    """No stage gains to confirm a negative sensitivity: read as reversed with a loud
    PolarityReversalWarning, which a user turns into an error to refuse the record."""
    path = tmp_path / "NP.1737.xml"
    path.write_text(_first_channel_xml((NAPA / "NP.1737.xml").read_text(), drop_stages=True))
    with pytest.warns(PolarityReversalWarning, match="no stage gain confirms it"):
        gm = read_motion(NAPA / "NP.1737.mseed", inventory=path)
    np.testing.assert_allclose(gm.components["V"], -napa_reference["V"], rtol=1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PolarityReversalWarning)
        with pytest.raises(ShipblockError, match="NP.1737.xml.*negative"):
            read_motion(NAPA / "NP.1737.mseed", inventory=path)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(value=st.floats(allow_nan=True, allow_infinity=True))
def test_stationxml_sensitivity_drawn(tmp_path, napa_reference, value):
    _check_xml(tmp_path, "Value", repr(value), napa_reference)


# ------------------------------------------------------------- obspy's formats through read_record


@pytest.mark.parametrize("kind", ["knet", "sac", "mseed"])
def test_obspy_formats_survive_mutations_through_read_record(tmp_path, kind):
    """Mutated K-NET (obspy's test file), SAC (made above) and MiniSEED (NP.1737) files, read by
    :func:`shipblock.io.read_record`: a project error, or finite samples at 1e-4..1 s. A K-NET
    sample replaced by 1e999 was read as inf counts before."""
    import obspy

    from shipblock.io import read_record
    from tests.reader_fuzz import assert_reader_survives

    raw = {
        "knet": lambda: (Path(obspy.__file__).parent / "io" / "nied" / "tests" / "data"
                         / "test.knet").read_bytes(),
        "sac": _sac_bytes,
        "mseed": lambda: (NAPA / "NP.1737.mseed").read_bytes(),
    }[kind]()
    path = tmp_path / f"fuzz.{kind}"

    def read(fileobj):
        path.write_bytes(fileobj.read())
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return read_record(path)

    assert assert_reader_survives(read, raw, seed=23, count=40) > 0
