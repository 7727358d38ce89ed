"""One time base per record: gaps inside a channel, and one rate and window for the components.

:func:`merge_gaps` merges the traces of each channel, refusing gaps (or filling short ones by
a straight line, ``gaps="interpolate"``) and overlaps with different samples;
:func:`align_components` brings the components to one sampling rate and one time window
(``align="trim"``, ``"resample"`` or ``"strict"``), within the tolerances below.
"""

from __future__ import annotations

import math

import numpy as np
from obspy import Stream, Trace

from shipblock.checks import how_to_pass
from shipblock.errors import ParameterError, RecordError
from shipblock.io import MAX_DIGITIZATION_GAP_S
from shipblock.records.motion import COMPONENT_KEY, trace_source

__all__ = ["MAX_INTERPOLATED_GAP_S", "WINDOW_TOLERANCE_FRACTION", "align_components", "merge_gaps"]

#: Anti-alias low-pass corner as a fraction of the new Nyquist frequency when down-sampling [-].
ANTI_ALIAS_FRACTION = 0.8

#: Order of the zero-phase Butterworth anti-alias filter [-].
ANTI_ALIAS_CORNERS = 8

#: Half-width of the Lanczos interpolation kernel, in samples [-].
LANCZOS_HALF_WIDTH = 20

#: Time offsets smaller than this fraction of a sample are treated as zero [-].
SAMPLE_FRACTION_TOLERANCE = 1e-3

#: Longest gap inside a channel that ``gaps="interpolate"`` fills by a straight line [s]: as for
#: digitized records (:data:`shipblock.io.MAX_DIGITIZATION_GAP_S`), a longer hole would
#: replace the 1-25 Hz motion the ship responds to by a line. Any gap is refused by default.
MAX_INTERPOLATED_GAP_S = MAX_DIGITIZATION_GAP_S

#: Largest share of a record's span (from the earliest start to the latest end of its components)
#: that trimming the components to their common window may drop [-]. Real records' components
#: differ by up to 3.1 % (CI.MPM, gmprocess corpus: ends at 66.05-68.19 s); a component with much
#: less than the others is damaged (a truncated file, a lost record) and is refused.
WINDOW_TOLERANCE_FRACTION = 0.05


def _seconds(duration_s: float) -> str:
    """A duration in words a reader can judge: seconds, or days/years when it is that long."""
    if abs(duration_s) >= 2 * 86400.0 * 365.25:
        return f"{duration_s:.6g} s ({duration_s / (86400.0 * 365.25):.3g} years)"
    if abs(duration_s) >= 2 * 86400.0:
        return f"{duration_s:.6g} s ({duration_s / 86400.0:.3g} days)"
    return f"{duration_s:.6g} s"


def _segments(group: Stream, name: str, seed_id: str):
    """Gaps and overlaps between the traces of one channel, found from their headers alone.

    Returns
    -------
    list of (obspy.UTCDateTime, float)
        ``(end of the data before the gap, gap length [s])``: time without samples, beyond half
        a sample.

    Raises
    ------
    RecordError
        If two traces overlap with different samples (two versions of the same time: a damaged
        time field, or two different recordings under one channel code).
    """
    delta = group[0].stats.delta
    ordered = sorted(group, key=lambda tr: tr.stats.starttime)
    found = []
    covered = ordered[0]
    for trace in ordered[1:]:
        missing = trace.stats.starttime - covered.stats.endtime - delta  # [s]
        if missing > 0.5 * delta:
            found.append((covered.stats.endtime, missing))
        elif missing < -0.5 * delta:
            for earlier in ordered:
                if earlier is trace:
                    break
                _check_overlap(earlier, trace, name, seed_id)
        if trace.stats.endtime > covered.stats.endtime:
            covered = trace
    return found


def _check_overlap(first: Trace, second: Trace, name: str, seed_id: str) -> None:
    """Refuse two traces of one channel whose common time holds different samples."""
    delta = first.stats.delta
    start = max(first.stats.starttime, second.stats.starttime)
    end = min(first.stats.endtime, second.stats.endtime)
    if end < start:
        return
    offset_a = (start - first.stats.starttime) / delta
    offset_b = (start - second.stats.starttime) / delta
    count = int(round((end - start) / delta)) + 1
    aligned = max(abs(offset_a - round(offset_a)), abs(offset_b - round(offset_b)))
    a = np.asarray(first.data[int(round(offset_a)):int(round(offset_a)) + count])
    b = np.asarray(second.data[int(round(offset_b)):int(round(offset_b)) + count])
    if aligned <= SAMPLE_FRACTION_TOLERANCE and a.shape == b.shape and np.array_equal(a, b):
        return  # the same samples twice (a repeated record): merged as one
    raise RecordError(
        name,
        f"channel {seed_id} holds two different recordings of {_seconds(end - start)} from"
        f" {start} (overlapping records with different samples: a damaged record time?)",
    )


def _channel_key(trace: Trace):
    """What makes traces pieces of one channel: the SEED id, and for a trace with neither station
    nor channel code (a file that names nothing, e.g. an SMC file of type ``0 UNKNOWN``) also
    its file: such files are components told apart by file name (``channel_map``)."""
    if trace.stats.station.strip("*") or trace.stats.channel:
        return trace.id
    return trace.id, trace_source(trace)


def merge_gaps(stream: Stream, gaps: str) -> Stream:
    """Merge traces of the same channel; refuse or fill gaps.

    Gaps and overlaps are found from the traces' headers before anything is merged, so that a
    damaged record time (a MiniSEED record put years away) is refused at once, without
    allocating the span it would make.
    """
    if gaps not in ("refuse", "interpolate"):
        raise ParameterError(f"gaps must be 'refuse' or 'interpolate', not {gaps!r}")
    merged = Stream()
    for key in dict.fromkeys(_channel_key(tr) for tr in stream):
        group = Stream([tr for tr in stream if _channel_key(tr) == key])
        seed_id = group[0].id
        if len(group) == 1:
            merged += group
            continue
        name = trace_source(group[0])
        if len({trace_source(tr) for tr in group}) > 1:
            raise RecordError(
                name, f"channel {seed_id} appears in several files: "
                + ", ".join(sorted({trace_source(tr) for tr in group}))
            )
        rates = {tr.stats.sampling_rate for tr in group}
        if len(rates) > 1:
            raise RecordError(name, f"channel {seed_id} changes sampling rate ({sorted(rates)} Hz)")
        gap_list = _segments(group, name, seed_id)
        if gap_list:
            first_end, first_gap = gap_list[0]
            longest = max(length for _, length in gap_list)
            where = (f"{len(gap_list)} gap(s), the first of {_seconds(first_gap)} after {first_end}"
                     + (f", the longest {_seconds(longest)}" if len(gap_list) > 1 else ""))
            if gaps == "refuse":
                raise RecordError(
                    name, f"channel {seed_id} has {where}; {how_to_pass('gaps', 'interpolate')} to"
                    f" fill gaps of up to {MAX_INTERPOLATED_GAP_S:g} s",
                )
            if longest > MAX_INTERPOLATED_GAP_S:
                raise RecordError(
                    name, f"channel {seed_id} has {where}: longer than the"
                    f" {MAX_INTERPOLATED_GAP_S:g} s gaps='interpolate' fills (a damaged record"
                    " time, or a recording with a hole in it)",
                )
        try:
            joined = group.copy().merge(method=1, fill_value="interpolate" if gap_list else None)
        except Exception as exc:  # noqa: BLE001
            raise RecordError(name, f"channel {seed_id} cannot be merged: {exc}") from exc
        trace = joined[0]
        if np.ma.isMaskedArray(trace.data):
            if np.ma.count_masked(trace.data):
                raise RecordError(name, f"channel {seed_id} has masked samples after merging")
            trace.data = np.ma.getdata(trace.data)
        if gap_list:
            trace.stats.shipblock_gaps_filled = len(gap_list)
        merged += joined
    return merged


def _describe(traces: list[Trace], origin) -> str:
    """Each component's rate, window (from ``origin``) and sample count, for error messages."""
    return "; ".join(
        f"{tr.stats[COMPONENT_KEY]} ({tr.id}) {tr.stats.sampling_rate:g} Hz,"
        f" {tr.stats.starttime - origin:.6g}-{tr.stats.endtime - origin:.6g} s,"
        f" {tr.stats.npts} samples"
        for tr in traces
    )


def align_components(traces: list[Trace], align: str, notes: list[str]) -> None:
    """Bring traces to one sampling rate and one time window, in place.

    Components must share one sampling rate (``align="resample"`` brings them to the lowest)
    and cover one window: trimming them to their common window may drop at most
    :data:`WINDOW_TOLERANCE_FRACTION` of the record's span, or one sample; beyond that, or with
    ``align="strict"`` any difference, the record is refused with the numbers.
    """
    label = trace_source(traces[0])
    origin = min(tr.stats.starttime for tr in traces)
    rates = sorted({tr.stats.sampling_rate for tr in traces})
    if any(not math.isclose(rate, rates[0], rel_tol=1e-9) for rate in rates):
        if align != "resample":
            raise RecordError(
                label,
                f"components have different sampling rates ({_describe(traces, origin)});"
                f" {how_to_pass('align', 'resample')} to resample them to the lowest rate"
                f" ({rates[0]:g} Hz) after an anti-alias low-pass",
            )
        target = rates[0]
        for tr in traces:
            if tr.stats.sampling_rate != target:
                old = tr.stats.sampling_rate
                tr.filter(
                    "lowpass",
                    freq=ANTI_ALIAS_FRACTION * target / 2.0,
                    corners=ANTI_ALIAS_CORNERS,
                    zerophase=True,
                )
                tr.interpolate(sampling_rate=target, method="lanczos", a=LANCZOS_HALF_WIDTH)
                notes.append(
                    f"{tr.stats[COMPONENT_KEY]} ({tr.id}): resampled {old:g} -> {target:g} Hz"
                    " after a"
                    f" zero-phase Butterworth low-pass at {ANTI_ALIAS_FRACTION * target / 2:g} Hz"
                )
    else:
        for tr in traces[1:]:
            tr.stats.sampling_rate = traces[0].stats.sampling_rate  # equal within 1e-9
    delta = traces[0].stats.delta
    start = max(tr.stats.starttime for tr in traces)
    end = min(tr.stats.endtime for tr in traces)
    same = all(
        tr.stats.starttime == traces[0].stats.starttime and tr.stats.npts == traces[0].stats.npts
        for tr in traces
    )
    if same:
        return
    if align == "strict":
        raise RecordError(
            label,
            "components differ in start time or length: "
            + ", ".join(f"{tr.stats[COMPONENT_KEY]} {tr.stats.starttime} npts={tr.stats.npts}"
                        for tr in traces),
        )
    if end - start < delta:
        raise RecordError(label, "components do not overlap in time: "
                          + _describe(traces, origin))
    span = max(tr.stats.endtime for tr in traces) - origin + delta
    dropped = span - (end - start + delta)
    allowed = max(delta, WINDOW_TOLERANCE_FRACTION * span)
    if dropped > allowed * (1.0 + 1e-9):
        raise RecordError(
            label,
            f"components do not cover one time window: their common window"
            f" {start - origin:.6g}-{end - origin:.6g} s would drop {dropped:.6g} s"
            f" ({100.0 * dropped / span:.3g} %) of the record's {span:.6g} s, more than"
            f" {100.0 * WINDOW_TOLERANCE_FRACTION:g} % ({_describe(traces, origin)}): a"
            " truncated or damaged component?",
        )
    for tr in traces:
        offset = (start - tr.stats.starttime) / delta
        if abs(offset - round(offset)) > SAMPLE_FRACTION_TOLERANCE:
            npts = int(math.floor((tr.stats.endtime - start) / delta + 1e-9)) + 1
            tr.interpolate(
                sampling_rate=tr.stats.sampling_rate,
                method="lanczos",
                a=LANCZOS_HALF_WIDTH,
                starttime=start,
                npts=npts,
            )
            notes.append(f"{tr.stats[COMPONENT_KEY]}: interpolated onto the common time grid")
        else:
            tr.trim(starttime=start, nearest_sample=True)
    npts = min(tr.stats.npts for tr in traces)
    for tr in traces:
        if tr.stats.npts > npts:
            tr.data = tr.data[:npts]
    notes.append(f"components trimmed to the common window {start} ({npts} samples;"
                 f" {dropped:.6g} s of the {span:.6g} s span dropped)")
