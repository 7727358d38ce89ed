"""A cheap look at a large file before obspy's format sniffing (issue 33, item 5).

:func:`obspy.read` without a format tries every plug-in's detector and, first, its archive
sniffing (:func:`tarfile.is_tarfile` scans a file of zero bytes block by block to its end; some
text detectors split the whole file into lines). On a 300 MB file that is no record that cost
64 s and 663 MB before "unknown format". Records are small (a strong-motion record is kilobytes
to a few megabytes) except in the formats that stream long data, and those all say what they are
in their first bytes. So a file larger than :data:`SCREEN_BYTES` is passed to obspy only if its
start carries one of these signatures (:func:`signature`); otherwise it is refused at once, with
the way round: name the format (``format=``, command line ``--format``), which skips the screen.

=====================  ============================================================
signature              what
=====================  ============================================================
compressed / archive   gzip ``1f 8b``, bzip2 ``BZh``, xz, zip ``PK``, tar ``ustar``
SEED                   a MiniSEED or full SEED record: 6 digits, a record type, blank
SAC                    binary: the file is 632 bytes + 4 x NPTS (header word 79)
SEG-Y                  a 3200-byte textual header starting with ``C`` (ASCII or EBCDIC)
SEG2                   block id ``0x3a55``
SEISAN                 a Fortran record of 80 bytes (its length word, either byte order)
WAV                    ``RIFF``
text                   the start is text whose lines are mostly numbers, or names one
                       of shipblock's text formats or obspy's (K-NET, GSE2, TSPAIR, ...)
=====================  ============================================================
"""

from __future__ import annotations

import os
import struct

from shipblock.errors import RecordError

__all__ = ["SCREEN_BYTES", "screen_large_file", "signature"]

#: Files larger than this [bytes] are screened; smaller ones go straight to obspy.
SCREEN_BYTES = 16 * 1024 * 1024

#: Bytes read from the start of a screened file.
HEAD_BYTES = 65536

_MAGIC = (
    (b"\x1f\x8b", "gzip"), (b"BZh", "bzip2"), (b"\xfd7zXZ\x00", "xz"), (b"PK\x03\x04", "zip"),
    (b"RIFF", "WAV"), (b"\x3a\x55", "SEG2"), (b"\x55\x3a", "SEG2"),
)

#: Words that open obspy's and shipblock's text formats (upper case).
_TEXT_WORDS = ("ORIGIN TIME", "TIMESERIES", "WID2", "DATA_TYPE", "DELTA:", "EVENT_NAME:",
               "PEER", "CORRECTED", "UNCORRECTED", "ACCELERATION", "STATION", "RECORD",
               "NPTS", "DT", "TIME", "ACCEL", "%", "#")

_SAC_HEADER_BYTES = 632
_SAC_NPTS_OFFSET = 79 * 4


def _sac(head: bytes, size: int) -> bool:
    if len(head) < _SAC_HEADER_BYTES:
        return False
    for order in "<>":
        npts, = struct.unpack(order + "i", head[_SAC_NPTS_OFFSET:_SAC_NPTS_OFFSET + 4])
        if npts > 0 and size == _SAC_HEADER_BYTES + 4 * npts:
            return True
    return False


def _text(head: bytes) -> bool:
    try:
        text = head.decode("ascii")
    except UnicodeDecodeError:
        try:
            text = head.decode("latin-1")
        except UnicodeDecodeError:  # pragma: no cover - latin-1 decodes any byte
            return False
        if sum(c.isprintable() or c in "\r\n\t" for c in text) < 0.99 * len(text):
            return False
    lines = [line for line in text.splitlines()[:-1] if line.strip()][:60]
    if not lines:
        return False
    if any(line.lstrip().upper().startswith(_TEXT_WORDS) for line in lines[:10]):
        return True
    numeric = 0
    for line in lines:
        try:
            [float(t) for t in line.replace(",", " ").replace(";", " ").split()]
        except ValueError:
            continue
        numeric += 1
    return numeric >= len(lines) // 2 + 1


def signature(head: bytes, size: int) -> str | None:
    """The kind of file the first bytes show (see the module table), or ``None``."""
    for magic, kind in _MAGIC:
        if head.startswith(magic):
            return kind
    if head[257:262] == b"ustar":
        return "tar"
    if (len(head) >= 8 and head[:6].replace(b" ", b"0").isdigit()
            and head[6:7] in (b"D", b"R", b"Q", b"M", b"V", b"A", b"S", b"T")
            and head[7:8] in (b" ", b"*")):
        return "SEED"
    if _sac(head, size):
        return "SAC"
    if len(head) >= 3600 and head[:1] in (b"C", b"\xc3"):
        return "SEG-Y"
    if head[:4] in (b"\x50\x00\x00\x00", b"\x00\x00\x00\x50"):
        return "SEISAN"
    if _text(head):
        return "text"
    return None


def screen_large_file(name: str) -> None:
    """Refuse a large file whose start shows no record format, before obspy sniffs it.

    Parameters
    ----------
    name : str
        Path of an existing file.

    Raises
    ------
    RecordError
        If the file is larger than :data:`SCREEN_BYTES` and :func:`signature` finds nothing.
    """
    size = os.path.getsize(name)
    if size <= SCREEN_BYTES:
        return
    with open(name, "rb") as fh:
        head = fh.read(HEAD_BYTES)
    if signature(head, size) is None:
        raise RecordError(
            name, f"unknown format: a file of {size / 1e6:.0f} MB whose start shows no record"
            " format (no SEED record, SAC header, archive, SEG-Y/SEG2/SEISAN/WAV signature or text"
            " of a record); if it is a record, name its format with format= (command line:"
            " --format)")
