"""The commands of risk: ``shipblock risk`` (a study's fragilities with a site hazard, over a
docking period) and ``shipblock select`` (the records that best match a target spectrum)."""

from __future__ import annotations

import sys
from pathlib import Path

from shipblock.cli._common import _save_figure
from shipblock.cli.reading import _processing_chain


def cmd_risk(args):
    from shipblock.risk.study import risk_lines, run_risk

    ds = run_risk(args.results, args.hazard, args.days, output=args.output, site=args.site,
                  format=args.format, measure=args.measure, band=not args.no_band)
    out = sys.stdout
    out.write(f"risk written to {ds.encoding['source']}\n")
    for line in risk_lines(ds, args.target_probability):
        out.write(line + "\n")
    if args.figure:
        from shipblock.plot_risk import plot_risk

        _save_figure(lambda: plot_risk(ds)[0].figure, args.figure)
        out.write(f"figure written to {args.figure}\n")
    return 0


def cmd_select(args):
    from shipblock.records.catalogue import load_catalogue
    from shipblock.risk.selection import (
        select_records,
        selection_lines,
        selection_toml,
        target_from_file,
    )

    entries = load_catalogue(args.catalogue)
    processing = [] if args.no_processing else _selection_chain(args.processing)
    target = target_from_file(args.target, args.units)
    vertical = (None if args.vertical_target is None
                else target_from_file(args.vertical_target, args.vertical_units or args.units))
    selection = select_records(
        entries, target, args.k, period_range=args.period_range, vertical_target=vertical,
        vertical_weight=args.vertical_weight, scale=not args.no_scale,
        min_scale_factor=args.min_scale_factor, max_scale_factor=args.max_scale_factor,
        horizontal=args.horizontal, azimuth=args.azimuth,
        processing=processing, max_per_event=args.max_per_event,
        damping=args.damping, n_periods=args.n_periods, ids=args.ids,
        suite_floor=not args.no_suite_floor)
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    partial = output.with_name(output.name + ".part")
    partial.write_text(selection_toml(selection, entries, output))
    try:
        load_catalogue(partial)  # what is written reads back
    except Exception:
        partial.unlink()
        raise
    partial.replace(output)
    sys.stdout.write(f"selection written to {output}\n")
    for line in selection_lines(selection):
        sys.stdout.write(line + "\n")
    return 0


def _selection_chain(spec):
    """The chain of ``select --processing`` (None: the default chain): a file's steps checked
    as a pipeline's are, an error naming the file and the step, before any record is read
    (else every record would fail alike, one by one)."""
    from shipblock.fragility.schema import _processing

    if spec is None:
        return None
    chain = _processing_chain(spec)
    if spec not in ("default", "none", "demean"):
        _processing({"processing": chain}, f"--processing {spec}")
    return chain
