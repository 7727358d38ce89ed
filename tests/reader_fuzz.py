"""Mutations of real record files, for the readers' fuzz tests.

:func:`mutations` derives damaged versions of a real file (truncated at several places, a header
line dropped, numbers replaced by NaN/inf/huge/negative values or garbage, lines duplicated,
bytes flipped); :func:`assert_reader_survives` feeds each to a reader and asserts that it either
raises one of shipblock's own errors (which name the file) or returns only finite samples at a
finite positive sampling interval. An IndexError, a hang or a silently wrong stream fails.
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
        read += 1
    return read
