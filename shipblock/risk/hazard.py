r"""Site hazard curves: annual rate of exceedance against an intensity measure.

A hazard curve gives, for a site, the mean annual rate :math:`\lambda_{IM}(x)` [1/yr] at which
the intensity measure exceeds :math:`x`. :func:`read_hazard_curve` reads one from four layouts
and returns a :class:`HazardCurve` in SI units (m/s^2 for PGA and Sa, m/s for PGV), with the
measure it is for and the file's provenance (path, SHA-256, layout, site):

``openquake``
    An OpenQuake engine hazard-curve export (``hazard_curve-mean-PGA.csv`` and the like): a
    comment line ``# ... investigation_time=50.0, imt='PGA'`` (the older exports write
    ``imt="PGA"``), a header ``lon,lat[,depth],poe-0.005,...`` and one row per site holding the
    probabilities of exceedance in the investigation time :math:`T`, converted to rates by the
    Poisson assumption :math:`\lambda = -\ln(1 - p)/T`. Levels are in g (PGA, SA) or cm/s (PGV),
    the OpenQuake units. A probability of 1 (an infinite rate) is left out with its level.
``nshmp-csv``
    A USGS nshmp-haz ``HazardCalc``/``DeaggCalc`` curve file (``curves/PGA/total.csv``): header
    ``[name,]lon,lat,<level>,...`` with the levels in g (cm/s for PGV), one row per site. The
    file does not name its measure: it is the name of its folder (``PGA``, ``SA0P2``, ``SA1P0``,
    ``PGV``) unless ``measure`` is given. The values are annual rates unless the run's
    ``config.json`` (looked for in the folder above, as nshmp-haz writes it) says
    ``"valueFormat": "POISSON_PROBABILITY"``, which is refused (its time span is not stated in
    the file).
``usgs-json``
    The JSON of the USGS hazard web services behind the Unified Hazard Tool, in either
    generation: nshmp-haz-ws ``/hazard`` (``{"response": [{"metadata": {"imt": {"value":
    "PGA"}, "xlabel": "Ground Motion (g)", "ylabel": "Annual Frequency of Exceedence",
    "xvalues": [...], "longitude", "latitude", "vs30", ...}, "data": [{"component": "Total",
    "yvalues": [...]}, ...]}, ...]}``, one response per IMT) or nshmp-haz 2's hazard service
    (``{"request": {"longitude", "latitude", "vs30", "truncate", "maxdir"}, "response":
    {"metadata": {"xlabel", "ylabel"}, "hazardCurves": [{"imt": {"value": "PGA"}, "data":
    [{"component": "Total", "values": {"xs": [...], "ys": [...]}}]}]}}``); the ``Total``
    component is used. The layouts are those of the services' source code (``HazardService``
    of nshmp-haz-ws and of nshmp-haz 2). ``maxdir`` (levels scaled to the maximum direction)
    and ``truncate`` (the curve cut where its rate falls below 1e-4) are kept in the
    provenance: a curve cut at 1e-4 leaves the rarer levels to the extended end slope
    (see ``risk_tail_fraction``).
``table``
    Two columns with units in the header, e.g. ``PGA [g], annual_rate [1/yr]`` or
    ``Sa(1.0) [m/s^2], poe_50yr [-]`` (probability of exceedance in 50 years); comma,
    semicolon or white space separated; ``#`` starts a comment.

Not read: a CSV saved from the USGS Unified Hazard Tool. No real example or description of
such a file was found (the tool's archived source has no CSV export of curves; the
``nshmp-haz-ws`` web apps' CSV is another tool's and names no measure): read the JSON of its
services (``usgs-json``) or a ``table`` instead.

Rates must not increase with the level; levels must increase. A file with several sites needs
``site`` (a name, or ``(lon, lat)`` in degrees matched within 0.001 deg).

References
----------
.. [1] Pagani, M. et al. (2014). OpenQuake engine: an open hazard (and risk) software for the
   Global Earthquake Model. *Seismol. Res. Lett.* 85(3), 692-702.
.. [2] Petersen, M. D. et al. (2008). Documentation for the 2008 update of the United States
   National Seismic Hazard Maps. USGS Open-File Report 2008-1128.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from shipblock import checks
from shipblock.errors import ParameterError, RecordError
from shipblock.units import ACCELERATION_UNITS_TO_SI, VELOCITY_UNITS_TO_SI

__all__ = [
    "HAZARD_FORMATS",
    "HazardCurve",
    "HazardError",
    "parse_measure",
    "read_hazard_curve",
]

#: Layouts :func:`read_hazard_curve` reads (``"auto"`` picks one from the file).
HAZARD_FORMATS = ("openquake", "nshmp-csv", "usgs-json", "table")

#: Unit of the levels of OpenQuake and USGS files, by measure.
_AGENCY_UNITS = {"pga": "g", "sa": "g", "pgv": "cm/s"}

#: Tolerance of a period match [s] (periods are written with a few decimals).
_PERIOD_TOLERANCE = 1e-6

#: Tolerance of a site match by coordinates [deg].
_SITE_TOLERANCE = 1e-3


class HazardError(RecordError):
    """A hazard curve file cannot be read or does not fit the study; the message names the file."""


@dataclass(frozen=True)
class HazardCurve:
    """Annual rate of exceedance of an intensity measure at one site.

    Attributes
    ----------
    im : numpy.ndarray
        Intensity levels [SI: m/s^2 for PGA and Sa, m/s for PGV], increasing, shape ``(n,)``.
    rate : numpy.ndarray
        Mean annual rate of exceedance :math:`\\lambda(x)` of each level [1/yr], non-increasing.
    measure : str
        ``"pga"``, ``"pgv"`` or ``"sa"``.
    period : float or None
        Oscillator period of Sa [s] (``None`` for PGA and PGV).
    source_units : str
        Unit of the levels in the file (``"g"``, ``"cm/s"``, ...).
    provenance : dict
        ``file``, ``sha256``, ``format``, ``site`` and what the file says about itself
        (investigation time, model, Vs30, ...): strings and numbers only.
    """

    im: np.ndarray
    rate: np.ndarray
    measure: str
    period: float | None
    source_units: str
    provenance: dict = field(default_factory=dict)

    @property
    def label(self) -> str:
        """The measure as written in hazard files: ``PGA``, ``PGV`` or ``SA(1.0 s)``."""
        return describe_measure(self.measure, self.period)


def describe_measure(measure: str, period: float | None) -> str:
    """``"PGA"``, ``"PGV"`` or ``"SA(T s)"`` for a measure and period."""
    return f"SA({period:g} s)" if measure == "sa" else measure.upper()


def parse_measure(text: str, source) -> tuple[str, float | None]:
    """Measure and period of an IMT name: ``PGA``, ``PGV``, ``SA(0.2)``, ``SA0P2``, ``Sa(1.0 s)``.

    Parameters
    ----------
    text : str
        The name as a hazard file writes it (case-insensitive).
    source : str or os.PathLike
        The file, for the error message.

    Returns
    -------
    measure : str
        ``"pga"``, ``"pgv"`` or ``"sa"``.
    period : float or None
        [s] for Sa.

    Raises
    ------
    HazardError
        For a name that is none of these.
    """
    name = text.strip().strip("'\"").replace(" ", "").lower()
    if name in ("pga", "pgv"):
        return name, None
    m = re.fullmatch(r"sa\(?([0-9]+(?:[.p][0-9]+)?)s?\)?", name)
    if m:
        period = float(m.group(1).replace("p", "."))
        if checks.MIN_PERIOD <= period <= checks.MAX_PERIOD:
            return "sa", period
    raise HazardError(source, f"intensity measure {text!r} is not one shipblock knows (PGA, PGV, "
                              "SA(T) or SA<T with P for the point>, e.g. SA0P2)")


def _levels_to_si(levels, unit: str, measure: str, source) -> np.ndarray:
    table = VELOCITY_UNITS_TO_SI if measure == "pgv" else ACCELERATION_UNITS_TO_SI
    kind = "a velocity" if measure == "pgv" else "an acceleration"
    factor = table.get(unit.strip().lower())
    if factor is None:
        raise HazardError(source, f"unit {unit!r} of the levels is not {kind} (the measure "
                                  f"{measure.upper()} is {kind}); known: {', '.join(sorted(table))}")
    return np.asarray(levels, dtype=float) * factor


def _curve(levels, rates, measure, period, unit, source, provenance) -> HazardCurve:
    """Check and convert one curve: levels increasing and positive, rates finite, non-increasing."""
    x = np.asarray(levels, dtype=float)
    y = np.asarray(rates, dtype=float)
    if x.size < 2:
        raise HazardError(source, f"a hazard curve needs at least 2 levels, got {x.size}")
    if not (np.all(np.isfinite(x)) and np.all(x > 0.0) and np.all(np.diff(x) > 0.0)):
        raise HazardError(source, "the intensity levels must be positive and increasing")
    if not (np.all(np.isfinite(y)) and np.all(y >= 0.0)):
        raise HazardError(source, "the rates of exceedance must be finite and non-negative")
    if np.any(np.diff(y) > 1e-9 * np.max(y)):
        i = int(np.argmax(np.diff(y) > 1e-9 * np.max(y)))
        raise HazardError(source, f"the rate of exceedance increases from level {x[i]:g} to "
                                  f"{x[i + 1]:g} {unit}: not a hazard curve")
    if not np.any(y > 0.0):
        raise HazardError(source, "every rate of exceedance is zero (no hazard at this site)")
    return HazardCurve(_levels_to_si(x, unit, measure, source), y, measure, period, unit,
                       provenance)


def _select_site(sites: list[tuple[str, float, float]], site, source) -> int:
    """Index of the wanted site among (name, lon, lat)."""
    shown = "; ".join(f"{n or '-'} ({lon:g}, {lat:g})" for n, lon, lat in sites[:20])
    if site is None:
        if len(sites) == 1:
            return 0
        raise HazardError(source, f"holds {len(sites)} sites; choose one with site (--site: a "
                                  f"name or lon,lat): {shown}")
    if isinstance(site, str) and "," in site and not any(n == site for n, _, _ in sites):
        try:
            site = tuple(float(v) for v in site.split(","))
        except ValueError:
            pass
    if isinstance(site, str):
        hits = [i for i, (n, _, _) in enumerate(sites) if n.strip().lower() == site.strip().lower()]
    else:
        try:
            lon, lat = (float(v) for v in site)
        except (TypeError, ValueError):
            raise ParameterError(f"site must be a name or (lon, lat) [deg], got {site!r}") from None
        hits = [i for i, (_, x, y) in enumerate(sites)
                if abs(x - lon) <= _SITE_TOLERANCE and abs(y - lat) <= _SITE_TOLERANCE]
    if len(hits) != 1:
        raise HazardError(source, f"site {site!r} is not in the file{' once' if hits else ''}; "
                                  f"sites: {shown}")
    return hits[0]


def _read_openquake(text, source, site, measure_hint):
    lines = text.splitlines()
    head = lines[0]
    imt = re.search(r"imt\s*=\s*['\"]?([A-Za-z]+(?:\([0-9.]+\))?)", head)
    span = re.search(r"investigation_time\s*=\s*([0-9.eE+-]+)", head)
    if imt is None or span is None:
        raise HazardError(source, "the OpenQuake comment line names no imt or investigation_time")
    measure, period = parse_measure(imt.group(1), source)
    t_years = float(span.group(1))
    if not t_years > 0.0:
        raise HazardError(source, f"investigation_time {t_years} must be positive [yr]")
    rows = list(csv.reader(lines[1:]))
    header = [h.strip() for h in rows[0]]
    poe_cols = [i for i, h in enumerate(header) if h.startswith("poe-")]
    if not poe_cols or header[:2] != ["lon", "lat"]:
        raise HazardError(source, "the header must be lon,lat[,depth],poe-<level>,...")
    levels = [float(header[i][4:]) for i in poe_cols]
    body = [r for r in rows[1:] if r]
    sites = [("", float(r[0]), float(r[1])) for r in body]
    k = _select_site(sites, site, source)
    poe = np.array([float(body[k][i]) for i in poe_cols])
    if np.any((poe < 0.0) | (poe > 1.0)):
        raise HazardError(source, "probabilities of exceedance must be in [0, 1]")
    keep = poe < 1.0
    with np.errstate(divide="ignore"):
        rate = -np.log1p(-poe[keep]) / t_years
    provenance = {"investigation_time_yr": t_years, "imt": imt.group(1),
                  "site": f"({sites[k][1]:g}, {sites[k][2]:g})",
                  "levels_dropped_poe_1": int(np.count_nonzero(~keep))}
    kind = re.search(r"kind\s*=\s*'([^']*)'", head)
    if kind:
        provenance["statistic"] = kind.group(1)
    engine = re.search(r"generated_by\s*=\s*'([^']*)'", head)
    if engine:
        provenance["generated_by"] = engine.group(1)
    return (np.asarray(levels)[keep], rate, measure, period, _AGENCY_UNITS[measure], provenance)


def _nshmp_config(path: Path) -> dict:
    for folder in (path.parent, path.parent.parent):
        config = folder / "config.json"
        if config.is_file():
            try:
                return json.loads(config.read_text())
            except (OSError, ValueError):
                return {}
    return {}


def _read_nshmp(text, source, site, measure_hint):
    path = Path(source)
    rows = [r for r in csv.reader(io.StringIO(text)) if r]
    header = [h.strip() for h in rows[0]]
    first = 1 if header[0] == "name" else 0
    if header[first:first + 2] != ["lon", "lat"]:
        raise HazardError(source, "the header must be [name,]lon,lat,<level>,...")
    levels = [float(h) for h in header[first + 2:]]
    try:  # nshmp-haz writes each measure's curves into a folder named after it
        imt_name = path.parent.name
        measure, period = parse_measure(imt_name, source)
    except HazardError:
        if measure_hint is None:
            raise HazardError(source, f"an nshmp-haz curve file does not name its measure and "
                                      f"its folder {path.parent.name!r} is not one (PGA, SA0P2, "
                                      "...): give the measure") from None
        imt_name = measure_hint
        measure, period = parse_measure(imt_name, source)
    config = _nshmp_config(path)
    hazard = config.get("hazard", {}) if isinstance(config, dict) else {}
    value_format = hazard.get("valueFormat", "ANNUAL_RATE")
    if value_format != "ANNUAL_RATE":
        raise HazardError(source, f"valueFormat {value_format!r} in the run's config.json: only "
                                  "ANNUAL_RATE curves are read (a probability's time span is not "
                                  "in the file)")
    sites = [(r[0] if first else "", float(r[first]), float(r[first + 1])) for r in rows[1:]]
    k = _select_site(sites, site, source)
    rate = [float(v) for v in rows[1 + k][first + 2:]]
    provenance = {"imt": imt_name, "site": sites[k][0] or f"({sites[k][1]:g}, {sites[k][2]:g})",
                  "longitude": sites[k][1], "latitude": sites[k][2], "value_format": value_format}
    vs30 = config.get("site", {}).get("vs30") if isinstance(config, dict) else None
    if vs30 is not None:
        provenance["vs30_m_s"] = float(vs30)
    if hazard.get("exceedanceModel"):
        provenance["exceedance_model"] = str(hazard["exceedanceModel"])
    return (levels, rate, measure, period, _AGENCY_UNITS[measure], provenance)


def _imt_name(imt) -> str | None:
    """The IMT of a service's ``imt`` entry: ``{"value": "PGA", ...}`` or a plain string."""
    name = imt.get("value") if isinstance(imt, dict) else imt
    return None if name is None else str(name)


def _usgs_curves(doc, source) -> tuple[dict, dict, dict]:
    """IMT -> (levels, rates, units) of a USGS hazard service response, its site and labels.

    Two generations of the service: nshmp-haz-ws (``response`` a list, one entry per IMT with
    ``metadata.xvalues`` and ``data[].yvalues``) and nshmp-haz 2 (``response.hazardCurves``,
    one entry per IMT with ``data[].values.xs``/``ys``; site and Vs30 in ``request``).
    """
    response = doc.get("response") if isinstance(doc, dict) else None
    curves, site, labels = {}, {}, {}
    if isinstance(response, dict) and "hazardCurves" in response:
        meta = response.get("metadata", {}) or {}
        labels = {"xlabel": meta.get("xlabel", ""), "ylabel": meta.get("ylabel", "")}
        request = doc.get("request", {}) or {}
        site = {k: request.get(k) for k in ("longitude", "latitude", "vs30", "maxdir",
                                            "truncate") if k in request}
        for entry in response["hazardCurves"]:
            name = _imt_name(entry.get("imt"))
            total = [c for c in entry.get("data", [])
                     if str(c.get("component", "")).lower() == "total"]
            if name and total:
                values = total[0]["values"]
                curves[name] = (values["xs"], values["ys"])
        return curves, site, labels
    if isinstance(response, dict):
        response = [response]
    if not isinstance(response, list):
        raise HazardError(source, "not a USGS hazard service response (no 'response' list or "
                                  "'response.hazardCurves')")
    for entry in response:
        meta = entry.get("metadata", {}) or {}
        name = _imt_name(meta.get("imt"))
        total = [c for c in entry.get("data", [])
                 if str(c.get("component", "")).lower() == "total"]
        if name and total:
            curves[name] = (meta["xvalues"], total[0]["yvalues"])
            labels = {"xlabel": meta.get("xlabel", ""), "ylabel": meta.get("ylabel", "")}
            site = {"longitude": meta.get("longitude"), "latitude": meta.get("latitude")}
            for key in ("edition", "region", "vs30"):
                value = meta.get(key)
                if isinstance(value, dict):
                    value = value.get("display") or value.get("value")
                if value is not None:
                    site[key] = value
    return curves, site, labels


def _read_usgs_json(text, source, site, measure_hint):
    try:
        doc = json.loads(text)
    except ValueError:
        raise HazardError(source, "is not JSON") from None
    found, where, labels = _usgs_curves(doc, source)
    if not found:
        raise HazardError(source, "holds no curve with an imt and a 'Total' component")
    if measure_hint is None:
        if len(found) > 1:
            raise HazardError(source, f"holds curves for {', '.join(found)}: choose one with "
                                      "measure")
        name = next(iter(found))
    else:
        wanted = parse_measure(measure_hint, source)
        names = [n for n in found if parse_measure(n, source) == wanted]
        if not names:
            raise HazardError(source, f"holds no curve for {measure_hint}; it has "
                                      f"{', '.join(found)}")
        name = names[0]
    levels, rates = found[name]
    measure, period = parse_measure(name, source)
    unit = re.search(r"\(([^)]+)\)", str(labels.get("xlabel", "")))
    unit = unit.group(1) if unit else _AGENCY_UNITS[measure]
    ylabel = str(labels.get("ylabel", ""))
    if ylabel and "annual" not in ylabel.lower():
        raise HazardError(source, f"ylabel {ylabel!r}: only annual rates of exceedance are read")
    lon, lat = where.get("longitude"), where.get("latitude")
    provenance = {"imt": name, "site": f"({lon}, {lat})"}
    provenance.update({k: (v if isinstance(v, bool | int | float) else str(v))
                       for k, v in where.items() if k not in ("longitude", "latitude")})
    if site is not None:
        _select_site([("", float(lon if lon is not None else math.nan),
                       float(lat if lat is not None else math.nan))], site, source)
    return (levels, rates, measure, period, unit, provenance)


_TABLE_HEADER = re.compile(r"^\s*([^\[\]]+?)\s*\[([^\]]+)\]\s*$")


def _read_table(text, source, site, measure_hint):
    lines = [ln.split("#", 1)[0].strip() for ln in text.splitlines()]
    lines = [ln for ln in lines if ln]
    if len(lines) < 3:
        raise HazardError(source, "a two-column table needs a header and at least 2 rows")
    split = re.compile(r"\s*[,;\t]\s*|\s{2,}")
    header = [h for h in split.split(lines[0]) if h]
    if len(header) != 2:
        raise HazardError(source, f"the header must name two columns with units, e.g. "
                                  f"'PGA [g], annual_rate [1/yr]', got {lines[0]!r}")
    parts = [_TABLE_HEADER.match(h) for h in header]
    if not all(parts):
        raise HazardError(source, f"each header column needs its unit in brackets, e.g. "
                                  f"'PGA [g], annual_rate [1/yr]', got {lines[0]!r}")
    (im_name, unit), (y_name, y_unit) = (p.groups() for p in parts)
    measure, period = parse_measure(im_name, source)
    if measure_hint is not None and parse_measure(measure_hint, source) != (measure, period):
        raise HazardError(source, f"the table is for {im_name}, not {measure_hint}")
    rows = []
    for n, line in enumerate(lines[1:], start=2):
        cells = [c for c in re.split(r"[,;\s]+", line) if c]
        try:
            rows.append((float(cells[0]), float(cells[1])))
        except (IndexError, ValueError):
            raise HazardError(source, f"line {n} of the data is not two numbers: {line!r}") \
                from None
    x, y = np.array(rows).T
    provenance = {"columns": f"{header[0]}; {header[1]}"}
    poe = re.fullmatch(r"poe_?(\d+(?:\.\d*)?)\s*_?(?:yr|y|years?)", y_name.strip().lower())
    if poe:
        t_years = float(poe.group(1))
        if np.any((y < 0.0) | (y >= 1.0)):
            raise HazardError(source, "probabilities of exceedance must be in [0, 1)")
        y = -np.log1p(-y) / t_years
        provenance["investigation_time_yr"] = t_years
    elif y_unit.replace(" ", "").lower() not in ("1/yr", "1/year", "/yr", "per_year", "1/y"):
        raise HazardError(source, f"the second column must be an annual rate '[1/yr]' or a "
                                  f"probability 'poe_<T>yr [-]', got {header[1]!r}")
    return (x, y, measure, period, unit.strip(), provenance)


_READERS = {"openquake": _read_openquake, "nshmp-csv": _read_nshmp,
            "usgs-json": _read_usgs_json, "table": _read_table}


def _detect(text: str, source) -> str:
    head = text.lstrip()[:2000]
    if head.startswith("{"):
        return "usgs-json"
    first = head.splitlines()[0] if head else ""
    if first.startswith("#") and "investigation_time" in first:
        return "openquake"
    if re.match(r"^(name\s*,\s*)?lon\s*,\s*lat\s*,", first):
        return "nshmp-csv"
    return "table"


def read_hazard_curve(path, *, format: str = "auto", site=None, measure: str | None = None
                      ) -> HazardCurve:  # noqa: A002 - 'format' is the user's word for it
    """Read a site hazard curve (see the module text for the layouts).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    format : {"auto", "openquake", "nshmp-csv", "usgs-json", "table"}
        Its layout; ``"auto"`` tells them apart by their first line.
    site : str or tuple of float, optional
        For a file with several sites: the site's name (nshmp-haz) or ``(lon, lat)`` [deg]
        (also as the string ``"lon,lat"``).
    measure : str, optional
        The IMT (``"PGA"``, ``"SA1P0"``, ``"SA(1.0)"``): required for an nshmp-haz file outside
        its IMT folder and for a USGS JSON holding several IMTs; elsewhere checked against the
        file.

    Returns
    -------
    HazardCurve
        Levels in SI, annual rates, the measure, and the provenance (``file``, ``sha256``,
        ``format``, ``site``, ...).

    Raises
    ------
    HazardError
        Naming the file: missing, unreadable, not in the layout, unknown measure or unit, a
        curve that is not one (levels not increasing, rates increasing), an unknown site.
    """
    source = checks.existing_file(path, "hazard", "a hazard curve file")
    fmt = checks.choice(format, "format", ("auto", *HAZARD_FORMATS))
    raw = Path(source).read_bytes()
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise HazardError(source, "is not a text file (UTF-8)") from None
    if not text.strip():
        raise HazardError(source, "is empty")
    if fmt == "auto":
        fmt = _detect(text, source)
    try:
        x, y, meas, period, unit, provenance = _READERS[fmt](text, source, site, measure)
    except (IndexError, KeyError, ValueError) as exc:
        if isinstance(exc, (HazardError, ParameterError)):
            raise
        raise HazardError(source, f"is not a {fmt} hazard curve: {exc}") from None
    if measure is not None and fmt != "usgs-json" and parse_measure(measure, source) != (
            meas, period):
        raise HazardError(source, f"is a curve for {describe_measure(meas, period)}, not "
                                  f"{measure}")
    provenance = {"file": str(Path(source).resolve()),
                  "sha256": hashlib.sha256(raw).hexdigest(), "format": fmt, **provenance}
    return _curve(x, y, meas, period, unit, source, provenance)
