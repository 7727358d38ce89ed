"""``shipblock simulate``: one record on one ship-block system; the summary, NetCDF file and
figure of a response (also those of ``shipblock history``)."""

from __future__ import annotations

import sys
from pathlib import Path

from shipblock.cli._common import SYSTEM_FLAGS, UserError, _save_figure, log
from shipblock.cli.reading import _horizontal_line, _load_motion
from shipblock.units import STANDARD_GRAVITY


def _system_from_args(args, base=None):
    """The system of --system (or ``base``, read from it already) and the system flags;
    quantities with units converted to SI (shipblock.quantities), and a warning for a system
    outside any dock (shipblock.system.warn_implausible)."""
    from shipblock.quantities import to_si
    from shipblock.system import FIELD_UNITS, ShipBlockSystem, warn_implausible

    if base is not None:
        system = base
    else:
        system = ShipBlockSystem.from_toml(args.system) if args.system else ShipBlockSystem.example()
    changes = {k: getattr(args, k) for k in SYSTEM_FLAGS if getattr(args, k) is not None}
    changes = {k: to_si(v, FIELD_UNITS[k], SYSTEM_FLAGS[k][0]) if k in FIELD_UNITS else v
               for k, v in changes.items()}
    if not changes:
        return system
    system = system.replace(**changes)
    warn_implausible(system, "the command line's system")
    return system


def _scaled_input(args, motion):
    """The horizontal and vertical to simulate, and the scale phrase of the figure's title."""
    from shipblock.scaling import acceleration_target, scale_record

    vertical = None if args.no_vertical else motion.vertical
    if vertical is None and args.vertical_scale is not None:  # else dropped without a word
        raise UserError(f"--vertical-scale {args.vertical_scale:g}: the record "
                        f"{motion.name} has no vertical component")
    if args.target_pga is None:
        factor = 1.0 if args.scale is None else args.scale
        ax = motion.horizontal * factor
        ay = None
        if vertical is not None:
            ay = vertical * (factor if args.vertical_scale is None else args.vertical_scale)
        return ax, ay, factor
    if args.scale is not None:
        raise UserError("give --scale or --target-pga, not both")
    target = acceleration_target(args.target_pga, "--target-pga")
    options = {"target": target, "measure": "pga"}
    if vertical is not None and args.vertical_scale is not None:
        options.update(vertical_mode="independent", vertical_factor=args.vertical_scale)
    scaled = scale_record(motion.horizontal, vertical, motion.dt, **options)
    log.info("scaled to PGA %.4g g: factor %.4g on the horizontal%s", target / STANDARD_GRAVITY,
             scaled.factor_h, "" if vertical is None else f", {scaled.factor_v:.4g} on the vertical")
    return (scaled.horizontal, scaled.vertical,
            f"scaled to PGA {target / STANDARD_GRAVITY:.3g} g (factor {scaled.factor_h:.4g})")


#: --rtol of a rigid-model run when not given (the section model has its own default).
RIGID_RTOL = 1e-8


def _solver_options(args, model) -> dict:
    """The ``[solver]`` table of ``--system``'s file (as a pipeline's, checked and named the
    same way), then ``--rtol`` and ``--atol`` as given, each checked against the range
    ``model`` declares for its ``[solver]`` option (a value outside it is an error naming the
    flag), and ``--no-exponential-steps``."""
    from shipblock.fragility.schema import load_solver
    from shipblock.models.base import FieldError

    options = load_solver(args.system, model) if args.system else {}
    for name in ("rtol", "atol"):
        value = getattr(args, name)
        if value is None:
            continue
        try:
            options[name] = model.options[name].check(value, f"--{name}")
        except FieldError as exc:
            raise UserError(f"--{name} {exc.problem} (the {model.name} model's range)") from None
    if not args.exponential_steps:
        if "exponential_steps" not in model.options:
            raise UserError(f"--no-exponential-steps applies to the section model; this is a "
                            f"{model.name!r} system")
        options["exponential_steps"] = False
    return options


def _model_system(args):
    """``(model, system)`` of ``--system`` when its ``[system]`` names its model (``model =
    "section"`` or ``"rigid"``: read as a pipeline's ``[system]``), else None (a plain
    :meth:`~shipblock.system.ShipBlockSystem.from_toml` table).

    The rigid model's flags (``--n-blocks``, ...) are refused for another model's system,
    naming the flag; ``--ship-mass`` (a key of both) replaces its ``ship_mass``."""
    from shipblock.checks import toml_file
    from shipblock.fragility.schema import load_system
    from shipblock.models import DEFAULT_MODEL

    if not args.system:
        return None
    table = toml_file(args.system, "system file").get("system")
    if not isinstance(table, dict) or "model" not in table:
        return None
    if table["model"] == DEFAULT_MODEL:  # the flags apply as to a plain table
        return load_system(args.system)
    given = [k for k in SYSTEM_FLAGS if getattr(args, k) is not None and k != "ship_mass"]
    if given:
        flag = SYSTEM_FLAGS[given[0]][0]
        raise UserError(f"{flag} sets the rigid model's system; {args.system} is a "
                        f"{table['model']!r} system: set its keys in the file")
    model, system = load_system(args.system)
    if args.ship_mass is not None:
        system = model.vary(system, {"ship_mass": model.parameters["ship_mass"].check(
            args.ship_mass)})
    return model, system


def cmd_simulate(args):
    from shipblock.plot import record_text
    from shipblock.solver import simulate

    from shipblock.models import DEFAULT_MODEL, get_model

    chosen = _model_system(args)
    if chosen is None or chosen[0].name == DEFAULT_MODEL:
        system = _system_from_args(args, None if chosen is None else chosen[1])
        chosen = None
    else:
        system = chosen[1]
    model = get_model(DEFAULT_MODEL) if chosen is None else chosen[0]
    options = _solver_options(args, model)  # the file's and flags' errors before the record's
    motion = _load_motion(args)
    ax, ay, scale = _scaled_input(args, motion)
    log.info("simulating %d samples at dt = %g s", ax.size, motion.dt)
    sys.stdout.write(f"horizontal  {_horizontal_line(motion)}\n")
    name = motion.name
    record = record_text(motion, scale)
    if chosen is not None:
        res = model.simulate(system, ax, ay, motion.dt, **options)
        _section_report(model, system, res, name, args.events)
    else:
        res = simulate(system, ax, ay, motion.dt, **{"rtol": RIGID_RTOL, **options})
        _report(res, name, args.events)
    if args.output:
        ds = res.to_dataset()
        for key, field in model.options.items():  # the options used (a rigid result states
            used = options.get(key, field.default)  # its tolerances itself)
            ds.attrs.setdefault(f"solver_{key}", int(used) if isinstance(used, bool) else used)
        ds.attrs["record"] = str(name)
        ds.attrs["record_description"] = record
        ds.attrs["processing"] = "\n".join(motion.metadata.get("processing", []) or [])
        _write_response(ds, args.output)
    _response_figure_option(res, record, args.figure, args.output)
    return 0


def _write_response(ds, output):
    from shipblock.fragility.store import write_dataset

    write_dataset(ds, output)
    sys.stdout.write(f"response written to {output}\n")


def _response_figure_option(res, record, figure, output):
    if figure is None and output:
        figure = str(Path(output).with_suffix(".png"))
    if figure:
        _save_figure(lambda: _response_figure(res, record), figure)
        sys.stdout.write(f"figure written to {figure}\n")


def _report(res, name, max_events):
    """Print the summary of a simulation: record, system, failure, peaks, modes, events."""
    import numpy as np

    out = sys.stdout
    system = res.system
    ax = res.ground_acceleration[0]
    dt = float(res.time[1] - res.time[0])
    s = res.summary
    rows = [
        ("record", f"{name} ({ax.size} samples, dt = {dt:g} s, "
                   f"PGA_H = {np.abs(ax).max() / STANDARD_GRAVITY:.3f} g)"),
        ("system", f"M = {system.ship_mass:.4g} kg on {system.n_blocks} blocks of "
                   f"{system.block_mass:.4g} kg, 2B x 2H = {2 * system.half_width:g} x "
                   f"{2 * system.half_height:g} m, e = {system.effective_restitution:.3f}"),
        ("failure", "none" if res.failure is None else f"{res.failure} at t = {res.failure_time:.4f} s"),
        ("peak block slip |x_b|", f"{100 * s['peak_block_slip']:.3f} cm"),
        ("peak ship slip |x_s|", f"{100 * s['peak_ship_slip']:.3f} cm"),
        ("peak rotation |theta|", f"{1000 * s['peak_rotation']:.3f} mrad "
                                  f"({100 * s['peak_rotation_ratio']:.1f} % of theta_c)"),
        ("residual x_b / x_s", f"{100 * s['residual_block_slip']:.3f} / "
                               f"{100 * s['residual_ship_slip']:.3f} cm"),
        ("uplift / impacts", f"{'yes' if s['uplift'] else 'no'} / {s['n_impacts']}"),
        ("peak loads per block", f"floor {s['peak_ground_normal_force'] / 1e3:.1f} kN, friction "
                                 f"{s['peak_ground_friction_force'] / 1e3:.1f} kN "
                                 f"(utilisation {s['peak_ground_friction_utilisation']:.2f}); ship "
                                 f"{s['peak_ship_normal_force'] / 1e3:.1f} kN, friction "
                                 f"{s['peak_ship_friction_force'] / 1e3:.1f} kN "
                                 f"(utilisation {s['peak_ship_friction_utilisation']:.2f})"),
    ]
    if s["uplift"]:
        rows.append(("peak corner load", f"{s['peak_corner_load'] / 1e3:.1f} kN per block, on "
                                         "the pivot edge while rocking"))
    width = max(len(r[0]) for r in rows)
    for key, val in rows:
        out.write(f"{key:<{width}}  {val}\n")
    out.write("time per mode:\n")
    from shipblock.modes import MODE_DESCRIPTIONS

    for m in range(1, 9):
        tm = s[f"time_in_mode_{m}"]
        if tm > 0:
            out.write(f"  {m} {MODE_DESCRIPTIONS[m]:<36} {tm:9.3f} s\n")
    counts = {}
    for e in res.events[1:]:
        counts[e.kind] = counts.get(e.kind, 0) + 1
    out.write("events: " + (", ".join(f"{k} {v}" for k, v in sorted(counts.items())) or "none") + "\n")
    shown = [e for e in res.events[1:] if e.kind != "impact"][:max_events]
    for e in shown:
        out.write(f"  t = {e.time:10.5f} s  {e.kind:<18} mode {e.from_mode} -> {e.to_mode}\n")


def _section_report(model, system, run, name, max_events):
    """Print the summary of a dock-section run: record, dock, failure, the capacity and cap
    pressure ratios per line, roll, sway, crushing, and its events."""
    import numpy as np

    out = sys.stdout
    s = run.summary
    h = run.ground[:, 0]
    sec = system.section
    failure = "none" if run.failure is None else f"{run.failure} at t = {run.failure_time:.4f} s"
    rows = [("record", f"{name} ({h.size} samples, PGA_H = "
                       f"{np.abs(h).max() / STANDARD_GRAVITY:.3f} g)"),
            ("system", model.caption(system)),
            ("failure", failure)]
    for line, what in (("keel", "keel"), ("side0", "starboard side"), ("side1", "port side")):
        if np.isfinite(s[f"{line}_capacity_ratio"]):
            rows.append((f"{what} blocks", f"peak {s[f'{line}_peak_load_per_block'] / 1e3:.1f} "
                         f"kN per block = {s[f'{line}_capacity_ratio']:.3f} of capacity; top cap "
                         f"{s[f'{line}_peak_top_pressure_ratio']:.3f} of its proportional limit"))
    rows += [
        ("peak cap pressure", f"{s['cap_pressure_ratio']:.3f} of the proportional limit "
                              f"(crushing set {1e3 * s['crushing_set']:.2f} mm)"),
        ("peak / residual roll", f"{1e3 * s['peak_roll']:.4g} / {1e3 * s['residual_roll']:.4g} "
                                 f"mrad ({np.degrees(s['peak_roll']):.3g} deg)"),
        ("peak / residual sway", f"{1e3 * s['peak_sway']:.4g} / {1e3 * s['residual_sway']:.4g} "
                                 f"mm on the keel blocks ({s['sway_ratio']:.3f} of the keel "
                                 f"cap's half-width {1e3 * sec.keel.block.half_width:.0f} mm)"),
        ("keel line slip", f"{1e3 * s['keel_slip']:.4g} mm on the floor"),
        ("energy balance", f"residual {s['energy_residual']:.2e} (relative)"),
    ]
    width = max(len(r[0]) for r in rows)
    for key, val in rows:
        out.write(f"{key:<{width}}  {val}\n")
    _events_report(run.events, max_events)


def _events_report(events, max_events):
    """Print the count of each kind of event and the first ``max_events`` (time, kind, where)."""
    out = sys.stdout
    counts = {}
    for e in events:
        counts[e.kind] = counts.get(e.kind, 0) + 1
    out.write("events: " + (", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
                            or "none") + "\n")
    for e in list(events)[:max_events]:
        out.write(f"  t = {e.time:10.5f} s  {e.kind:<22} {getattr(e, 'where', '')}\n")


def _response_figure(res, record):
    """The response figure, ``record`` the first line of its title (:func:`plot_response`, or
    :func:`plot_section_response` for a run of the dock-section model; None: a response
    dataset's own)."""
    from shipblock.plot import is_section_response, plot_response, plot_section_response

    if is_section_response(res) or hasattr(res, "result"):  # a SectionRun or its dataset
        return plot_section_response(res, record=record)[0].figure
    return plot_response(res, record=record)[0].figure
