"""From counts or stated units to m/s^2: instrument response removal and unit conversion.

:func:`to_si` converts one trace in place and says how: traces of formats that carry units are
already converted by their readers (:mod:`shipblock.io`); K-NET and Kinemetrics EVT counts are
scaled with the calibration obspy reads from their headers; raw counts are divided by the
overall sensitivity of a StationXML inventory (or of the response attached to the trace), or the
full response is removed (``response="full"``); otherwise the caller states the unit, or a SAC
file does. A velocity is differentiated to acceleration only when asked to
(``differentiate=True``). Nothing about units is guessed: an unknown unit is a
:class:`~shipblock.errors.UnitsError` naming the file.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from obspy import Trace

from shipblock.checks import how_to_pass
from shipblock.errors import ParameterError, RecordError, UnitsError
from shipblock.io import UNITS_GIVEN_KEY, check_count_value, sensitivity_sign
from shipblock.records.motion import SI_UNITS, trace_source
from shipblock.records.sensors import orientation_letter
from shipblock.units import (
    ACCELERATION_UNITS_TO_SI,
    VELOCITY_UNITS_TO_SI,
    canonical_unit,
    canonical_velocity_unit,
    si_factor,
)

__all__ = ["CALIB_IN_SI_FORMATS", "to_si"]

#: Formats whose ``stats.calib`` (set by obspy from the file header) is m/s^2 per count.
CALIB_IN_SI_FORMATS = {
    "KNET": "K-NET scale factor; the digitiser offset, the record's mean, removed as NIED states",
    "KINEMETRICS_EVT": "Kinemetrics EVT full scale and sensitivity",
}

#: SAC's dependent-variable codes (IDEP) that state a unit, and the unit (SAC manual: IACC is
#: nm/s^2, IVEL nm/s).
SAC_IDEP_UNITS = {8: "nm/s^2", 7: "nm/s"}

SAC_IDEP_NAMES = {8: "IACC", 7: "IVEL"}

#: How close to 1 the mean of a vertical may be to be taken for gravity in g [-].
GRAVITY_MEAN_TOLERANCE = 0.05


def _select_channel(trace: Trace, inventory, inventory_name):
    """The inventory's channel of a trace in force at the trace's start (its epoch)."""
    stats = trace.stats
    selected = inventory.select(
        network=stats.network,
        station=stats.station,
        location=stats.location,
        channel=stats.channel,
        time=stats.starttime,
    )
    channels = [ch for net in selected for sta in net for ch in sta]
    if not channels:
        raise RecordError(
            trace_source(trace),
            f"StationXML {inventory_name} has no channel {trace.id} at {stats.starttime}"
            " (inventory does not match the record)",
        )
    return channels[0]


def _input_unit(unit: str | None):
    """``(quantity, factor to SI)`` of a StationXML/SAC input unit, or ``(None, None)``."""
    acceleration = canonical_unit(unit or "")
    if acceleration is not None:
        return "acceleration", ACCELERATION_UNITS_TO_SI[acceleration]
    velocity = canonical_velocity_unit(unit)
    if velocity is not None:
        return "velocity", VELOCITY_UNITS_TO_SI[velocity]
    return None, None


def _differentiate(trace: Trace, how: str, differentiate: bool, name: str, what: str) -> str:
    """Differentiate a velocity trace [m/s] to acceleration [m/s^2] in place, if asked to."""
    if not differentiate:
        raise UnitsError(
            name,
            f"channel {trace.id} is a velocity record ({what});"
            f" {how_to_pass('differentiate', True)} to differentiate it to acceleration",
        )
    # Central differences inside, one-sided at the ends (obspy's Trace.differentiate).
    trace.data = np.gradient(np.asarray(trace.data, dtype=np.float64), trace.stats.delta)
    return how + "; velocity differentiated to acceleration (central differences)"


def _by_sensitivity(trace, response, source_label, differentiate, name, note=""):
    """Divide counts by a response's overall sensitivity; convert its input unit to SI."""
    sensitivity = response.instrument_sensitivity if response is not None else None
    value = None if sensitivity is None else sensitivity.value
    if value is None or not (math.isfinite(value) and value != 0):
        raise RecordError(
            name, f"{source_label} has no usable sensitivity for channel {trace.id}"
            f" (value {value!r}; a finite, non-zero number of counts per input unit is needed)"
        )
    input_units = sensitivity.input_units or ""
    quantity, factor = _input_unit(input_units)
    if quantity is not None:
        check_count_value(factor / value, name, f"{source_label}: channel {trace.id}'s sensitivity"
                                                f" {value:.6g} counts/({input_units})")
    # A negative sensitivity: a reversed channel if its stages agree, refused if they do not.
    note += sensitivity_sign(response, name, f"{source_label}: channel {trace.id}")
    if quantity is None:
        raise UnitsError(
            name, f"{source_label}: channel {trace.id} senses {input_units or 'unknown units'},"
            " which is neither an acceleration nor a velocity; "
            + how_to_pass("response", "full"),
        )
    trace.data = np.asarray(trace.data, dtype=np.float64) * (factor / value)
    how = (f"counts -> {'m/s**2' if quantity == 'acceleration' else 'm/s'} by the overall"
           f" sensitivity {value:.6g} counts/({input_units}) of {source_label}{note}")
    if quantity == "velocity":
        how = _differentiate(trace, how, differentiate, name, f"{source_label} senses {input_units}")
    return how


def _by_response(trace, inventory, inventory_name, response, differentiate) -> str:
    """Counts to m/s^2 with an inventory, or with the response attached to the trace."""
    name = trace_source(trace)
    if inventory is not None:
        channel = _select_channel(trace, inventory, inventory_name)
        resp, label = channel.response, f"StationXML {inventory_name}"
    else:
        resp, label = trace.stats.response, "the response attached to the stream"
    if response == "sensitivity":
        return _by_sensitivity(trace, resp, label, differentiate, name)
    if response != "full":
        raise ParameterError(f"response must be 'sensitivity' or 'full', not {response!r}")
    if resp is None or not resp.response_stages:
        # Strong-motion StationXML often holds the overall sensitivity only: with no stages there
        # is no frequency response to remove, and the sensitivity is all there is.
        return _by_sensitivity(
            trace, resp, label, differentiate, name,
            note=" (response='full' asked, but the response has no stages)",
        )
    trace.data = np.asarray(trace.data, dtype=np.float64)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Found more than one matching")
            if inventory is not None:
                # The channel of the record's epoch, not whichever epoch obspy finds first.
                trace.stats.response = resp
            trace.remove_response(output="ACC")
    except Exception as exc:  # noqa: BLE001 - obspy raises many kinds on bad responses
        raise RecordError(name, f"response of {trace.id} from {label} failed: {exc}") from exc
    return f"counts -> m/s**2 by the full response of {label} (obspy remove_response, output ACC)"


def _sac_unit(trace: Trace) -> tuple[str | None, str]:
    """The unit a SAC file states (KUSER0-2 unit word, else IDEP), and where it came from."""
    sac = trace.stats.get("sac") or {}
    for key in ("kuser0", "kuser1", "kuser2"):
        word = str(sac.get(key, "") or "").strip()
        if word and word != "-12345" and (canonical_unit(word) or canonical_velocity_unit(word)):
            return word, f"SAC {key.upper()}={word!r}"
    idep = sac.get("idep")
    if idep in SAC_IDEP_UNITS:
        return SAC_IDEP_UNITS[idep], f"SAC IDEP={idep} ({SAC_IDEP_NAMES[idep]})"
    return None, ""


def _check_gravity(trace: Trace, unit: str, origin: str, name: str) -> None:
    """Refuse a vertical whose mean is 1 in a unit where 1 g would be absurdly small."""
    letter = orientation_letter(trace.stats.channel)
    if letter != "Z" or unit != "nm/s^2":
        return
    mean = float(np.mean(np.asarray(trace.data, dtype=np.float64)))
    if abs(abs(mean) - 1.0) <= GRAVITY_MEAN_TOLERANCE:
        raise UnitsError(
            name,
            f"{origin} says the samples are in nm/s^2, but vertical channel {trace.id} averages"
            f" {mean:.4g}: that is gravity in g, not 1 nm/s^2 (Community Seismic Network files"
            " are written so); " + how_to_pass("units", "g"),
        )


def to_si(trace: Trace, inventory, inventory_name, units, response, differentiate=False) -> str:
    """Convert one trace to m/s^2 in place; return how it was done."""
    name = trace_source(trace)
    stats = trace.stats
    fmt = stats.get("_format", "")
    current = stats.get("units")
    if current == SI_UNITS:
        original = stats.get("original_units", SI_UNITS)
        key = canonical_unit(str(original))
        if units is not None and (key is None or si_factor(units, name)
                                  != ACCELERATION_UNITS_TO_SI[key]):
            raise UnitsError(name, f"units={units!r} contradicts the file's own unit {original!r}"
                                   " (leave out --units, catalogue key units)")
        if stats.get(UNITS_GIVEN_KEY):
            return f"{original} -> m/s**2 as given with --units (units={units!r})"
        if (stats.get("shipblock_smc") or {}).get("data_type_stated_by_caller"):
            return (f"{original} -> m/s**2 (SMC's unit); the file's data type '0 UNKNOWN' taken"
                    " for acceleration as stated with --data-type (data_type='acceleration')")
        return f"{original} -> m/s**2 from the file header ({fmt or 'stream'})"
    if current == "m/s" and (units is None or stats.get(UNITS_GIVEN_KEY)):
        original = stats.get("original_units", "m/s")
        if units is not None and canonical_velocity_unit(units) != canonical_velocity_unit(original):
            raise UnitsError(name, f"units={units!r} contradicts the file's own unit {original!r}"
                                   " (leave out --units, catalogue key units)")
        how = (f"{original} -> m/s as given with --units (units={units!r})"
               if stats.get(UNITS_GIVEN_KEY) else f"{original} -> m/s from the file header ({fmt})")
        how = _differentiate(trace, how, differentiate, name, "the file states velocity")
        stats.units = SI_UNITS
        return how
    if current == "m/s":
        raise UnitsError(name, f"units={units!r} contradicts the file's own unit"
                               f" {stats.get('original_units', 'm/s')!r} (a velocity)")
    if current not in (None, "counts"):
        raise UnitsError(name, f"channel {trace.id} has unsupported units {current!r}")

    has_response = inventory is not None or stats.get("response") is not None
    if has_response and fmt not in CALIB_IN_SI_FORMATS and units is None:
        how = _by_response(trace, inventory, inventory_name, response, differentiate)
        original = "counts"
    elif has_response and inventory is not None and units is not None:
        raise UnitsError(
            name, "both an inventory (--inventory) and units= (--units) were given for raw data;"
            " give one of them"
        )
    elif fmt in CALIB_IN_SI_FORMATS:
        if units is not None:
            raise UnitsError(
                name, f"{fmt} records carry their own calibration; do not give units= (--units,"
                " catalogue key units)"
            )
        check_count_value(stats.calib, name, f"the {CALIB_IN_SI_FORMATS[fmt]} (calibration"
                                             f" {stats.calib!r} m/s^2 per count)")
        trace.data = np.asarray(trace.data, dtype=np.float64) * stats.calib
        how = f"counts -> m/s**2 by stats.calib={stats.calib:.6g} ({CALIB_IN_SI_FORMATS[fmt]})"
        stats.calib = 1.0
        original = "counts"
    else:
        origin = "the caller's units="
        if units is None and fmt == "SAC":
            units, origin = _sac_unit(trace)
            if units is not None:
                _check_gravity(trace, units, origin, name)
        if units is None:
            raise UnitsError(
                name,
                f"units of channel {trace.id} are unknown ({fmt or 'stream'} data"
                f"{', raw counts' if current == 'counts' else ''}): for raw counts"
                f" {how_to_pass('inventory', 'STATIONXML', placeholder=True)}; otherwise state"
                f" the unit: {how_to_pass('units', 'UNIT', placeholder=True)}, UNIT one of"
                " m/s^2, cm/s^2, gal, g, or a velocity unit m/s, cm/s with --differentiate",
            )
        data = np.asarray(trace.data, dtype=np.float64)
        prefix = ""
        if stats.calib != 1.0:
            velocity = canonical_velocity_unit(units)
            unit_si = (VELOCITY_UNITS_TO_SI[velocity] if velocity is not None
                       else si_factor(units, name))
            check_count_value(stats.calib * unit_si, name,
                              f"the {'SAC SCALE' if fmt == 'SAC' else 'calibration'}"
                              f" {stats.calib!r} ({units} per count)")
            data = data * stats.calib
            prefix = f"calib {stats.calib:g} from the {fmt or 'stream'} header, then "
            stats.calib = 1.0
        velocity = canonical_velocity_unit(units)
        if velocity is not None:
            factor = VELOCITY_UNITS_TO_SI[velocity]
            trace.data = data * factor
            how = prefix + f"{units} -> m/s as stated by {origin} (x{factor:g})"
            how = _differentiate(trace, how, differentiate, name, f"{origin} gives {units}")
        else:
            factor = si_factor(units, name)
            trace.data = data * factor
            how = prefix + f"{units} -> m/s**2 as stated by {origin} (x{factor:g})"
        original = units
    stats.units = SI_UNITS
    stats.original_units = stats.get("original_units", original)
    return how
