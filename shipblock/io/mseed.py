"""MiniSEED and full SEED files: what libmseed (through :func:`obspy.read`) does not check.

SEED [1]_ files are records of a fixed length (256 bytes to 64 kB), each with a 48-byte fixed
header: a six-digit sequence number, a record type (``D``, ``R``, ``Q``, ``M``: data; ``V``,
``A``, ``S``, ``T``: the control headers of a full SEED volume), then for data records the
number of samples (bytes 30-31), the offset of the samples (bytes 44-45) and of the first
blockette (bytes 46-47). Blockette 1000 gives the encoding of the samples (byte 4: 1 = INT16,
3 = INT32, 4 = FLOAT32, 5 = FLOAT64, 10 = Steim-1, 11 = Steim-2), their word order (byte 5) and
the record length (byte 6, a power of two).

Two things a reading needs that libmseed leaves out:

* **Full SEED volumes** hold the station's metadata (the "dataless" control headers) before the
  data records. libmseed skips them; the check that the records read account for every byte of
  the file (a record cut short is otherwise skipped without a word) must count them too:
  :func:`control_header_bytes`. The volume's own responses are read with obspy's SEED parser
  [2]_ (:func:`attach_volume_responses`), so its counts convert without a separate StationXML;
  each trace says so in ``stats.seed_volume``.
* **A damaged encoding byte.** Steim-compressed samples read as INT16 or INT32 are numbers, just
  wrong ones (the campaign of issue 33 found ~2,000 per record). Steim frames carry their own
  check: the first frame's words 1 and 2 are the first and last sample (the forward and reverse
  integration constants X0 and Xn). A record that declares an integer or float encoding but whose
  samples decode as Steim-1 or Steim-2 to the stated number of samples with both constants right
  is Steim data under a damaged encoding byte (random integers pass that check with probability
  of order 2^-64): :func:`check_encodings` refuses it.

References
----------
.. [1] International Federation of Digital Seismograph Networks (2012), "SEED Reference Manual,
   version 2.4", chapters 8 (fixed section of data header, blockette 1000) and appendix B
   (Steim compression: "the first frame ... integration constants X0 and Xn").
.. [2] obspy.io.xseed, https://docs.obspy.org/packages/obspy.io.xseed.html
"""

from __future__ import annotations

import struct
import sys
import warnings

import numpy as np
import obspy
from obspy.io.mseed.util import _unpack_steim_1, _unpack_steim_2

from shipblock.errors import RecordError

__all__ = ["attach_volume_responses", "check_encodings", "control_header_bytes"]

#: Record types of the control headers of a full SEED volume: volume, abbreviation, station,
#: time span.
CONTROL_TYPES = b"VAST"

#: Record types of data records.
DATA_TYPES = b"DRQM"

#: Encodings of blockette 1000 that are not compressed, and their names.
PLAIN_ENCODINGS = {1: "INT16", 3: "INT32", 4: "FLOAT32", 5: "FLOAT64"}

_FIXED_HEADER = 48
_SMALLEST_RECORD = 256


def _is_record_start(raw: bytes, pos: int, types: bytes) -> bool:
    """Whether ``raw[pos:]`` starts a SEED record of one of ``types`` (sequence number, type)."""
    head = raw[pos:pos + 8]
    return (len(head) == 8 and head[6:7] in [bytes([t]) for t in types]
            and all(c in b"0123456789 " for c in head[:6]) and head[7:8] in b" *")


def control_header_bytes(raw: bytes) -> int:
    """Bytes of the control-header records a full SEED volume starts with (0 for MiniSEED).

    The logical record length is the one the volume header states in its first blockette
    (005 field, 008 telemetry or 010 station volume: type, 4-digit length, 4-character version,
    2-digit exponent).
    """
    if not _is_record_start(raw, 0, CONTROL_TYPES) or raw[8:11] not in (b"005", b"008", b"010"):
        return 0
    try:
        length = 2 ** int(raw[19:21])
    except ValueError:
        return 0
    if not _SMALLEST_RECORD <= length <= 2 ** 16:
        return 0
    pos = 0
    while pos < len(raw) and _is_record_start(raw, pos, CONTROL_TYPES):
        pos += length
    return min(pos, len(raw))


def _records(raw: bytes, start: int):
    """``(offset, fixed header fields, blockette 1000 fields)`` of each data record."""
    pos = start
    while pos + _FIXED_HEADER <= len(raw):
        if not _is_record_start(raw, pos, DATA_TYPES):
            return
        year_be = struct.unpack(">H", raw[pos + 20:pos + 22])[0]
        order = ">" if 1900 <= year_be <= 2200 else "<"
        npts, = struct.unpack(order + "H", raw[pos + 30:pos + 32])
        data_offset, blockette = struct.unpack(order + "HH", raw[pos + 44:pos + 48])
        b1000 = None
        seen = 0
        while blockette and blockette + 8 <= len(raw) - pos and seen < 16:
            kind, following = struct.unpack(order + "HH", raw[pos + blockette:pos + blockette + 4])
            if kind == 1000:
                b1000 = tuple(raw[pos + blockette + 4:pos + blockette + 7])
                break
            blockette, seen = following, seen + 1
        if b1000 is None or not 8 <= b1000[2] <= 16:
            return  # libmseed's own checks cover records it cannot place
        length = 2 ** b1000[2]
        yield pos, npts, data_offset, length, b1000
        pos += length


def _decodes_as_steim(payload: bytes, npts: int, big_endian: bool) -> str | None:
    """``"STEIM1"``/``"STEIM2"`` if the bytes decode as that with both integration constants."""
    if npts < 2 or len(payload) < 64:
        return None
    order = ">" if big_endian else "<"
    x0, xn = struct.unpack(order + "ii", payload[4:12])
    swap = int(big_endian != (sys.byteorder == "big"))
    buffer = np.frombuffer(payload, dtype=np.uint8).copy()
    for name, unpack in (("STEIM2", _unpack_steim_2), ("STEIM1", _unpack_steim_1)):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # libmseed's integrity warning: the answer is no
                samples = unpack(buffer, npts, swapflag=swap)
        except Exception:  # noqa: BLE001 - not decodable this way
            continue
        if samples.size == npts and samples[0] == x0 and samples[-1] == xn:
            return name
    return None


def check_encodings(raw: bytes, name: str) -> None:
    """Refuse a record whose stated plain encoding hides Steim frames (a damaged encoding byte).

    Parameters
    ----------
    raw : bytes
        The file's bytes.
    name : str
        The file, for the message.

    Raises
    ------
    RecordError
        Naming the record (byte offset), its stated encoding and the Steim variant found.
    """
    for pos, npts, data_offset, length, (encoding, word_order, _) in _records(
            raw, control_header_bytes(raw)):
        if encoding not in PLAIN_ENCODINGS or not _FIXED_HEADER <= data_offset < length:
            continue
        steim = _decodes_as_steim(raw[pos + data_offset:pos + length], npts, word_order == 1)
        if steim is not None:
            raise RecordError(
                name, f"is damaged: the record at byte {pos} states encoding"
                f" {PLAIN_ENCODINGS[encoding]} (blockette 1000) but its samples are {steim}"
                " frames whose integration constants check: the encoding byte is wrong")


def attach_volume_responses(stream, name: str, notes: list[str]) -> None:
    """Attach the responses of a full SEED volume's control headers to its traces, in place.

    Read with :func:`obspy.read_inventory` (format ``SEED``). Traces that already have a response
    keep it; a volume obspy cannot read (it refuses 512-byte logical records, which telemetry
    volumes use), or one without a channel of a trace, is said in ``notes`` and leaves the trace
    as it is (its counts then need ``inventory=``).
    """
    try:
        inventory = obspy.read_inventory(name, format="SEED")
    except Exception as exc:  # noqa: BLE001 - obspy's SEED parser raises anything on odd volumes
        notes.append(f"its control headers could not be read as metadata ({exc}): the counts"
                     " need inventory= (command line: --inventory)")
        return
    for trace in stream:
        if trace.stats.get("response") is not None:
            continue
        try:
            trace.stats.response = inventory.get_response(trace.id, trace.stats.starttime)
        except Exception:  # noqa: BLE001 - no such channel or epoch
            notes.append(f"its control headers have no response of {trace.id}")
