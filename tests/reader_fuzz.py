"""Mutations of real record files, for the readers' fuzz tests.

:func:`mutations` derives damaged versions of a real file (truncated at several places, a header
line dropped, numbers replaced by NaN/inf/huge/negative values or garbage, lines duplicated,
bytes flipped); :func:`assert_reader_survives` feeds each to a reader and asserts that it either
raises one of shipblock's own errors (which name the file) or returns only finite samples at a
sampling interval within 1e-4..1 s, accelerations under 100 g. An IndexError, a hang or a
silently wrong stream fails.

:func:`sac_patch` and :func:`stationxml_patch` change one header field of a SAC or StationXML file
(the cases of :func:`sac_field_mutations` and :func:`stationxml_field_mutations`), for the tests
of ``tests/test_reader_fuzz_headers.py``, which know the correct read of each.
"""

from __future__ import annotations

import io
import math
import random
import re

import numpy as np

from shipblock.errors import ShipblockError

_NUMBER = re.compile(rb"[-+]?\d+\.?\d*(?:[eEdD][-+]?\d+)?")

#: What a number in a file is replaced by.
REPLACEMENTS = (b"nan", b"NaN", b"inf", b"-inf", b"1e999", b"-1e308", b"1e-320", b"0", b"-1",
                b"99999999999999999999", b"x", b"", b"1.2.3")


def mutations(raw: bytes, seed: int = 0, count: int = 60):
    """Yield ``(description, damaged bytes)`` pairs derived from ``raw``."""
    rng = random.Random(seed)
    yield "empty", b""
    yield "one byte", raw[:1]
    lines = raw.splitlines(keepends=True)
    for fraction in (0.02, 0.1, 0.3, 0.5, 0.9, 0.999):
        cut = int(len(raw) * fraction)
        yield f"truncated at {fraction:.1%}", raw[:cut]
    header_lines = min(len(lines), 80)
    for _ in range(count // 4):
        index = rng.randrange(header_lines) if header_lines else 0
        yield f"line {index} dropped", b"".join(lines[:index] + lines[index + 1:])
    numbers = list(_NUMBER.finditer(raw[: min(len(raw), 20000)]))
    for _ in range(count // 2):
        if not numbers:
            break
        match = rng.choice(numbers)
        new = rng.choice(REPLACEMENTS)
        yield (f"number {match.group().decode(errors='replace')!r} at byte {match.start()}"
               f" -> {new.decode()!r}"), raw[: match.start()] + new + raw[match.end():]
    if len(lines) > 2:
        index = rng.randrange(header_lines)
        yield f"line {index} doubled", b"".join(lines[: index + 1] + lines[index:])
    for _ in range(count // 4):
        if not raw:
            break
        position = rng.randrange(min(len(raw), 20000))
        flipped = bytes([raw[position] ^ (1 << rng.randrange(7))])
        yield f"byte {position} flipped", raw[:position] + flipped + raw[position + 1:]


def assert_reader_survives(reader, raw: bytes, seed: int = 0, count: int = 60, **kwargs) -> int:
    """Feed every mutation of ``raw`` to ``reader``; return how many were read without error.

    Parameters
    ----------
    reader : callable
        A shipblock reader (``read_dmg`` ...) taking a file object.
    raw : bytes
        A real file's bytes.

    Raises
    ------
    AssertionError
        If a mutation makes the reader raise anything but a :class:`ShipblockError`, or return
        non-finite samples or an invalid sampling interval.
    """
    read = 0
    for description, damaged in mutations(raw, seed=seed, count=count):
        try:
            stream = reader(io.BytesIO(damaged), **kwargs)
        except ShipblockError:
            continue
        except Exception as exc:  # noqa: BLE001 - the point of the test
            raise AssertionError(f"{description}: {type(exc).__name__}: {exc}") from exc
        for trace in stream:
            assert trace.stats.npts > 0, description
            assert np.all(np.isfinite(trace.data)), description
            assert math.isfinite(trace.stats.delta) and trace.stats.delta > 0, description
            # The shared plausibility limits (shipblock.io._common): 1e-4..1 s, under 100 g.
            assert 1e-4 <= trace.stats.delta <= 1.0, (description, trace.stats.delta)
            if trace.stats.get("units") == "m/s**2":
                assert np.max(np.abs(trace.data)) <= 100 * 9.80665, description
        read += 1
    return read


# ------------------------------------------------------------------ header fields (SAC, StationXML)

#: Absurd values every numeric header field is tried with (beside each field's own cases).
ABSURD_FLOATS = (float("nan"), float("inf"), float("-inf"), 0.0, -1.0, 1e-30, 1e30, 1e-300, 1e300)


def sac_patch(raw: bytes, field: str, value) -> bytes:
    """A SAC file with one header field replaced, as a damaged or hand-edited file would hold it.

    Parameters
    ----------
    raw : bytes
        A binary SAC file (either byte order).
    field : str
        A header name of :mod:`obspy.io.sac.header` (``"delta"``, ``"npts"``, ``"kuser0"`` ...).
    value : float, int or str
        The new value (a float field is stored as float32: 1e300 becomes inf, 1e-300 zero).

    Returns
    -------
    bytes
        The patched file.
    """
    import struct

    from obspy.io.sac.header import FLOATHDRS, INTHDRS, STRHDRS

    # NVHDR (header version, 6) tells the byte order.
    order = "<" if struct.unpack("<i", raw[280 + 4 * INTHDRS.index("nvhdr"):][:4])[0] == 6 else ">"
    patched = bytearray(raw)
    if field in FLOATHDRS:
        offset = 4 * FLOATHDRS.index(field)
        with np.errstate(over="ignore"):
            patched[offset:offset + 4] = np.array([value], dtype=order + "f4").tobytes()
    elif field in INTHDRS:
        offset = 280 + 4 * INTHDRS.index(field)
        patched[offset:offset + 4] = struct.pack(order + "i", int(value))
    else:
        offset = 440 + 8 * STRHDRS.index(field)  # KEVNM's 16 characters count as two fields
        patched[offset:offset + 8] = str(value).encode("ascii").ljust(8)[:8]
    return bytes(patched)


def sac_field_mutations():
    """Yield ``(field, value)`` cases for the SAC header fields the readers use."""
    for value in (*ABSURD_FLOATS, 5.0, 0.02):
        yield "delta", value
    for value in (0, -1, 1, 1999, 2001, 10**9):
        yield "npts", value
    for value in (float("nan"), float("inf"), 1e30, -1e30, 12.5):
        yield "b", value
    for value in (float("nan"), 1e30, -5.0):
        yield "e", value
    for value in (*ABSURD_FLOATS, 2.0):
        yield "scale", value
    for value in (5, 6, 7, 8, 99, -12345):
        yield "idep", value
    for value in ("g", "cm/s2", "cm/s", "cm", "furlong", "-12345"):
        yield "kuser0", value


def stationxml_patch(text: str, element: str, value: str, occurrence: int = 0) -> str:
    """StationXML text with the content of one element replaced.

    Parameters
    ----------
    text : str
        The StationXML document.
    element : str
        ``"Value"`` or ``"Frequency"`` (of the first channel's InstrumentSensitivity),
        ``"InputUnits"`` (its input unit's ``Name``) or ``"SampleRate"`` (the channel's).
    value : str
        The new content, as written in the file.
    occurrence : int, optional
        Which channel's (0: the first).

    Returns
    -------
    str
        The patched document.
    """
    patterns = {
        "Value": r"(<InstrumentSensitivity>\s*<Value>)([^<]*)(</Value>)",
        "Frequency": r"(<InstrumentSensitivity>\s*<Value>[^<]*</Value>\s*<Frequency>)([^<]*)"
                     r"(</Frequency>)",
        "InputUnits": r"(<InstrumentSensitivity>\s*<Value>[^<]*</Value>\s*<Frequency>[^<]*"
                      r"</Frequency>\s*<InputUnits>\s*<Name>)([^<]*)(</Name>)",
        "SampleRate": r"(<SampleRate[^>]*>)([^<]*)(</SampleRate>)",
    }
    matches = list(re.finditer(patterns[element], text))
    match = matches[occurrence]
    return text[: match.start(2)] + value + text[match.end(2):]


def stationxml_field_mutations():
    """Yield ``(element, value)`` cases for the StationXML fields read_motion uses or parses."""
    numbers = ("inf", "-inf", "NaN", "1e300", "1e-300", "0", "-1", "1e-30", "x", "")
    for element in ("Value", "Frequency", "SampleRate"):
        for value in numbers:
            yield element, value
    for value in ("FURLONGS", "", "M", "M/S", "CM/S**2", "NM/S**2", "G"):
        yield "InputUnits", value
