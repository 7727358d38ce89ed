"""Reader for PEER NGA ``.AT2`` acceleration files (obspy waveform plug-in ``SHIPBLOCK_AT2``).

Layout, from the PEER Strong Motion Database documentation [1]_ and the NGA-West2 files: four
header lines, then the samples read horizontally line by line (usually 5 per line, ``E15.7``):

1. title, e.g. ``PEER NGA STRONG MOTION DATABASE RECORD``;
2. earthquake name, date, station and component, comma separated, e.g.
   ``Helena Montana-01, 10/31/1935, Carroll College, 180``;
3. quantity and units, e.g. ``ACCELERATION TIME SERIES IN UNITS OF G``;
4. ``NPTS=  4000, DT=   .0100 SEC`` (NGA) or ``4000   0.0100   NPTS, DT`` (older PEER files).

The samples are in g (the format's unit; the header says so) unless line 3 names another unit after
``UNITS OF`` or alone in parentheses (``(CM/S2)``): ``MG``/``MILLI-G`` (milli-g), ``G/100`` and
``%G`` (hundredths of g), ``CM/S2``/``GAL``, ``MM/S2``, ``M/S2``, ``KM/S2``, ``IN/S2``, ``FT/S^2``
(any spelling of s^2: ``S2``, ``S**2``, ``SEC/SEC``). They are converted to m/s^2 (g =
:data:`shipblock.units.STANDARD_GRAVITY`); ``stats.units`` is ``"m/s**2"`` and
``stats.original_units`` the unit. A word that is not an acceleration unit is refused: a velocity
(``CM/S``) or length (``CM``: displacement) as such, any other word as unknown (also in
parentheses: ``(FOO)`` is refused, not read as g; a processing word such as ``(ROTATED)`` is no
unit statement); velocity and displacement files (PEER ``.VT2``, ``.DT2``) are refused. DT must lie
within 1e-4..1 s (``DT= 1,5``, a decimal comma, is refused, not read as 1 s) and the samples under
100 g. Values written in a fixed format (``E15.7``: 99 % of them alike) must all be: a last
value cut short (``-.1234567E-0``, 100 times too large) is refused. The component token of line 2
gives the orientation: a number is the azimuth [deg clockwise from north];
``UP``/``V``/``VER``/``Z`` is vertical positive up and ``DWN``/``DOWN`` vertical positive down. The
file holds no start time, so traces start at the epoch (1970-01-01T00:00:00Z).

Line 2 names the station in words and no network or location, so the trace's SEED-like id
``NET.STA.LOC.CHA`` is made as follows (``Loma Prieta, 10/18/1989, Corralitos, 0`` gives
``.CORRALITOS..HNN``):

* network and location: empty (PEER states none; obspy's default);
* station: the station name in upper case (as SEED codes are written, and so that files that
  write it in different cases are one station) with each run of characters other than letters,
  digits and ``_`` made one ``-`` (``Anaheim - Lakeview & Riverdale`` ->
  ``ANAHEIM-LAKEVIEW-RIVERDALE``): no ``.`` to break the id, no space, and two stations stay
  two. The name as written is ``stats.shipblock_at2.station_name``;
* channel: the orientation code every shipblock reader gives an accelerometer component (band
  letter by rate, ``N``, then ``Z`` vertical, ``N``/``E`` for a horizontal along north/east, else
  ``1``/``2`` by the nearer axis): ``000`` and ``360`` -> ``HNN``, ``090`` -> ``HNE``, ``180`` ->
  ``HN1``, ``270`` -> ``HN2``, ``UP`` and ``DWN`` -> ``HNZ`` (``stats.dip`` -90 or 90 tells the
  polarity). ``stats.azimuth`` keeps the azimuth and ``stats.file_component`` the word as the
  file writes it (``"0"``, ``"DWN"``), which a ``channel_map`` may also name. A word that states
  no orientation (``FN``) is kept as the channel, its component left to a ``channel_map``;
* ``stats.seed_channel`` is ``False``: the code is the reader's, not an agency's, and names no
  sensor, so the files of one station are one record, and the H1/H2 order of two horizontals
  follows their azimuths (rule 3 of :data:`shipblock.records.sensors.HORIZONTAL_RULE`: PEER
  ``000``/``090`` -> ``000``, ``045``/``315`` -> ``315``), not their codes' digits.

Earlier the id held the raw words (``.Corralitos..0``: the station name as the code, the
component word as the channel).

References
----------
.. [1] PEER Strong Motion Database, "Sample data files",
   http://peer.berkeley.edu/smcat/data.html (accessed 2024).
"""

from __future__ import annotations

import re
from collections import Counter

from obspy import Stream
from obspy.core import AttribDict

from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
    FLOAT_RE,
    check_plausible_samples,
    check_samples,
    check_sampling_interval,
    code_from_name,
    horizontal_index,
    make_trace,
    orientation_stats,
    parse_float,
    peek_text,
    read_text,
    source_name,
)
from shipblock.units import (
    ACCELERATION_UNITS_TO_SI,
    INCH,
    STANDARD_GRAVITY,
    canonical_unit,
    canonical_velocity_unit,
)

__all__ = ["FORMAT", "is_at2", "read_at2"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_AT2"

#: Titles that mark a PEER file (line 1), compared in upper case.
_TITLES = ("PEER", "PACIFIC ENGINEERING", "PAIFIC ENGINEERING", "NGA")

#: How many lines the NPTS/DT line may be from the top (7 for spectrally matched NRC files).
_MAX_HEADER_LINES = 8

_NPTS_DT_NGA = re.compile(
    r"NPTS\s*=\s*(\d+)\s*[,;]?\s*DT\s*=\s*([-+]?[\d.]*(?:,\d+)?(?:[EeDd][-+]?\d+)?)",
    re.IGNORECASE,
)
_NPTS_DT_OLD = re.compile(
    r"^\s*(\d+)\s+(" + FLOAT_RE.pattern + r")\s+NPTS\s*,\s*DT", re.IGNORECASE
)
_UNITS_RE = re.compile(r"UNITS\s+OF\s+([A-Z/*^0-9'%]+)", re.IGNORECASE)
#: Share of the values that must be written alike for a file to count as fixed-format.
FIXED_FORMAT_SHARE = 0.99

_SHAPE_RE = re.compile(r"[-+]?\d*(?:\.(\d*))?(?:[EeDd][-+]?(\d*))?")
_PAREN_RE = re.compile(r"\(([^()]*)\)")
#: A word in parentheses that describes the processing (``(ROTATED)``, ``(FILTERED)``): a past
#: participle, not a unit.
_PARTICIPLE_RE = re.compile(r"^[A-Z]+ED$", re.IGNORECASE)

#: One foot [m] (international foot, 1959).
FOOT = 0.3048

#: Acceleration units the AT2 reader knows beyond :func:`shipblock.units.canonical_unit`
#: (normalised spelling, see :func:`_normalise`) -> factor to m/s^2. ``km/s^2`` is a real unit
#: (1000 m/s^2) and is converted; the 100 g plausibility check catches a file whose numbers are
#: not what the header says.
_EXTRA_ACCELERATION = {
    "ft/s^2": FOOT,
    "in/s^2": INCH,
    "km/s^2": 1000.0,
    "%g": 0.01 * STANDARD_GRAVITY,
    "g%": 0.01 * STANDARD_GRAVITY,
    "milli-g": 1e-3 * STANDARD_GRAVITY,
    "millig": 1e-3 * STANDARD_GRAVITY,
    "micro-g": 1e-6 * STANDARD_GRAVITY,
}

#: Velocity and displacement units (normalised): an AT2 header naming one does not hold an
#: acceleration.
_VELOCITY = {"m/s", "cm/s", "mm/s", "km/s", "in/s", "ft/s", "nm/s"}
_DISPLACEMENT = {"m", "cm", "mm", "km", "in", "ft", "nm"}
_VERTICAL_UP = {"UP", "V", "VER", "VERT", "Z", "HNZ", "HLZ", "HHZ", "HGZ"}
_VERTICAL_DOWN = {"DWN", "DOWN", "DN"}


def _shape(token: str) -> tuple[int, int | None]:
    """``(digits after the point, exponent digits or None)`` of a number as written."""
    match = _SHAPE_RE.fullmatch(token)
    if match is None:
        return -1, None
    decimals, exponent = match.group(1), match.group(2)
    return len(decimals or ""), (None if exponent is None else len(exponent))


def _check_written_alike(tokens, name: str) -> None:
    """Refuse a value written shorter than the file's fixed format (a value cut short).

    When at least :data:`FIXED_FORMAT_SHARE` of the values are written with the same digits
    (``E15.7``: seven decimals, a two-digit exponent), the file is in that fixed format and every
    value must be; a value with other digits was cut (``-.1234567E-0`` reads 10 or 100 times too
    large) or damaged. Files in free format (digits varying) are not checked.
    """
    if len(tokens) < 10:
        return
    shapes = [_shape(token) for token, _ in tokens]
    shape, count = Counter(shapes).most_common(1)[0]
    if count == len(shapes) or count < FIXED_FORMAT_SHARE * len(shapes):
        return
    index = next(k for k, other in enumerate(shapes) if other != shape)
    token, lineno = tokens[index]
    exponent = "" if shape[1] is None else f", a {shape[1]}-digit exponent"
    raise RecordError(
        name, f"line {lineno}: value {token!r} is not written like the other {count} ({shape[0]}"
        f" decimals{exponent}): a value cut short (truncated file?) or a damaged digit")


def _npts_dt(line: str):
    """Return ``(npts, dt as written)`` from a header line, or ``None``."""
    match = _NPTS_DT_NGA.search(line) or _NPTS_DT_OLD.search(line)
    if match is None or not any(c.isdigit() for c in match.group(2)):
        return None
    return int(match.group(1)), match.group(2)


def _find_header(lines):
    """Return the index of the NPTS/DT line and its values, or ``None``."""
    if not lines or not any(t in lines[0].upper() for t in _TITLES):
        return None
    for index, line in enumerate(lines[1:_MAX_HEADER_LINES], start=1):
        try:
            found = _npts_dt(line)
        except ValueError:
            return None
        if found is not None:
            return index, found
    return None


def is_at2(filename) -> bool:
    """Tell whether a file is a PEER AT2 acceleration file (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if line 1 is a PEER title and an ``NPTS``/``DT`` line follows within the header.
    """
    text = peek_text(filename)
    if text is None:
        return False
    try:
        return _find_header(text.splitlines()[:_MAX_HEADER_LINES]) is not None
    except Exception:  # noqa: BLE001 - detection must never raise
        return False


def _orientation(component: str, sampling_rate: float) -> dict:
    """Map the component token of header line 2 to ``channel``, ``azimuth``/``dip`` [deg].

    A known orientation gets the SEED-like code of every shipblock reader
    (:func:`~shipblock.io._common.orientation_stats`: ``HNZ``, ``HNN``, ``HNE``, ``HN1``/``HN2``,
    band letter by rate); an unknown token is kept as the channel (letters, digits, ``-``), its
    orientation left unset (a ``channel_map`` names its component).
    """
    token = component.strip().upper()
    if token in _VERTICAL_UP or token.endswith("-UP"):
        return orientation_stats(sampling_rate, vertical=True, positive_up=True)
    if token in _VERTICAL_DOWN or token.endswith("-DWN"):
        return orientation_stats(sampling_rate, vertical=True, positive_up=False)
    azimuth = None
    digits = re.search(r"(\d{1,3})$", token)
    if digits is not None and 0 <= int(digits.group(1)) <= 360:
        azimuth = float(int(digits.group(1)) % 360)
    elif len(token) == 3 and token[2] in "NE":
        azimuth = 0.0 if token[2] == "N" else 90.0
    if azimuth is None:
        return {"channel": code_from_name(component)}
    return orientation_stats(sampling_rate, vertical=False, azimuth_deg=azimuth,
                             index=horizontal_index(azimuth))


def _normalise(word: str) -> str:
    """Lower-case a unit word and spell powers and seconds one way (``CM/SEC/SEC`` -> ``cm/s^2``)."""
    key = word.strip().lower().replace(" ", "").replace("**", "^").replace("sec", "s")
    key = re.sub(r"/s/s$", "/s^2", key)
    return re.sub(r"/s2$", "/s^2", key)


def _unit_factor(word: str) -> tuple[str, float] | None:
    """``(unit, factor to m/s^2)`` of an acceleration unit word, or ``None`` if it is not one."""
    key = canonical_unit(word)
    if key is not None:
        return key, ACCELERATION_UNITS_TO_SI[key]
    norm = _normalise(word)
    if norm in _EXTRA_ACCELERATION:
        return norm, _EXTRA_ACCELERATION[norm]
    fraction = re.fullmatch(r"g/(\d+)", norm)
    if fraction and int(fraction.group(1)) > 0:
        return norm, STANDARD_GRAVITY / int(fraction.group(1))
    key = canonical_unit(norm)
    if key is not None:
        return key, ACCELERATION_UNITS_TO_SI[key]
    return None


def _units(line: str, name: str) -> tuple[str, float, bool]:
    """Return the unit of the samples, its factor to m/s^2, and whether the header stated it.

    The unit is the word after ``UNITS OF`` (or a unit word in parentheses). A header that names
    no unit means g (the format's unit); a word that is not an acceleration unit is refused.
    """
    upper = line.upper()
    if "VELOCITY" in upper or "DISPLACEMENT" in upper:
        raise UnitsError(name, f"holds {line.strip()!r}, not an acceleration time series (read the"
                               " record's .AT2 acceleration file)")
    stated = _UNITS_RE.search(line)
    if stated is not None:
        word = stated.group(1).rstrip("'")
    else:
        # A one-word group in parentheses is the unit slot (``(CM/S2)``), unless it is a
        # processing word (``(ROTATED)``); phrases (``(HP=0.1 HZ, LP=25 HZ)``) are notes.
        words = [m.group(1).strip() for m in _PAREN_RE.finditer(line)]
        words = [w for w in words if w and len(w.split()) == 1 and not _PARTICIPLE_RE.match(w)]
        word = next((w for w in words if _unit_factor(w) is not None), words[0] if words else None)
        if word is None:
            # The AT2 format is defined in g; a header that does not repeat it still means g.
            return "g", STANDARD_GRAVITY, False
    found = _unit_factor(word) or _unit_factor(word.rstrip("Ss"))  # G'S, GS
    if found is not None:
        return found[0], found[1], True
    norm = _normalise(word)
    if norm in _VELOCITY or canonical_velocity_unit(word) is not None:
        raise UnitsError(name, f"header line {line.strip()!r} gives the unit {word!r}, a velocity:"
                               " not an acceleration")
    if norm in _DISPLACEMENT:
        raise UnitsError(name, f"header line {line.strip()!r} gives the unit {word!r}, a length"
                               " (displacement): not an acceleration")
    raise UnitsError(
        name, f"unknown acceleration unit {word!r} in header line {line.strip()!r}; known: g, mg"
        " (milli-g), g/N, %g, cm/s^2 (gal), mm/s^2, m/s^2, km/s^2, in/s^2, ft/s^2 (any spelling of s^2:"
        " s2, s**2, sec/sec)",
    )


def read_at2(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read a PEER AT2 acceleration file into a Stream of one trace in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The AT2 file.
    headonly : bool, optional
        Read only the header; the trace then has no samples.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace; ``stats.units == "m/s**2"``, ``stats.original_units`` the header unit,
        station and channel codes made from the header (see the module's notes: e.g.
        ``.CORRALITOS..HNN``), ``stats.file_component`` the component word as written,
        ``stats.azimuth``/``stats.dip`` [deg] where the component token tells them, and the
        original header in ``stats.shipblock_at2``.

    Raises
    ------
    RecordError
        If the file is not a valid AT2 file, is truncated, or holds NaN/inf samples.
    UnitsError
        If the file holds velocity or displacement, or an unknown unit.
    """
    name = source_name(filename)
    text = read_text(filename)
    lines = text.splitlines()
    try:
        found = _find_header(lines[:_MAX_HEADER_LINES])
    except ValueError:
        found = None
    if found is None:
        raise RecordError(name, "is not a PEER AT2 file (no PEER title and NPTS/DT header line)")
    npts_line, (npts, dt_text) = found
    if "," in dt_text:
        raise RecordError(name, f"header line {npts_line + 1}: DT {dt_text!r} is written with a"
                                " decimal comma; write it with a point (DT= 0.005)")
    try:
        dt = parse_float(dt_text)
    except ValueError:
        raise RecordError(name, f"header line {npts_line + 1}: DT {dt_text!r} is not a"
                                " number") from None
    delta = check_sampling_interval(dt, name, "DT")
    header_lines = lines[: npts_line + 1]
    description = header_lines[1] if npts_line >= 2 else ""
    units_line = header_lines[npts_line - 1] if npts_line >= 2 else ""
    unit, factor, stated = _units(units_line, name)

    tokens = [t.strip() for t in description.split(",")]
    component = tokens[-1] if len(tokens) >= 2 else ""
    station = tokens[-2] if len(tokens) >= 3 else ""
    header = AttribDict(
        {
            "header_lines": header_lines,
            "event": tokens[0] if len(tokens) >= 2 else description.strip(),
            "station_name": station,
            "component": component,
            "npts": npts,
            "dt": dt,
            "units": unit,
            "units_stated_in_header": stated,
        }
    )
    stats = {
        # PEER states no network, station code or location: the station is the name of line 2
        # made an upper-case code (no dots or spaces: "Mt. Wilson" is no NET.STA split), the
        # channel is made from the component word, which is kept in file_component.
        "network": "",
        "station": code_from_name(station).upper(),
        "location": "",
        "file_component": component,
        # The channel code is the reader's, not the agency's: it names no sensor, so the three
        # files of a station stay one record whatever their rates.
        "seed_channel": False,
        "units": "m/s**2",
        "original_units": unit,
        "shipblock_at2": header,
        **_orientation(component, 1.0 / delta),
    }
    if headonly:
        trace = make_trace([], delta, stats)
        trace.stats.npts = npts
        return Stream([trace])

    samples, tokens = [], []
    for lineno, line in enumerate(lines[npts_line + 1 :], start=npts_line + 2):
        values = FLOAT_RE.findall(line)
        rest = FLOAT_RE.sub(" ", line).replace(",", " ").strip()
        if rest:
            raise RecordError(name, f"line {lineno}: {rest[:20]!r} is not a number (corrupt data)")
        try:
            samples.extend(parse_float(v) for v in values)
        except ValueError:
            raise RecordError(name, f"line {lineno}: unreadable number") from None
        tokens.extend((v, lineno) for v in values)
    _check_written_alike(tokens, name)
    if len(samples) != npts:
        what = "truncated" if len(samples) < npts else "longer than its header says"
        raise RecordError(
            name, f"is {what}: header NPTS={npts} but {len(samples)} samples were found"
        )
    trace = make_trace(samples, delta, stats)
    check_samples(trace.data, name, "the acceleration record")
    trace.data *= factor
    check_plausible_samples(trace.data, name, f"the acceleration record (in {unit})")
    return Stream([trace])
