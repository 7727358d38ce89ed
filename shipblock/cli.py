"""The ``shipblock`` command: simulate, process, info, catalogue, run, history, plot, export, risk,
select, report, bench.

The command only parses arguments, calls the library and prints; every computation lives in the
library. User errors print one line ``shipblock: error: ...`` and exit with status 2.
"""

from __future__ import annotations

import argparse
import json
import logging
import signal
import sys
import time
from contextlib import contextmanager
from pathlib import Path

from shipblock.processes import Terminated, terminate_as_interrupt
from shipblock.units import STANDARD_GRAVITY

log = logging.getLogger("shipblock")

SYSTEM_FLAGS = {
    "ship_mass": ("--ship-mass", str, "ship mass M: kg, or with a unit: '20000 t'"),
    "block_mass": ("--block-mass", str, "mass of one keel block m: kg, or with a unit: '4 t'"),
    "n_blocks": ("--n-blocks", int, "number of keel blocks n"),
    "half_width": ("--half-width", str, "block half width B: m, or with a unit: 600mm"),
    "half_height": ("--half-height", str, "block half height H: m, or with a unit: 750mm"),
    "mu_s_ground": ("--mu-s-ground", float, "static friction blocks/ground"),
    "mu_k_ground": ("--mu-k-ground", float, "kinetic friction blocks/ground"),
    "mu_s_ship": ("--mu-s-ship", float, "static friction blocks/ship"),
    "mu_k_ship": ("--mu-k-ship", float, "kinetic friction blocks/ship"),
    "restitution": ("--restitution", float, "restitution theta_dot+/theta_dot- (default: system value)"),
    "impact_rule": ("--impact-rule", str, "impact rule: momentum (default), paper or plastic"),
}


class UserError(Exception):
    """An error caused by the user's input: reported in one line, no traceback."""


#: What numba compiles on first use, by the module of the function compiled: (module prefix,
#: what it is, seconds it took from an empty cache). The seconds are measured by
#: ``shipblock bench`` (:func:`shipblock.bench.startup.cold_start`, docs/benchmarks.rst) on
#: the project's 2-core machine; the notice quotes them, and the log says afterwards how long it
#: took here.
COMPILED_PARTS = (
    ("shipblock.solver", "the solver", 22.0),
    ("shipblock.equations", "the solver", 22.0),
    ("shipblock.impact", "the solver", 22.0),
    ("shipblock.interface_forces", "the contact loads", 0.5),
    ("shipblock.intensity", "the intensity measures", 0.3),
    # RotD spectra (info --figure): compiled as fast as the spectrum kernel (4.3 s against its
    # 4.9 s side by side on the loaded machine), so its time is quoted
    ("shipblock.rotd", "the intensity measures", 0.3),
    # the dock-section model's kernel (shipblock.section): about 20 s of one core, measured on the
    # loaded machine when it was written (issue 29)
    ("shipblock.section", "the dock-section model", 20.0),
)


def compiled_part(module: str) -> tuple[str, float | None]:
    """What a compiled function of ``module`` belongs to, and its measured compile time [s]."""
    for prefix, what, seconds in COMPILED_PARTS:
        if module == prefix or module.startswith(prefix + "."):
            return what, seconds
    return f"numba code of {module}", None


def compile_message(what: str, seconds: float | None) -> str:
    """The notice said when ``what`` starts compiling."""
    took = "" if seconds is None else f": about {seconds:.2g} s on 2 cores"
    return (f"compiling {what} for this machine (first use only, kept in numba's cache for later "
            f"runs){took}")


@contextmanager
def compile_notice(say, done=None):
    """Call ``say(message)`` once per part when numba compiles it within the block.

    Loading a function from numba's on-disk cache is not a compilation, so ``say`` runs only
    on a first use, where a progress bar would otherwise sit at 0 % with no word of why. The
    message names the part compiled (the solver, the intensity measures; :func:`compiled_part`)
    and the time it took on the benchmark machine. ``done(what, seconds)``, if given, is called
    when a part has compiled, with the time it took here [s]. Uses numba's event API
    (``numba:compile`` is triggered on a cache miss only; the outermost of nested events
    is the function a command called).
    """
    import time

    from numba.core import event

    class _Parts(event.Listener):
        def __init__(self):
            self.said = set()
            self.depth = 0
            self.what = None
            self.t0 = 0.0

        def on_start(self, ev):
            self.depth += 1
            if self.depth > 1:
                return
            dispatcher = (ev.data or {}).get("dispatcher")
            module = getattr(getattr(dispatcher, "py_func", None), "__module__", None) or "?"
            what, seconds = compiled_part(module)
            self.what, self.t0 = what, time.perf_counter()
            if what not in self.said:
                self.said.add(what)
                say(compile_message(what, seconds))

        def on_end(self, ev):
            self.depth -= 1
            if self.depth == 0 and done is not None:
                done(self.what, time.perf_counter() - self.t0)

    with event.install_listener("numba:compile", _Parts()):
        yield


def _log_compiled(what, seconds):
    if seconds >= 1.0:
        log.info("%s compiled in %.1f s", what, seconds)


# --------------------------------------------------------------------------- record input
def _add_record_arguments(p):
    g = p.add_argument_group("record")
    g.add_argument("files", nargs="*",
                   help="record files (MiniSEED, SAC, K-NET/KiK-net, CSMIP, COSMOS, GeoNet, ESM,"
                        " AT2, ...), or a folder or glob pattern holding one record")
    g.add_argument("--record", help="id of a catalogue record, e.g. NP.1765 or south-napa-2014/NP.1765")
    g.add_argument("--catalogue", help="record catalogue TOML (default: the shipped one)")
    _add_conversion_arguments(g)
    g.add_argument("--azimuth", type=float,
                   help="dock transverse axis [deg clockwise from north]: horizontals rotated to it")
    g.add_argument("--horizontal", choices=["H1", "H2"],
                   help="use this horizontal component (default H1, the record's first"
                        " horizontal; see docs/user_guide/records.rst)")
    g.add_argument("--processing", default="default",
                   help="'default' (the documented chain), 'demean', 'none', or a TOML file with "
                        "[[processing]] steps")


def _add_conversion_arguments(g):
    from shipblock.records.arguments import add_read_arguments

    add_read_arguments(g)


def _read_options(args) -> dict:
    from shipblock.records.arguments import read_options

    return read_options(args)


def _find_entry(record_id, catalogue):
    from shipblock.records.catalogue import load_catalogue

    entries = load_catalogue(catalogue)
    if record_id in entries:
        return entries[record_id]
    matches = [k for k in entries if k.endswith("/" + record_id) or k.split("/")[-1] == record_id]
    if len(matches) == 1:
        return entries[matches[0]]
    known = ", ".join(sorted(entries))
    raise UserError(f"record {record_id!r} is not in the catalogue; known records: {known}")


def _processing_chain(spec):
    from shipblock.processing import default_chain

    if spec in (None, "default"):
        return default_chain()
    if spec == "none":
        return []
    if spec == "demean":
        return [{"step": "demean"}]
    import tomllib

    path = Path(spec)
    if not path.exists():
        raise UserError(f"processing chain file {spec} does not exist")
    with open(path, "rb") as fh:
        data = tomllib.load(fh)
    chain = data.get("processing")
    if isinstance(chain, dict):
        chain = chain.get("chain", chain.get("steps"))
    if not isinstance(chain, list):
        raise UserError(f"{spec}: expected a list of [[processing]] tables")
    return chain


def _load_motion(args):
    """The record of the command line, processed as --processing says."""
    return _processed(_read_record(args), args)


def _processed(motion, args):
    from shipblock.processing import process_motion

    chain = _processing_chain(args.processing)
    return process_motion(motion, chain) if chain else motion


def _read_record(args):
    """The record of the command line as read (converted to m/s^2, not processed)."""
    from shipblock.records.reading import read_motion

    if args.record and args.files:
        raise UserError("give either --record or record files, not both")
    if args.record:
        entry = _find_entry(args.record, args.catalogue)
        motion = entry.read(azimuth=args.azimuth, horizontal=args.horizontal,
                            **_read_options(args))
    elif args.files:
        import glob

        for f in args.files:
            if not Path(f).exists() and not glob.has_magic(f):
                raise UserError(f"{f}: no such file")
        motion = read_motion(args.files if len(args.files) > 1 else args.files[0],
                             azimuth=args.azimuth, horizontal=args.horizontal,
                             **_read_options(args))
    else:
        raise UserError("no record: give record files or --record ID (see 'shipblock info --help')")
    return motion


def _horizontal_line(motion) -> str:
    from shipblock.records.sensors import describe_horizontal

    return describe_horizontal(motion)


# --------------------------------------------------------------------------- subcommands
def _system_from_args(args):
    """The system of --system and the system flags; quantities with units converted to SI
    (shipblock.quantities), and a warning for a system outside any dock
    (shipblock.system.warn_implausible)."""
    from shipblock.quantities import to_si
    from shipblock.system import FIELD_UNITS, ShipBlockSystem, warn_implausible

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


def cmd_simulate(args):
    from shipblock.plot import record_text
    from shipblock.solver import simulate

    system = _system_from_args(args)
    motion = _load_motion(args)
    ax, ay, scale = _scaled_input(args, motion)
    log.info("simulating %d samples at dt = %g s", ax.size, motion.dt)
    sys.stdout.write(f"horizontal  {_horizontal_line(motion)}\n")
    res = simulate(system, ax, ay, motion.dt, rtol=args.rtol)
    name = motion.name
    record = record_text(motion, scale)
    _report(res, name, args.events)
    if args.output:
        ds = res.to_dataset()
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


def _parse_assignments(items):
    """``["mu_ground=0.4", ...]`` -> ``{"mu_ground": 0.4}`` (numbers only)."""
    values = {}
    for item in items or []:
        name, sep, text = item.partition("=")
        if not sep or not name.strip():
            raise UserError(f"--set expects NAME=VALUE, got {item!r}")
        try:
            values[name.strip()] = float(text)
        except ValueError:
            raise UserError(f"--set {name.strip()}: {text!r} is not a number") from None
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
    _report(res, name, args.events)
    record = dataset_record_line(ds)
    ds.attrs["record_description"] = record
    if args.output:
        _write_response(ds, args.output)
    _response_figure_option(res, record, args.figure, args.output)
    return 0


def _response_figure(res, record):
    """The response figure, ``record`` the first line of its title (:func:`plot_response`;
    None: a response dataset's own)."""
    from shipblock.plot import plot_response

    return plot_response(res, record=record)[0].figure


def _save_figure(make, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = make()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def cmd_info(args):
    import numpy as np

    from shipblock import intensity

    raw = _read_record(args)
    motion = _processed(raw, args)
    out = sys.stdout
    md = motion.metadata
    site = (md.get("catalogue") or {}).get("site", "")
    out.write(f"record      {motion.name} {site}\n")
    for f in md.get("source_files", []):
        out.write(f"file        {f}\n")
    out.write(f"start       {motion.starttime}\n")
    out.write(f"sampling    dt = {motion.dt:g} s ({1 / motion.dt:g} Hz), {motion.npts} samples, "
              f"{motion.npts * motion.dt:.2f} s\n")
    units = md.get("units")
    if isinstance(units, dict):
        for comp, note in units.items():
            out.write(f"units {comp:<5} {note}\n")
    elif units:
        out.write(f"units       {units}\n")
    processed = motion is not raw
    stated = {tr.stats.get("motion_component"): tr.stats.get("stated_peak_si")
              for tr in raw.stream}
    out.write("PGA [g]: 'as read' is after unit conversion only"
              + (", 'processed' after the processing below" if processed else "")
              + ("; 'file states' is the peak the file's header states" if any(stated.values())
                 else "") + "\n")
    out.write("component  azimuth  as read" + ("  processed" if processed else "")
              + ("  file states" if any(stated.values()) else "")
              + f"  {'(processed) ' if processed else ''}PGV [cm/s]  Arias [m/s]  CAV [m/s]"
                "  D5-95 [s]\n")
    for comp, acc in motion.components.items():
        im = intensity.intensity_measures(acc, motion.dt, periods=(0.2, 1.0))
        az = motion.azimuths.get(comp)
        row = (f"{comp:<10} {'' if az is None else f'{az:7.1f}':>7}"
               f"  {np.abs(raw.components[comp]).max() / STANDARD_GRAVITY:7.4f}")
        if processed:
            row += f"  {im['pga'] / STANDARD_GRAVITY:9.4f}"
        if any(stated.values()):
            peak = stated.get(comp)
            row += f"  {'' if peak is None else f'{peak / STANDARD_GRAVITY:11.4f}':>11}"
        out.write(row + f"  {100 * im['pgv']:10.3f}  {im['arias']:11.4f}  {im['cav']:9.4f}"
                        f"  {im['d5_95']:9.2f}\n")
    h = motion.horizontal
    sa = intensity.spectral_acceleration(h, motion.dt, np.array([0.2, 1.0]), 0.05)
    out.write(f"horizontal used by the solver: {_horizontal_line(motion)}\n")
    out.write(f"  {'processed: ' if processed else ''}PGA {np.abs(h).max() / STANDARD_GRAVITY:.4f}"
              f" g, Sa(0.2 s) {sa[0] / STANDARD_GRAVITY:.4f} g,"
              f" Sa(1 s) {sa[1] / STANDARD_GRAVITY:.4f} g\n")
    for note in md.get("processing", []) or []:
        out.write(f"processing  {note}\n")
    if args.figure:
        _record_figure(args, raw, motion)
        out.write(f"figure written to {args.figure}\n")
    return 0


def _record_figure(args, raw, processed):
    """``info --figure``: the record as read and processed, spectra, Fourier amplitudes."""
    from shipblock.plot import plot_record_overview

    done = processed if processed.metadata.get("processing") else None
    _save_figure(lambda: plot_record_overview(raw, done)["spectra"].figure, args.figure)


def cmd_catalogue(args):
    from shipblock.records.catalogue import catalogue_toml, load_catalogue, record_id
    from shipblock.records.folders import read_motions

    options = _read_options(args)
    found = read_motions(args.sources, **options)
    for where, why in found.failures:
        log.warning("not used: %s: %s", where, why)
    if not found.motions:
        raise UserError(f"no record could be read from {', '.join(args.sources)}"
                        f" ({len(found.failures)} failures listed above)")
    text = catalogue_toml(found, args.output, licence=args.license, credit=args.credit,
                          options=options)
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    partial = output.with_name(output.name + ".part")
    partial.write_text(text)
    try:
        load_catalogue(partial)  # what is written reads back (paths resolve in the same folder)
    except Exception:
        partial.unlink()
        raise
    partial.replace(output)
    sys.stdout.write(f"{len(found.motions)} records written to {output}; "
                     f"{len(found.failures)} files or groups not used\n")
    for motion in found.motions:
        peaks = "  ".join(f"{c} {abs(a).max() / STANDARD_GRAVITY:.4f} g"
                          for c, a in motion.components.items())
        sensor = record_id(motion)
        sys.stdout.write(f"  {sensor:<20} dt {motion.dt:g} s  {motion.npts:>7} samples  {peaks}\n")
    return 0


def cmd_process(args):
    import csv

    from shipblock import intensity
    from shipblock.records.catalogue import record_file_stem

    motion = _load_motion(args)
    outdir = Path(args.output_dir)
    outdir.mkdir(parents=True, exist_ok=True)
    st = motion.stream.copy()
    name = motion.name
    stem = record_file_stem(name)
    fmt = args.format.upper()
    ext = {"MSEED": "mseed", "SAC": "sac"}[fmt]
    written = []
    if fmt == "SAC":
        for tr in st:
            path = outdir / f"{stem}.{tr.stats.channel}.{ext}"
            tr.write(str(path), format="SAC")
            written.append(path)
    else:
        for tr in st:
            tr.data = tr.data.astype("float64")
        path = outdir / f"{stem}.{ext}"
        st.write(str(path), format="MSEED")
        written.append(path)
    table = outdir / f"{stem}_intensity.csv"
    with open(table, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["component", "pga_m_s2", "t_pga_s", "pgv_m_s", "pgd_m", "arias_m_s", "cav_m_s",
                    "cav5_m_s", "d5_75_s", "d5_95_s", "sa_0.2s_m_s2", "sa_1.0s_m_s2"])
        for comp, acc in motion.components.items():
            im = intensity.intensity_measures(acc, motion.dt, periods=(0.2, 1.0))
            w.writerow([comp, im["pga"], im["t_pga"], im["pgv"], im["pgd"], im["arias"], im["cav"],
                        im["cav5"], im["d5_75"], im["d5_95"], im["sa"][0], im["sa"][1]])
    for p in written + [table]:
        sys.stdout.write(f"written {p}\n")
    return 0


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
    if "x_b" in ds and "time" in ds.dims:
        _save_figure(lambda: _response_figure(ds, None), figure)  # the file's own record line
        sys.stdout.write(f"figure written to {figure}\n")
        return 0
    if "median" not in ds:
        raise UserError(f"{args.results}: neither a simulation response nor a fragility result")
    from shipblock.plot import (
        check_edp,
        plot_fragility,
        plot_ida,
        plot_median_sweep,
        sweep_selection,
    )

    try:
        sweep = sweep_selection(ds, _parse_assignments(args.set))
    except ValueError as exc:
        raise UserError(f"{args.results}: --set {exc}") from None
    if args.kind == "ida":
        try:
            check_edp(ds, args.edp, "--edp")
        except ValueError as exc:
            raise UserError(f"{args.results}: {exc}") from None
        _save_figure(lambda: plot_ida(ds, args.edp, sweep=sweep).figure, figure)
    elif args.kind == "median":
        if not sweep:
            raise UserError(f"{args.results}: --kind median needs a study with a [sweep]")
        against = args.against or next(iter(sweep))
        if against not in sweep:
            raise UserError(f"{args.results}: --against {against!r} is not a swept parameter; "
                            f"swept: {', '.join(sweep)}")
        _save_figure(lambda: plot_median_sweep(ds, against, sweep=sweep).figure, figure)
    else:
        _save_figure(lambda: plot_fragility(ds, sweep=sweep).figure, figure)
    sys.stdout.write(f"figure written to {figure}\n")
    return 0


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
    target = target_from_file(args.target, args.units)
    vertical = (None if args.vertical_target is None
                else target_from_file(args.vertical_target, args.vertical_units or args.units))
    selection = select_records(
        entries, target, args.k, period_range=args.period_range, vertical_target=vertical,
        vertical_weight=args.vertical_weight, scale=not args.no_scale,
        min_scale_factor=args.min_scale_factor, max_scale_factor=args.max_scale_factor,
        horizontal=args.horizontal, azimuth=args.azimuth,
        processing=[] if args.no_processing else None)
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
    from shipblock.report_html import write_report
    from shipblock.risk.selection import target_from_file

    target = None if args.target is None else target_from_file(args.target, args.units)
    written = write_report(args.results, args.output, hazard_results=args.hazard_results,
                           target=target, period_range=args.period_range)
    sys.stdout.write(f"report written to {written[0]}\n")
    for path in written[1:]:
        sys.stdout.write(f"written {path}\n")
    return 0


def cmd_bench(args):
    if args.read:
        import json

        from shipblock.bench.readers import reader_throughput, write_reader_throughput

        result = reader_throughput(args.read, min_seconds=0.3 if args.quick else 1.0)
        write_reader_throughput(result, sys.stdout)
        if args.output:
            Path(args.output).write_text(json.dumps(result, indent=2))
        return 0
    from shipblock.bench.run import run_benchmarks

    if args.campaign_runs is not None and args.campaign_runs < 0:
        raise UserError(f"--campaign-runs must be >= 0, got {args.campaign_runs}")
    if args.chunk_size is not None and args.chunk_size < 1:
        raise UserError(f"--chunk-size must be >= 1, got {args.chunk_size}")
    dask_workers = None
    if args.dask:
        try:
            dask_workers = [int(n) for n in args.dask.split(",")]
        except ValueError:
            raise UserError(f"--dask takes numbers of workers like 1,2; got {args.dask!r}") from None
        if min(dask_workers) < 1:
            raise UserError(f"--dask: numbers of workers must be >= 1, got {args.dask!r}")
    return run_benchmarks(quick=args.quick, pyslammer=not args.no_pyslammer, output=args.output,
                          campaign_runs=args.campaign_runs, chunk_size=args.chunk_size,
                          profile=args.profile, cold=not args.no_cold_start,
                          dask_workers=dask_workers)


# --------------------------------------------------------------------------- parser
def build_parser():
    p = argparse.ArgumentParser(
        prog="shipblock",
        description="Seismic response of a ship standing free on keel blocks: simulation, "
                    "ground-motion processing and fragility.",
    )
    p.add_argument("-v", "--verbose", action="count", default=0, help="more log output")
    p.add_argument("-q", "--quiet", action="store_true", help="only warnings and errors")
    # For the cold-start benchmark (shipblock.bench.startup), which runs the command in a fresh
    # process: the seconds numba compiled, by part, and the process's CPU time, as JSON.
    p.add_argument("--compile-report", metavar="FILE", help=argparse.SUPPRESS)
    sub = p.add_subparsers(dest="command", metavar="COMMAND")

    s = sub.add_parser("simulate", help="simulate one record on one ship-block system",
                       description="Simulate one record; prints a summary, writes NetCDF and a figure.")
    _add_record_arguments(s)
    g = s.add_argument_group("system (defaults: ShipBlockSystem.example())")
    g.add_argument("--system", help="TOML file with a [system] table (SI units)")
    for key, (flag, typ, help_) in SYSTEM_FLAGS.items():
        g.add_argument(flag, dest=key, type=typ, help=help_)
    g = s.add_argument_group("run")
    g.add_argument("--scale", type=float,
                   help="factor on the horizontal (and vertical); default 1")
    g.add_argument("--target-pga", metavar="PGA",
                   help="scale to this PGA of the horizontal, with its unit: 0.4g, 3.9m/s^2, "
                        "392gal (the vertical by the same factor unless --vertical-scale)")
    g.add_argument("--vertical-scale", type=float, help="independent factor on the vertical")
    g.add_argument("--no-vertical", action="store_true", help="ignore the vertical component")
    g.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance of rocking phases")
    g.add_argument("--output", "-o", help="NetCDF file for the response")
    g.add_argument("--figure", help="PNG for the response figure (default: next to --output)")
    g.add_argument("--events", type=int, default=20, help="list at most this many events")
    s.set_defaults(func=cmd_simulate)

    s = sub.add_parser("info", help="what is in a record: components, units, sampling, IMs")
    _add_record_arguments(s)
    s.add_argument("--figure", metavar="PNG",
                   help="draw the record: each component as read and processed (the file's "
                        "stated peak marked), 5 %%-damped response spectra with the RotD50 of "
                        "the horizontals, and Fourier amplitude spectra")
    s.set_defaults(func=cmd_info)

    s = sub.add_parser("process", help="process records; write MiniSEED/SAC and an IM table")
    _add_record_arguments(s)
    s.add_argument("--output-dir", "-o", default="processed", help="output folder")
    s.add_argument("--format", default="MSEED", choices=["MSEED", "SAC", "mseed", "sac"])
    s.set_defaults(func=cmd_process)

    s = sub.add_parser("catalogue", help="read a folder of agency records into a catalogue TOML",
                       description="Read every record file of folders or glob patterns, group"
                       " the files into one record per station sensor, and write a catalogue"
                       " (station, event, dt, duration, PGA per component, source files). Files"
                       " that cannot be read are listed with their reasons.")
    s.add_argument("sources", nargs="+", help="folders, glob patterns or files")
    s.add_argument("--output", "-o", default="catalogue.toml", help="catalogue TOML to write")
    g = s.add_argument_group("reading (stored in each entry, so that it reads back the same)")
    _add_conversion_arguments(g)
    s.add_argument("--license", "--licence", dest="license", help="licence of the records")
    s.add_argument("--credit", help="credit line of the records")
    s.set_defaults(func=cmd_catalogue)

    s = sub.add_parser("run", help="run a pipeline file (batch, fragility)")
    s.add_argument("pipeline", help="pipeline TOML, e.g. pipelines/demo.toml")
    s.add_argument("--output", "-o", help="NetCDF output (overrides the pipeline's)")
    s.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786")
    s.add_argument("--figure", help="PNG of the fragility curves")
    s.add_argument("--wait", action="store_true",
                   help="if another run is writing the same output, wait for it to end and then "
                        "run (default: refuse, naming its process id)")
    s.set_defaults(func=cmd_run)

    s = sub.add_parser("history", help="full time histories of one run of a pipeline",
                       description="Simulate one run of a pipeline again (same record, "
                                   "processing, scaling, system and solver options as in the "
                                   "batch) and print, write and plot its full response.")
    s.add_argument("pipeline", help="pipeline TOML, e.g. pipelines/demo.toml")
    s.add_argument("--record", required=True, help="record id, e.g. NP.1765")
    s.add_argument("--im-level-g", type=float, help="IM level of the run [g] (PGA, Sa)")
    s.add_argument("--im-level", type=float,
                   help="IM level of the run in SI units of the measure (m/s^2; m/s for PGV)")
    s.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="value of a swept parameter, e.g. --set mu_ground=0.4 (repeatable)")
    s.add_argument("--output", "-o", help="NetCDF file for the response")
    s.add_argument("--figure", help="PNG for the response figure (default: next to --output)")
    s.add_argument("--events", type=int, default=20, help="list at most this many events")
    s.set_defaults(func=cmd_history)

    s = sub.add_parser("plot", help="figure from a results NetCDF (response or fragility)")
    s.add_argument("results", help="NetCDF written by 'simulate' or 'run'")
    # --output too: 'simulate' and 'history' name their NetCDF so, and here the output is the PNG
    s.add_argument("--figure", "--output", "-o", dest="figure",
                   help="PNG path (default: next to the results)")
    s.add_argument("--kind", choices=["fragility", "ida", "median"], default="fragility",
                   help="for batch results: fragility curves (default), IDA curves, or the "
                        "fitted median against a swept parameter")
    s.add_argument("--edp", default="peak_ship_slip", help="demand parameter of the IDA curves")
    s.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="value of a swept parameter to draw, e.g. --set mu_ground=0.5 "
                        "(repeatable; default: the first value of each)")
    s.add_argument("--against", metavar="NAME",
                   help="with --kind median: the swept parameter on the x axis (default: the "
                        "first)")
    s.set_defaults(func=cmd_plot)

    s = sub.add_parser("risk", help="risk over a docking period: fragility x site hazard",
                       description="Convolve every fitted fragility of a result with a site "
                       "hazard curve: annual rate of exceedance, return period, probability "
                       "during the docking period (Poisson), bootstrap band and deaggregation "
                       "over the intensity; written to a copy of the result.")
    s.add_argument("results", help="NetCDF written by 'shipblock run'")
    s.add_argument("--hazard", required=True, metavar="FILE",
                   help="hazard curve: OpenQuake hazard_curve CSV, USGS nshmp-haz CSV, USGS "
                        "hazard service JSON, or a two-column table with units in its header")
    s.add_argument("--days", required=True, type=float, help="docking period [d]")
    s.add_argument("--site", help="site of a file with several: its name or LON,LAT [deg]")
    s.add_argument("--format", default="auto",
                   choices=["auto", "openquake", "nshmp-csv", "usgs-json", "table"],
                   help="layout of the hazard file (default: told from the file)")
    s.add_argument("--measure", help="IMT of the hazard file when it does not say (e.g. PGA, "
                                     "SA1P0)")
    s.add_argument("--output", "-o", help="NetCDF to write (default: <results>_risk.nc)")
    s.add_argument("--figure", help="PNG of the hazard, fragilities and deaggregation")
    s.add_argument("--no-band", action="store_true",
                   help="skip the bootstrap band (the replicates are made again)")
    s.add_argument("--target-probability", type=float, metavar="P",
                   help="acceptable probability during the docking period: each fit (its upper "
                        "bound) is marked below or above it")
    s.set_defaults(func=cmd_risk)

    s = sub.add_parser("select", help="choose the records of a catalogue that best match a "
                                      "target spectrum",
                       description="Rank the records of a catalogue by the misfit of their "
                       "spectra (horizontal, and vertical with --vertical-target) to a target "
                       "over a period range, each scaled by its best factor within bounds; "
                       "write the best k as a catalogue a pipeline reads, with the ASCE 7-16 "
                       "suite-mean check.")
    s.add_argument("catalogue", help="catalogue TOML (e.g. from 'shipblock catalogue')")
    s.add_argument("--target", required=True, metavar="FILE",
                   help="target spectrum: two columns, period [s] and Sa (uniform hazard or "
                        "conditional mean); the Sa unit from --units or the header, e.g. "
                        "'period [s], Sa [g]'")
    s.add_argument("--units", help="unit of the target's Sa (g, m/s^2, ...)")
    s.add_argument("-k", type=int, default=7, help="number of records to choose (default 7)")
    s.add_argument("--output", "-o", default="selected.toml", help="catalogue TOML to write")
    s.add_argument("--period-range", nargs=2, type=float, metavar=("TA", "TB"),
                   help="periods compared [s] (default: the target's range)")
    s.add_argument("--vertical-target", metavar="FILE", help="target spectrum of the vertical")
    s.add_argument("--vertical-units", help="unit of its Sa (default --units or its header)")
    s.add_argument("--vertical-weight", type=float, default=1.0,
                   help="weight of the vertical misfit (default 1)")
    s.add_argument("--horizontal", default="H1", choices=["H1", "H2", "geomean"],
                   help="horizontal spectrum compared (default H1, as a pipeline's default)")
    s.add_argument("--azimuth", type=float,
                   help="dock transverse axis [deg from north]: horizontals rotated onto it "
                        "(instead of --horizontal)")
    s.add_argument("--no-scale", action="store_true", help="compare the records unscaled")
    s.add_argument("--min-scale-factor", type=float, default=0.25, help="default 0.25")
    s.add_argument("--max-scale-factor", type=float, default=4.0, help="default 4")
    s.add_argument("--no-processing", action="store_true",
                   help="spectra of the records as read (default: the default processing chain)")
    s.set_defaults(func=cmd_select)

    s = sub.add_parser("export", help="a study's results as CSV tables (runs, fragility)",
                       description="Write the per-run table (runs.csv: EDPs, scale factors, "
                       "failure, exceedance per limit state) and the fitted fragility table "
                       "(fragility.csv: definition, median, bootstrap band, beta) of a results "
                       "file of 'shipblock run'; every column of a quantity names its unit, "
                       "e.g. 'peak_ship_slip [m]'.")
    s.add_argument("results", help="NetCDF written by 'run'")
    s.add_argument("--csv", required=True, metavar="DIR", help="folder for the CSV tables")
    s.set_defaults(func=cmd_export)

    s = sub.add_parser("report", help="a study's report: one HTML file with its figures, and CSV "
                                      "tables",
                       description="Write a self-contained HTML report of a results file of "
                       "'shipblock run': the study (pipeline, design, system with units, "
                       "processing, solver options), the records used and left out, their "
                       "spectra against a target spectrum, the limit states, the fragility "
                       "curves with bootstrap bands and, with a file of 'shipblock risk', the "
                       "risk over the docking period; figures embedded as PNG; the tables of "
                       "'shipblock export' in <output stem>_csv/ beside it.")
    s.add_argument("results", help="NetCDF written by 'run' (or by 'risk')")
    s.add_argument("--hazard-results", metavar="FILE",
                   help="NetCDF written by 'shipblock risk' for this study: its risk goes in")
    s.add_argument("--target", metavar="FILE",
                   help="target spectrum to draw the records' spectra against (two columns, "
                        "period [s] and Sa; default: the study's own target, if any); the "
                        "records are read and processed again")
    s.add_argument("--units", help="unit of the target's Sa (default: from its header)")
    s.add_argument("--period-range", nargs=2, type=float, metavar=("TA", "TB"),
                   help="periods of the match with --target [s] (default: the target's)")
    s.add_argument("--output", "-o", default="report.html", help="HTML file to write "
                                                                  "(default report.html)")
    s.set_defaults(func=cmd_report)

    s = sub.add_parser("bench", help="benchmarks: runs/s, campaign time and memory, pySLAMMER, "
                                     "batch scaling")
    s.add_argument("--quick", action="store_true",
                   help="smaller, faster benchmark (campaign of 300 runs)")
    s.add_argument("--no-pyslammer", action="store_true", help="skip the pySLAMMER comparison")
    s.add_argument("--output", "-o", help="also write the results as JSON")
    s.add_argument("--campaign-runs", type=int, metavar="N",
                   help="runs of the pipeline campaign (default 100000; 0 skips it)")
    s.add_argument("--chunk-size", type=int, metavar="N",
                   help="cases per chunk of the campaign (default: about 100 chunks)")
    s.add_argument("--profile", metavar="FILE",
                   help="profile the campaign with cProfile and write the statistics to FILE")
    s.add_argument("--no-cold-start", action="store_true",
                   help="skip the cold start (the demo command from an empty numba cache)")
    s.add_argument("--dask", metavar="N[,N...]",
                   help="also run a pipeline on Dask LocalClusters of these numbers of worker "
                        "processes (e.g. 1,2): runs/s per worker, scaling, equality with the "
                        "local run")
    s.add_argument("--read", nargs="+", metavar="SOURCE",
                   help="only the readers' benchmark: files/s per format on these folders, globs"
                        " or files")
    s.set_defaults(func=cmd_bench)
    return p


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    level = logging.WARNING if args.quiet else (logging.DEBUG if args.verbose > 1 else logging.INFO)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    if args.command is None:
        parser.print_help()
        return 2
    compiled = {}
    code = _run(args, compiled)
    if args.compile_report:
        Path(args.compile_report).write_text(json.dumps(
            {"code": code, "compiled": compiled, "cpu": time.process_time()}))
    return code


def _run(args, compiled: dict) -> int:
    """Run the command of ``args``; its exit status. ``compiled`` collects the seconds numba
    compiled, by part (:func:`compile_notice`)."""
    from shipblock.errors import ShipblockError

    def done(what, seconds):
        compiled[what] = compiled.get(what, 0.0) + seconds
        _log_compiled(what, seconds)

    try:
        from tqdm.contrib.logging import logging_redirect_tqdm

        # log lines go above a progress bar, not onto its line; SIGTERM unwinds as Ctrl-C
        with logging_redirect_tqdm(), compile_notice(log.info, done), terminate_as_interrupt():
            return args.func(args)
    except (UserError, ShipblockError, ValueError, FileNotFoundError, OSError) as exc:
        if args.verbose > 1:
            raise
        sys.stderr.write(f"shipblock: error: {exc}\n")
        return 2
    except KeyboardInterrupt as exc:
        return _interrupted(args, exc)


def _interrupted(args, exc: KeyboardInterrupt) -> int:
    """Say that the command was interrupted (Ctrl-C) or terminated (SIGTERM); the exit status
    128 + the signal's number, as a shell reports a process ended by it."""
    terminated = isinstance(exc, Terminated)
    what = "terminated" if terminated else "interrupted"
    if args.command == "run":
        what += ("; finished runs and fits are kept: the same command again resumes from them")
    sys.stderr.write(f"shipblock: {what}\n")
    return 128 + (signal.SIGTERM if terminated else signal.SIGINT)


if __name__ == "__main__":
    sys.exit(main())
