"""``shipblock report``: a study's report as HTML or PDF, with its tables as CSV beside it."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import xarray as xr

from shipblock import checks
from shipblock.errors import ParameterError
from shipblock.fragility.export import write_csv
from shipblock.report.document import (
    RISK,
    check_study,
    record_spectra,
    report_document,
    study_spectra,
)
from shipblock.report.html import render_html
from shipblock.report.pdf import write_pdf
from shipblock.scaling import TargetSpectrum

__all__ = ["REPORT_FORMATS", "write_report"]

#: Formats :func:`write_report` writes.
REPORT_FORMATS = ("html", "pdf")


def _open(path) -> xr.Dataset:
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such results file")
    try:
        with xr.open_dataset(path) as ds:
            return ds.load()
    except ValueError as exc:
        raise ParameterError(f"{path}: not a NetCDF results file ({exc})") from None


def _format(output: Path, format: str | None) -> str:  # noqa: A002 - the user's word
    if format is not None:
        return checks.choice(format, "format", REPORT_FORMATS)
    suffix = output.suffix.lower().lstrip(".")
    return suffix if suffix in REPORT_FORMATS else "html"


def write_report(results, output, *, hazard_results=None, target: TargetSpectrum | None = None,
                 period_range=None, format: str | None = None  # noqa: A002 - the user's word
                 ) -> list[Path]:
    """Write the report of a study (HTML or PDF, the same content) and its CSV tables.

    Parameters
    ----------
    results : str or os.PathLike
        NetCDF of ``shipblock run`` (or of ``shipblock risk``, which holds the study too).
    output : str or os.PathLike
        The report file; the tables go to the folder ``<output stem>_csv`` beside it.
    hazard_results : str or os.PathLike, optional
        NetCDF of ``shipblock risk`` for this study (the same pipeline fingerprint): its risk
        goes into the report and the tables.
    target : TargetSpectrum, optional
        Target spectrum to draw the records' spectra against
        (:func:`~shipblock.report.document.record_spectra`); default the study's own, if it
        matched one.
    period_range : (float, float), optional
        Periods of the match with ``target`` [s].
    format : {"html", "pdf"}, optional
        Default: from the suffix of ``output`` (``.pdf`` a PDF), else HTML.

    Returns
    -------
    list of Path
        The report, then the CSV tables.

    Raises
    ------
    ParameterError
        If a file is not a study result (named), the risk file belongs to another study, or
        ``format`` is not one of :data:`REPORT_FORMATS`.
    """
    output = Path(output)
    kind = _format(output, format)
    matplotlib.use("Agg")  # figures to files only; no display needed
    ds = _open(results)
    check_study(ds, str(results))
    if hazard_results is not None:
        risk = _open(hazard_results)
        check_study(risk, str(hazard_results))
        if RISK not in risk:
            raise ParameterError(f"{hazard_results}: holds no risk ({RISK}); make it with "
                                 "'shipblock risk'")
        mine, theirs = (d.attrs.get("pipeline_fingerprint") for d in (ds, risk))
        if mine != theirs:
            raise ParameterError(f"{hazard_results}: the risk of another study (pipeline "
                                 f"fingerprint {str(theirs)[:12]}..., {results} has "
                                 f"{str(mine)[:12]}...)")
        ds = risk
    spectra = None
    if target is not None:
        spectra = record_spectra(ds, target, period_range)
    elif "record_sa" in ds:
        spectra = study_spectra(ds)
    output.parent.mkdir(parents=True, exist_ok=True)
    csv = write_csv(ds, output.with_name(output.stem + "_csv"))
    links = {p.name: f"{p.parent.name}/{p.name}" for p in csv}
    blocks = report_document(ds, name=str(results), spectra=spectra, tables=links)
    partial = output.with_name(output.name + ".part")
    try:
        if kind == "pdf":
            write_pdf(blocks, partial, name=str(results))
        else:
            partial.write_text(render_html(blocks), encoding="utf-8")
    except BaseException:
        partial.unlink(missing_ok=True)
        raise
    partial.replace(output)
    return [output, *csv]
