r"""Record selection for a target spectrum: the k records of a catalogue that match it best.

Every record of a catalogue is read, processed (the default chain unless another is given, as
a pipeline would) and its 5 %-damped pseudo-acceleration spectra computed
(:func:`shipblock.intensity.spectral_acceleration`) on ``n_periods`` periods :math:`T_i`
log-spaced over the period range :math:`[T_a, T_b]`: of the horizontal the study will use
(``"H1"``, ``"H2"``, or ``"geomean"``, the geometric mean of the two) and, when a vertical
target is given, of the vertical. One factor :math:`f` scales both components (the V/H ratio
of the record is kept, as ``vertical = "same"`` in a pipeline). With the log residuals

.. math:: r^H_i(f) = \ln\frac{f\,S^H(T_i)}{S^{H*}(T_i)}, \qquad
          r^V_i(f) = \ln\frac{f\,S^V(T_i)}{S^{V*}(T_i)},

the misfit of a record is the weighted RMS

.. math:: \varepsilon(f) = \sqrt{\frac{\sum_i (r^H_i)^2 + w \sum_i (r^V_i)^2}{n (1 + w)}}

(:math:`w` = ``vertical_weight``, 0 without a vertical target). It is quadratic in
:math:`\ln f`, so its minimum is the weighted mean of the log ratios,

.. math:: \ln f^\star = \frac{\sum_i \ln(S^{H*}_i/S^H_i) + w \sum_i \ln(S^{V*}_i/S^V_i)}
          {n(1 + w)},

and within bounds :math:`[f_{min}, f_{max}]` the bounded minimum is :math:`f^\star` clipped to
them (a convex function of one variable). Without scaling :math:`f = 1`. The k records of least
misfit are the suite.

**Suite mean (ASCE 7-16 §16.2.3).** The arithmetic mean of the suite's scaled horizontal
spectra must not fall below 90 % of the target anywhere in the period range. If it does and
scaling is on, every factor is raised by the common ratio that lifts the lowest point to 90 %
(within ``max_scale_factor``; the report says if the bound prevents it). ASCE 7-16 states the
check on maximum-direction spectra; here it is made on the component the study applies (or the
geometric mean), which is what the ship-block model sees.

**Records per earthquake.** Several records of one earthquake share its source and path, so a
suite drawn mostly from one event understates the record-to-record variability; common practice
caps them (FEMA P-695 takes at most two records from any one earthquake in its record sets).
With ``max_per_event = N`` the
suite is the k records of least total misfit with at most N from any one earthquake: taken best
first, a record is skipped when its earthquake already has N. The records allowed by such caps
form a matroid (a partition matroid), on which this greedy choice is optimal, so no other set
of k records within the caps has a smaller total misfit [3]_. The earthquake of a record is
(:func:`event_identity`, first found): the catalogue key ``event_id`` of its table; the
QuakeML event's resource id (the table's ``event`` file); the origin time (to the second) and
epicentre (to 0.01 deg) of an event given without id; the event name the record's own header
gives (PEER NGA ``.AT2``); the table's ``event_name``; the ``event`` file itself. Two QuakeML
files of one earthquake from different agencies have different ids: state ``event_id`` then.

The suite is written as a catalogue (:func:`selection_toml`): the chosen records' tables with
paths relative to the new file, each with ``selection_rank``, ``selection_scale_factor`` and
``selection_misfit``; a pipeline reads it with ``ids = "all"``.

References
----------
.. [1] ASCE/SEI 7-16 (2017). *Minimum Design Loads and Associated Criteria for Buildings and
   Other Structures*, §16.2.3 (selection and amplitude scaling of ground motions).
.. [2] Baker, J. W. and Lee, C. (2018). An improved algorithm for selecting ground motions to
   match a conditional spectrum. *J. Earthquake Eng.* 22(4), 708-723 (selection by the sum of
   squared log residuals).
.. [3] FEMA P-695 (2009). *Quantification of Building Seismic Performance Factors*, Appendix A
   (the record sets: no more than two records from any one earthquake); Edmonds, J. (1971).
   Matroids and the greedy algorithm. *Math. Programming* 1, 127-136.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from shipblock import checks, intensity
from shipblock.records.catalogue import CatalogueEntry, load_catalogue, relative_path, toml_value
from shipblock.errors import ParameterError, ShipblockError
from shipblock.processing import process_motion
from shipblock.scaling import TargetSpectrum, read_target_spectrum

__all__ = [
    "ASCE_SUITE_FLOOR",
    "RecordMatch",
    "Selection",
    "event_identity",
    "match_record",
    "select_records",
    "selection_lines",
    "selection_toml",
    "target_from_file",
]

#: Lowest ratio of the suite's mean spectrum to the target over the range (ASCE 7-16 §16.2.3).
ASCE_SUITE_FLOOR = 0.9

#: Default number of periods the spectra are compared on [-].
DEFAULT_PERIODS = 30

#: Horizontal spectra a selection can compare.
HORIZONTALS = ("H1", "H2", "geomean")


@dataclass(frozen=True)
class RecordMatch:
    """One record's spectra and its best factor to the target.

    Attributes
    ----------
    id : str
        Catalogue id.
    factor : float
        Scale factor of both components [-].
    misfit, misfit_h, misfit_v : float
        Combined, horizontal and vertical RMS log residual at ``factor`` [-] (``misfit_v`` NaN
        without a vertical target).
    sa_h, sa_v : numpy.ndarray
        Unscaled spectra on the selection's periods [m/s^2] (``sa_v`` None without a vertical
        target).
    bounded : bool
        Whether the factor sits on a bound (the unbounded optimum was outside).
    event : str
        The record's earthquake (:func:`event_identity`; empty when none is known).
    """

    id: str
    factor: float
    misfit: float
    misfit_h: float
    misfit_v: float
    sa_h: np.ndarray
    sa_v: np.ndarray | None
    bounded: bool = False
    event: str = ""


@dataclass
class Selection:
    """The chosen suite and every record's match.

    Attributes
    ----------
    chosen : list of RecordMatch
        The k best, best first, with the suite's common factor applied.
    ranked : list of RecordMatch
        Every record that could be matched, best first (factors before the suite factor).
    failures : dict
        Record id -> why it could not be used.
    periods : numpy.ndarray
        Comparison periods [s].
    target_h, target_v : numpy.ndarray
        Targets there [m/s^2] (``target_v`` None without a vertical target).
    suite_mean_h, suite_mean_v : numpy.ndarray
        Mean of the chosen records' scaled spectra [m/s^2].
    suite_ratio_min : float
        Lowest ``suite_mean_h / target_h`` over the range [-].
    suite_ratio_period : float
        Where it is [s].
    suite_factor : float
        Common factor applied to every chosen record to reach the floor (1 if not needed).
    passes : bool
        ``suite_ratio_min >= 0.9`` (ASCE 7-16 §16.2.3).
    options : dict
        The selection's settings, for the written catalogue.
    capped : dict
        Record id -> its earthquake, for the records that ranked above the last one chosen
        but were left out by ``max_per_event`` (empty without it).
    """

    chosen: list
    ranked: list
    failures: dict
    periods: np.ndarray
    target_h: np.ndarray
    target_v: np.ndarray | None
    suite_mean_h: np.ndarray
    suite_mean_v: np.ndarray | None
    suite_ratio_min: float
    suite_ratio_period: float
    suite_factor: float
    passes: bool
    options: dict = field(default_factory=dict)
    capped: dict = field(default_factory=dict)


def target_from_file(path, units: str | None = None) -> TargetSpectrum:
    """Read a target spectrum (period [s], Sa) whose Sa unit is given or in its header.

    Parameters
    ----------
    path : str or os.PathLike
        Two columns (see :func:`shipblock.scaling.read_target_spectrum`).
    units : str, optional
        Unit of Sa; default: the bracketed unit of the header's second column, e.g.
        ``period [s], Sa [g]``.

    Returns
    -------
    TargetSpectrum
        [m/s^2].

    Raises
    ------
    ParameterError
        If no unit is given and the header states none.
    """
    path = checks.existing_file(path, "target", "a target spectrum file (period [s], Sa)")
    if units is None:
        first = next((ln.split("#", 1)[0] for ln in Path(path).read_text().splitlines()
                      if ln.split("#", 1)[0].strip()), "")
        found = re.findall(r"\[([^\]]+)\]", first)
        if len(found) < 2:
            raise ParameterError(f"{path}: give the unit of Sa (units, --units) or write it in "
                                 f"the header, e.g. 'period [s], Sa [g]'; got {first.strip()!r}")
        units = found[1].strip()
    return read_target_spectrum(path, units)


def _horizontal(motion, horizontal: str | None, periods, damping):
    if horizontal is None:  # the motion's own horizontal: rotated to the dock's azimuth
        return intensity.spectral_acceleration(motion.horizontal, motion.dt, periods, damping)
    comps = motion.components
    if horizontal == "geomean":
        if "H1" not in comps or "H2" not in comps:
            raise ShipblockError("needs both horizontals for horizontal = 'geomean'")
        return np.sqrt(intensity.spectral_acceleration(comps["H1"], motion.dt, periods, damping)
                       * intensity.spectral_acceleration(comps["H2"], motion.dt, periods,
                                                         damping))
    if horizontal not in comps:
        raise ShipblockError(f"has no {horizontal} component")
    return intensity.spectral_acceleration(comps[horizontal], motion.dt, periods, damping)


def event_identity(entry: CatalogueEntry, metadata: dict | None = None) -> tuple[str, str] | None:
    """The earthquake a catalogue record comes from, and how it is known.

    Parameters
    ----------
    entry : CatalogueEntry
        The record's catalogue table.
    metadata : dict, optional
        The metadata of the record as read (:attr:`GroundMotion.metadata
        <shipblock.records.motion.GroundMotion.metadata>`): its ``event`` summary.

    Returns
    -------
    (str, str) or None
        The identity and where it comes from, first found of: the table's ``event_id``; the
        QuakeML event's resource id; its origin time (to the second) and epicentre (to 0.01
        deg); the event name in the record's header; the table's ``event_name``; the table's
        ``event`` file. None when there is none of them.
    """
    if entry.extra.get("event_id") not in (None, ""):
        return str(entry.extra["event_id"]), "catalogue event_id"
    event = (metadata or {}).get("event") or {}
    if event.get("id"):
        return str(event["id"]), "QuakeML event id"
    if event.get("time") and event.get("latitude") is not None \
            and event.get("longitude") is not None:
        return (f"{str(event['time'])[:19]} at {float(event['latitude']):.2f}, "
                f"{float(event['longitude']):.2f}", "origin time and epicentre")
    if event.get("name"):
        return str(event["name"]), "event name in the record"
    if entry.extra.get("event_name") not in (None, ""):
        return str(entry.extra["event_name"]), "catalogue event_name"
    if entry.event is not None:
        return str(entry.event), "catalogue event file"
    return None


def match_record(record_id, sa_h, sa_v, target_h, target_v, *, vertical_weight=1.0,
                 scale=True, min_scale_factor=0.25, max_scale_factor=4.0) -> RecordMatch:
    r"""Best factor and misfit of one record's spectra to the targets (see the module text).

    Parameters
    ----------
    record_id : str
    sa_h, target_h : array_like
        Horizontal spectrum and target on the same periods [m/s^2], positive.
    sa_v, target_v : array_like or None
        The same for the vertical (both None: horizontal only).
    vertical_weight : float
        :math:`w` [-], >= 0.
    scale : bool
        Scale (else ``f = 1``).
    min_scale_factor, max_scale_factor : float
        Bounds of ``f`` [-].

    Returns
    -------
    RecordMatch
    """
    sa_h, target_h = np.asarray(sa_h, float), np.asarray(target_h, float)
    log_h = np.log(target_h / sa_h)
    w = 0.0 if target_v is None else float(vertical_weight)
    log_v = np.log(np.asarray(target_v, float) / np.asarray(sa_v, float)) if w else None
    bounded = False
    if scale:
        total = log_h.sum() + (w * log_v.sum() if w else 0.0)
        log_f = total / (log_h.size + (w * log_v.size if w else 0.0))
        low, high = np.log(min_scale_factor), np.log(max_scale_factor)
        bounded = not low <= log_f <= high
        log_f = float(np.clip(log_f, low, high))
    else:
        log_f = 0.0
    r_h = log_f - log_h
    misfit_h = float(np.sqrt(np.mean(r_h**2)))
    if w:
        r_v = log_f - log_v
        misfit_v = float(np.sqrt(np.mean(r_v**2)))
        misfit = float(np.sqrt((np.sum(r_h**2) + w * np.sum(r_v**2))
                               / (r_h.size + w * r_v.size)))
    else:
        misfit_v = float("nan") if target_v is None else float(np.sqrt(np.mean(
            (log_f - np.log(np.asarray(target_v, float) / np.asarray(sa_v, float))) ** 2)))
        misfit = misfit_h
    return RecordMatch(str(record_id), float(np.exp(log_f)), misfit, misfit_h, misfit_v,
                       sa_h, None if sa_v is None else np.asarray(sa_v, float), bounded)


def select_records(catalogue, target, k: int, *, period_range=None, vertical_target=None,
                   vertical_weight: float = 1.0, scale: bool = True,
                   min_scale_factor: float = 0.25, max_scale_factor: float = 4.0,
                   horizontal: str = "H1", azimuth: float | None = None,
                   damping: float = intensity.DEFAULT_DAMPING,
                   n_periods: int = DEFAULT_PERIODS, processing=None, ids=None,
                   suite_floor: bool = True, max_per_event: int | None = None) -> Selection:
    """Choose the ``k`` records of a catalogue that best match a target spectrum.

    Parameters
    ----------
    catalogue : str or os.PathLike or dict or None
        A catalogue TOML, or the entries of :func:`shipblock.records.catalogue.load_catalogue`; None:
        the shipped catalogue.
    target : TargetSpectrum or str or os.PathLike
        Horizontal target (a file as :func:`target_from_file`, unit in its header).
    k : int
        Number of records to choose, >= 1.
    period_range : tuple of float, optional
        :math:`(T_a, T_b)` [s]; default the target's whole range (and the vertical's).
    vertical_target : TargetSpectrum or path, optional
        Vertical target; then the vertical spectra count with ``vertical_weight``.
    vertical_weight : float
        :math:`w` [-].
    scale : bool
        Scale each record (one factor for both components); else unscaled.
    min_scale_factor, max_scale_factor : float
        Bounds of the factor [-] (ASCE-style practice keeps them within about 0.25 to 4).
    horizontal : {"H1", "H2", "geomean"}
        Horizontal spectrum compared (the study's component, or the geometric mean).
    azimuth : float, optional
        Dock transverse axis [deg clockwise from north]: the horizontals rotated onto it, as a
        pipeline's ``records.azimuth`` (replaces ``horizontal``).
    damping : float
        Fraction of critical damping of the spectra [-].
    n_periods : int
        Comparison periods, log-spaced [-].
    processing : list of dict, optional
        Processing chain before the spectra (default :data:`shipblock.processing.DEFAULT_CHAIN`;
        ``[]`` for none).
    ids : list of str, optional
        Only these catalogue records (default all).
    suite_floor : bool
        Raise the suite's factors to meet the 90 % floor when scaling.
    max_per_event : int, optional
        At most this many records from one earthquake (:func:`event_identity`); default no
        limit.

    Returns
    -------
    Selection

    Raises
    ------
    ParameterError
        Naming the argument: ``k`` larger than the records that could be matched (or, with
        ``max_per_event``, than the caps allow), a bad range, factor bounds or horizontal; with
        ``max_per_event``, a record whose earthquake is not known (naming it and the catalogue
        key ``event_id`` that states it).
    """
    entries = catalogue if isinstance(catalogue, dict) else load_catalogue(catalogue)
    k = checks.whole(k, "k", low=1, high=10_000)
    horizontal = checks.choice(horizontal, "horizontal", HORIZONTALS)
    if azimuth is not None:
        azimuth = checks.azimuth(azimuth, "azimuth")
    vertical_weight = checks.real(vertical_weight, "vertical_weight", low=0.0)
    min_scale_factor = checks.real(min_scale_factor, "min_scale_factor", low=0.0, low_open=True)
    max_scale_factor = checks.real(max_scale_factor, "max_scale_factor", low=min_scale_factor)
    n_periods = checks.whole(n_periods, "n_periods", low=2, high=1000)
    if max_per_event is not None:
        max_per_event = checks.whole(max_per_event, "max_per_event", low=1, high=10_000)
    if not isinstance(target, TargetSpectrum):
        target = target_from_file(target)
    if vertical_target is not None and not isinstance(vertical_target, TargetSpectrum):
        vertical_target = target_from_file(vertical_target)
    if period_range is None:
        lo, hi = target.periods[0], target.periods[-1]
        if vertical_target is not None:
            lo, hi = max(lo, vertical_target.periods[0]), min(hi, vertical_target.periods[-1])
        period_range = (lo, hi)
    try:
        ta, tb = (float(x) for x in period_range)
    except (TypeError, ValueError):
        raise ParameterError(f"period_range must be two periods [s], got {period_range!r}") \
            from None
    if not (checks.MIN_PERIOD <= ta < tb <= checks.MAX_PERIOD):
        raise ParameterError(f"period_range must satisfy 0 < T_a < T_b [s], got {period_range!r}")
    periods = np.geomspace(ta, tb, n_periods)
    target_h = target.at(periods)
    target_v = None if vertical_target is None else vertical_target.at(periods)
    wanted = list(entries) if ids is None else list(ids)
    unknown = [i for i in wanted if i not in entries]
    if unknown:
        raise ParameterError(f"ids: not in the catalogue: {', '.join(unknown)}")
    ranked, failures = [], {}
    for record_id in wanted:
        entry = entries[record_id]
        try:
            raw = entry.read(azimuth=azimuth)
            event = event_identity(entry, raw.metadata)
            motion = process_motion(raw, processing)
            sa_h = _horizontal(motion, None if azimuth is not None else horizontal, periods,
                               damping)
            sa_v = None
            if target_v is not None:
                if motion.vertical is None:
                    raise ShipblockError("has no vertical component (a vertical target is given)")
                sa_v = intensity.spectral_acceleration(motion.vertical, motion.dt, periods,
                                                       damping)
            if np.any(sa_h <= 0) or (sa_v is not None and np.any(sa_v <= 0)):
                raise ShipblockError(f"has zero Sa between {ta:g} and {tb:g} s")
        except (ShipblockError, ValueError, OSError) as exc:
            failures[record_id] = str(exc)
            continue
        if max_per_event is not None and event is None:
            raise ParameterError(f"max_per_event: the earthquake of record {record_id!r} is not "
                                 "known (no QuakeML event, no event in its header, no "
                                 "event_name); state it with event_id = \"...\" in its "
                                 "catalogue table")
        match = match_record(record_id, sa_h, sa_v, target_h, target_v,
                             vertical_weight=vertical_weight, scale=scale,
                             min_scale_factor=min_scale_factor,
                             max_scale_factor=max_scale_factor)
        ranked.append(replace(match, event="" if event is None else event[0]))
    if k > len(ranked):
        raise ParameterError(f"k = {k} but only {len(ranked)} records could be matched"
                             + (f" ({len(failures)} not: {failures})" if failures else ""))
    ranked.sort(key=lambda m: (m.misfit, m.id))
    chosen, capped = _capped(ranked, k, max_per_event)
    factors = np.array([m.factor for m in chosen])
    mean_h = np.mean([m.factor * m.sa_h for m in chosen], axis=0)
    ratio = mean_h / target_h
    suite_factor = 1.0
    if scale and suite_floor and ratio.min() < ASCE_SUITE_FLOOR:
        suite_factor = min(ASCE_SUITE_FLOOR / ratio.min(), max_scale_factor / factors.max())
        suite_factor = max(suite_factor, 1.0)
    if suite_factor != 1.0:
        chosen = [_rescaled(m, suite_factor, target_h, target_v, vertical_weight)
                  for m in chosen]
        mean_h = mean_h * suite_factor
        ratio = mean_h / target_h
    mean_v = None
    if target_v is not None:
        mean_v = np.mean([m.factor * m.sa_v for m in chosen], axis=0)
    i_min = int(np.argmin(ratio))
    options = {"k": k, "period_range_s": [ta, tb], "n_periods": n_periods,
               "horizontal": horizontal if azimuth is None else f"azimuth {azimuth:g} deg",
               "damping": damping, "scale": scale,
               "min_scale_factor": min_scale_factor, "max_scale_factor": max_scale_factor,
               "vertical_weight": vertical_weight if target_v is not None else 0.0,
               "target": target.source,
               "vertical_target": None if vertical_target is None else vertical_target.source,
               "max_per_event": max_per_event}
    return Selection(chosen, ranked, failures, periods, target_h, target_v, mean_h, mean_v,
                     float(ratio[i_min]), float(periods[i_min]), float(suite_factor),
                     bool(ratio[i_min] >= ASCE_SUITE_FLOOR * (1 - 1e-12)), options, capped)


def _capped(ranked, k, max_per_event):
    """The ``k`` best of ``ranked`` (best first) with at most ``max_per_event`` per earthquake,
    and the better-ranked records the cap left out (id -> earthquake)."""
    if max_per_event is None:
        return ranked[:k], {}
    chosen, left_out, count = [], {}, Counter()
    for m in ranked:
        if count[m.event] >= max_per_event:
            left_out[m.id] = m.event
            continue
        chosen.append(m)
        count[m.event] += 1
        if len(chosen) == k:
            break
    if len(chosen) < k:
        events = len({m.event for m in ranked})
        raise ParameterError(f"max_per_event = {max_per_event} (--max-per-event): the "
                             f"{len(ranked)} matched records come from {events} earthquake(s), so "
                             f"at most {len(chosen)} can be chosen, not k = {k} (-k)")
    return chosen, left_out


def _rescaled(m: RecordMatch, c: float, target_h, target_v, w) -> RecordMatch:
    """``m`` with its factor times ``c`` and the misfits at the new factor."""
    again = match_record(m.id, m.sa_h, m.sa_v, target_h / (m.factor * c), None if target_v is None
                         else target_v / (m.factor * c), vertical_weight=w, scale=False)
    return RecordMatch(m.id, m.factor * c, again.misfit, again.misfit_h, again.misfit_v,
                       m.sa_h, m.sa_v, m.bounded, m.event)


def _inline(value) -> str:
    if isinstance(value, dict):
        return "{" + ", ".join(f"{toml_value(str(k))} = {_inline(v)}"
                               for k, v in value.items()) + "}"
    return toml_value(value)


def _entry_lines(entry: CatalogueEntry, base: Path, extra: dict) -> list[str]:
    table = {"id": entry.id, "files": [relative_path(f, base) for f in entry.files]}
    if entry.inventory is not None:
        table["inventory"] = relative_path(entry.inventory, base)
    if entry.event is not None:
        table["event"] = relative_path(entry.event, base)
    for key in ("network", "station", "site", "license", "credit"):
        if getattr(entry, key):
            table[key] = getattr(entry, key)
    table["station"] = entry.station
    if entry.units:
        table["units"] = entry.units
    table.update({k: v for k, v in entry.extra.items() if not k.startswith("selection_")})
    table.update(extra)
    lines = ["[[record]]"] + [f"{k} = {_inline(v)}" for k, v in table.items()
                              if v is not None]
    if entry.components:
        lines += ["[record.components]"]
        lines += [f"{toml_value(k)} = {toml_value(v)}" for k, v in entry.components.items()]
    return lines + [""]


def selection_toml(selection: Selection, entries: dict, output) -> str:
    """The chosen suite as a catalogue TOML (paths relative to ``output``'s folder).

    Parameters
    ----------
    selection : Selection
    entries : dict
        The catalogue's entries (:func:`~shipblock.records.catalogue.load_catalogue`).
    output : str or os.PathLike
        Where it will be written.

    Returns
    -------
    str
    """
    base = Path(checks.pathname(output, "output", "the catalogue to write")).resolve().parent
    o = selection.options
    lines = [
        "# Records selected by 'shipblock select' (shipblock.risk.selection) for the target",
        f"# {o['target']} over {o['period_range_s'][0]:g} to {o['period_range_s'][1]:g} s "
        f"({o['horizontal']} horizontal"
        + (f"; vertical target {o['vertical_target']}, weight {o['vertical_weight']:g}"
           if o["vertical_target"] else "") + ").",
        ("# Scale factors bounded to " + format(o["min_scale_factor"], "g") + " .. "
         + format(o["max_scale_factor"], "g") if o["scale"] else
         "# Scale factors not applied (unscaled)")
        + f"; suite factor {selection.suite_factor:.4g}.",
        f"# Suite mean / target: lowest {selection.suite_ratio_min:.3f} at "
        f"{selection.suite_ratio_period:.3g} s: ASCE 7-16 §16.2.3 90 % check "
        f"{'passed' if selection.passes else 'FAILED'}.",
        *([f"# At most {o['max_per_event']} record(s) per earthquake (selection_event; "
           "shipblock.risk.selection.event_identity)."] if o.get("max_per_event") else []),
        "# selection_scale_factor is the factor that matches the target; a pipeline scales the "
        "records itself",
        "# to its IM levels (read this catalogue with ids = \"all\").",
        "", "schema_version = 1", "",
    ]
    for rank, m in enumerate(selection.chosen, start=1):
        extra = {"selection_rank": rank, "selection_scale_factor": m.factor,
                 "selection_misfit": m.misfit, "selection_misfit_h": m.misfit_h}
        if np.isfinite(m.misfit_v):
            extra["selection_misfit_v"] = m.misfit_v
        if m.event:
            extra["selection_event"] = m.event
        lines += _entry_lines(entries[m.id], base, extra)
    return "\n".join(lines)


def selection_lines(selection: Selection) -> list[str]:
    """What ``shipblock select`` prints: the suite, each record's factor and misfit, the check."""
    o = selection.options
    lines = [f"{len(selection.chosen)} of {len(selection.ranked)} records chosen "
             f"({o['horizontal']} horizontal"
             + (", with the vertical" if o["vertical_target"] else "")
             + f", {100 * o['damping']:g} % damping, "
             f"{o['period_range_s'][0]:g} to {o['period_range_s'][1]:g} s)"]
    header = f"  {'rank':>4}  {'record':<32} {'factor':>8} {'misfit':>8} {'misfit H':>9}"
    if o["vertical_target"]:
        header += f" {'misfit V':>9}"
    lines.append(header)
    for rank, m in enumerate(selection.chosen, start=1):
        row = (f"  {rank:>4}  {m.id:<32} {m.factor:>8.3f} {m.misfit:>8.3f} {m.misfit_h:>9.3f}")
        if o["vertical_target"]:
            row += f" {m.misfit_v:>9.3f}"
        if m.bounded:
            row += "  (factor at its bound)"
        lines.append(row)
    if o.get("max_per_event"):
        count = Counter(m.event for m in selection.chosen)
        lines.append(f"at most {o['max_per_event']} per earthquake: {len(count)} earthquake(s), "
                     + "; ".join(f"{n} from {event}" for event, n in count.items()))
        for record_id, event in selection.capped.items():
            lines.append(f"left out for max_per_event: {record_id} ({event})")
    if selection.suite_factor != 1.0:
        lines.append(f"suite factor {selection.suite_factor:.4g} applied to reach the 90 % floor")
    if not selection.passes and o["scale"]:
        lines.append(f"the factors cannot rise further: max_scale_factor = "
                     f"{o['max_scale_factor']:g} (--max-scale-factor; or choose other records)")
    lines.append(f"suite mean / target: lowest {selection.suite_ratio_min:.3f} at "
                 f"{selection.suite_ratio_period:.3g} s: ASCE 7-16 §16.2.3 90 % check "
                 f"{'passed' if selection.passes else 'FAILED'}")
    for record_id, why in selection.failures.items():
        lines.append(f"not used: {record_id}: {why}")
    return lines
