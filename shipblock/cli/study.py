"""The commands of a study: ``shipblock run`` (a pipeline), ``history`` (one of its runs again,
in full), ``plot`` (a figure of a results file), ``export`` (its CSV tables) and ``report`` (its
HTML or PDF report)."""

from __future__ import annotations

import sys
from pathlib import Path

from shipblock.cli._common import UserError, _save_figure
from shipblock.cli.simulate import (
    _events_report,
    _report,
    _response_figure,
    _response_figure_option,
    _write_response,
)


def _parse_assignments(items):
    """``["mu_ground=0.4", "cap_material=white_oak"]`` -> ``{"mu_ground": 0.4, "cap_material":
    "white_oak"}``: a number where the text is one, else the text (a name of a string
    dimension, checked against the study's values where it is used)."""
    values = {}
    for item in items or []:
        name, sep, text = item.partition("=")
        if not sep or not name.strip() or not text.strip():
            raise UserError(f"--set expects NAME=VALUE, got {item!r}")
        try:
            values[name.strip()] = float(text)
        except ValueError:
            values[name.strip()] = text.strip()
    return values


def cmd_history(args):
    from shipblock.fragility.pipeline import _rerun
    from shipblock.plot import dataset_record_line, run_name

    if args.im_level is not None and args.im_level_g is not None:
        raise UserError("give --im-level or --im-level-g, not both")
    ds, res = _rerun(args.pipeline, args.record, im_level=args.im_level,
                     im_level_g=args.im_level_g, **_parse_assignments(args.set))
    name = ds.attrs["record"]
    level = ""
    if "im_level" in ds.attrs:
        level = f" at {run_name(ds).rsplit(', ', 1)[-1]}"
    sys.stdout.write(f"run {ds.attrs['case']} of {args.pipeline}: {name}{level}, scale factor "
                     f"{ds.attrs['scale_factor']:.4g}\n")
    if hasattr(res, "ground_acceleration"):  # the rigid model's SimulationResult
        _report(res, name, args.events)
    else:
        _model_report(res, ds, args.events)
    record = dataset_record_line(ds)
    ds.attrs["record_description"] = record
    if args.output:
        _write_response(ds, args.output)
    _response_figure_option(res, record, args.figure, args.output)
    return 0


def _model_report(res, ds, max_events):
    """Print the outputs of a run of any model (with their units) and its events."""
    from shipblock.fragility.store import dataset_model

    model = dataset_model(ds)
    out = sys.stdout
    names = list(model.outputs) if model is not None else list(res.summary)
    width = max(map(len, names))
    for name in names:
        value = res.summary.get(name)
        units = model.outputs[name][0] if model is not None else ""
        if isinstance(value, float) and model is not None and name == "failure":
            value = f"{value:g} ({model.failure_codes.get(int(value), '?')})"
        elif isinstance(value, float):
            value = f"{value:.6g}"
        out.write(f"{name:<{width}}  {value} {'' if units in ('', '1') else units}\n")
    _events_report(getattr(res, "events", []), max_events)


def cmd_run(args):
    from shipblock.fragility.filesystem import output_name_problem
    from shipblock.fragility.pipeline import run_pipeline

    if args.output and (problem := output_name_problem(args.output)) is not None:
        raise UserError(f"--output {args.output}: {problem}")
    ds = run_pipeline(args.pipeline, output=args.output, scheduler=args.scheduler,
                      progress=not args.quiet, wait=args.wait)
    out = sys.stdout
    out.write(f"results written to {ds.encoding.get('source', args.output or 'the pipeline output')}\n")
    from shipblock.fragility.report import study_report

    for line in study_report(ds):
        out.write(line + "\n")
    if "history_file" in ds:
        n = int((ds["history_file"] != "").sum())
        folder = Path(ds.encoding.get("source", ".")).parent / ds.attrs["histories_directory"]
        out.write(f"{n} time histories written to {folder} "
                  "(listed in the variable history_file; draw one with 'shipblock plot')\n")
    if args.figure:
        from shipblock.plot import plot_fragility

        _save_figure(lambda: plot_fragility(ds).figure, args.figure)
        out.write(f"figure written to {args.figure}\n")
    return 0


def cmd_plot(args):
    import xarray as xr

    with xr.open_dataset(args.results) as ds:
        ds = ds.load()
    figure = args.figure or str(Path(args.results).with_suffix(".png"))
    if ("x_b" in ds or "ship_sway" in ds) and "time" in ds.dims:
        _save_figure(lambda: _response_figure(ds, None), figure)  # the file's own record line
        sys.stdout.write(f"figure written to {figure}\n")
        return 0
    if "median" not in ds:
        raise UserError(f"{args.results}: neither a simulation response nor a fragility result")
    from shipblock.plot import (
        check_edp,
        default_edp,
        plot_fragility,
        plot_ida,
        plot_median_sweep,
        sweep_selection,
    )

    try:
        sweep = sweep_selection(ds, _parse_assignments(args.set))
    except ValueError as exc:
        raise UserError(f"{args.results}: --set {exc}") from None
    limit_states = args.limit_state
    if limit_states:
        if args.kind == "ida":
            raise UserError(f"{args.results}: --limit-state draws with --kind fragility or "
                            "median; IDA curves draw an --edp")
        known = [str(n) for n in ds["limit_state"].values]
        unknown = [n for n in limit_states if n not in known]
        if unknown:
            raise UserError(f"{args.results}: --limit-state {unknown[0]!r} is not a limit state "
                            f"of the study; limit states: {', '.join(known)}")
    if args.kind == "ida":
        edp = default_edp(ds) if args.edp is None else args.edp
        try:
            check_edp(ds, edp, "--edp")
        except ValueError as exc:
            raise UserError(f"{args.results}: {exc}") from None
        _save_figure(lambda: plot_ida(ds, edp, sweep=sweep).figure, figure)
    elif args.kind == "median":
        if not sweep:
            raise UserError(f"{args.results}: --kind median needs a study with a [sweep]")
        against = args.against or next(iter(sweep))
        if against not in sweep:
            raise UserError(f"{args.results}: --against {against!r} is not a swept parameter; "
                            f"swept: {', '.join(sweep)}")
        _save_figure(lambda: plot_median_sweep(ds, against, limit_states,
                                                        sweep=sweep).figure, figure)
    else:
        _save_figure(lambda: plot_fragility(ds, limit_states, sweep=sweep).figure, figure)
    sys.stdout.write(f"figure written to {figure}\n")
    return 0


def cmd_export(args):
    import xarray as xr

    from shipblock.fragility.export import write_csv

    with xr.open_dataset(args.results) as ds:
        ds = ds.load()
    if "median" not in ds or "limit_state" not in ds.dims:
        raise UserError(f"{args.results}: not the result of a study ('shipblock run'); a "
                        "simulation's response is drawn with 'shipblock plot'")
    for path in write_csv(ds, args.csv):
        sys.stdout.write(f"written {path}\n")
    return 0


def cmd_report(args):
    from shipblock.report import write_report
    from shipblock.risk.selection import target_from_file

    target = None if args.target is None else target_from_file(args.target, args.units)
    results = Path(args.results)  # by default the report goes beside it, as risk's file does
    output = args.output or results.with_name(f"{results.stem}_report.{args.format or 'html'}")
    written = write_report(args.results, output, hazard_results=args.hazard_results,
                           target=target, period_range=args.period_range, format=args.format)
    sys.stdout.write(f"report written to {written[0]}\n")
    for path in written[1:]:
        sys.stdout.write(f"written {path}\n")
    return 0
