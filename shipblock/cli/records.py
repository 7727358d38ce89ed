"""The commands on records: ``shipblock info`` (what is in a record), ``shipblock process``
(processed files and an intensity table) and ``shipblock catalogue`` (a folder of records to a
catalogue)."""

from __future__ import annotations

import sys
from pathlib import Path

from shipblock.cli._common import UserError, _save_figure, log
from shipblock.cli.reading import _horizontal_line, _load_motion, _processed, _read_options, _read_record
from shipblock.units import STANDARD_GRAVITY


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
    # formats without a start time (PEER AT2, one-column text) leave obspy's epoch: not a time
    start = motion.starttime
    out.write(f"start       {start}\n" if start.year > 1970 else
              "start       not stated in the file (its reader's placeholder: 1970-01-01)\n")
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
