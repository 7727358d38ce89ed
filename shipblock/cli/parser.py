"""The argument parser of the ``shipblock`` command: its options, its sub-commands and the
argument groups they share (a record and how to read it, the system flags)."""

from __future__ import annotations

import argparse

from shipblock.cli._common import SYSTEM_FLAGS
from shipblock.cli.bench import cmd_bench
from shipblock.cli.records import cmd_catalogue, cmd_info, cmd_process
from shipblock.cli.risk import cmd_risk, cmd_select
from shipblock.cli.simulate import cmd_simulate
from shipblock.cli.study import cmd_export, cmd_history, cmd_plot, cmd_report, cmd_run


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
    g.add_argument("--system", help="TOML file with a [system] table (SI units, or quantities "
                                    "with units); model = \"section\" runs the dock-section "
                                    "model with the keys of a pipeline's [system]")
    for key, (flag, typ, help_) in SYSTEM_FLAGS.items():
        g.add_argument(flag, dest=key, type=typ, help=help_)
    g = s.add_argument_group("run")
    g.add_argument("--scale", type=float,
                   help="factor on the horizontal (and vertical); default 1")
    g.add_argument("--target-pga", metavar="PGA",
                   help="scale to this PGA of the horizontal, with its unit: 0.4g, 3.9m/s^2, "
                        "392gal (the vertical by the same factor unless --vertical-scale)")
    # one or the other: a factor on a vertical that is dropped would be ignored without a word
    vertical = g.add_mutually_exclusive_group()
    vertical.add_argument("--vertical-scale", type=float,
                          help="independent factor on the vertical (not with --no-vertical)")
    vertical.add_argument("--no-vertical", action="store_true",
                          help="ignore the vertical component (not with --vertical-scale)")
    g.add_argument("--rtol", type=float,
                   help="relative tolerance of the integration (default: 1e-8 for the rigid "
                        "model's rocking phases, the section model's own otherwise)")
    g.add_argument("--atol", type=float,
                   help="absolute tolerance of the integration, in the unit of each state: m "
                        "and m/s for displacements and velocities, rad and rad/s for rotations "
                        "(default: 1e-10 for the rigid model's rocking phases, the section "
                        "model's own, 1e-9, otherwise); checked against the model's range")
    g.add_argument("--no-exponential-steps", dest="exponential_steps", action="store_false",
                   help="section model: Dormand-Prince throughout, not one exponential step per "
                        "sample while the dock is in its static regime (slower, the same "
                        "response to the tolerance)")
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
    s.add_argument("--edp", help="demand parameter of the IDA curves (default: the model's, "
                                 "peak_ship_slip for the rigid model, keel_load_ratio for the "
                                 "section model)")
    s.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="value of a swept parameter to draw, e.g. --set mu_ground=0.5 "
                        "(repeatable; default: the first value of each)")
    s.add_argument("--against", metavar="NAME",
                   help="with --kind median: the swept parameter on the x axis (default: the "
                        "first)")
    s.add_argument("--limit-state", action="append", metavar="NAME",
                   help="with --kind fragility or median: draw only this limit state "
                        "(repeatable; default: all)")
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
    chain = s.add_mutually_exclusive_group()
    chain.add_argument("--no-processing", action="store_true",
                       help="spectra of the records as read (default: the default processing "
                            "chain; not with --processing)")
    chain.add_argument("--processing", metavar="FILE",
                       help="processing chain before the spectra: a TOML file with "
                            "[[processing]] steps, as a pipeline's (checked before any record "
                            "is read), or 'default', 'demean', 'none' as for simulate (not "
                            "with --no-processing)")
    s.add_argument("--ids", nargs="+", action="extend", metavar="ID",
                   help="only these catalogue records (default: all), e.g. --ids NP.1765 "
                        "NP.1764")
    s.add_argument("--damping", type=float, default=0.05, metavar="ZETA",
                   help="fraction of critical damping of the records' spectra, as the "
                        "target's [-] (default 0.05, i.e. 5 %%; not a percentage)")
    s.add_argument("--n-periods", type=int, default=30, metavar="N",
                   help="periods compared, log-spaced over the range (default 30)")
    s.add_argument("--no-suite-floor", action="store_true",
                   help="do not raise the suite's factors to meet the ASCE 7-16 90 %% floor "
                        "(default: raise them)")
    s.add_argument("--max-per-event", type=int, metavar="N",
                   help="at most N records from one earthquake (FEMA P-695 takes 2); the "
                        "earthquake from the catalogue's event_id, else the QuakeML event, the "
                        "record's header or event_name (default: no limit)")
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

    s = sub.add_parser("report", help="a study's report: one HTML or PDF file with its figures, "
                                      "and CSV tables",
                       description="Write a self-contained HTML (or PDF) report of a results "
                       "file of "
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
    s.add_argument("--format", choices=["html", "pdf"],
                   help="html (one self-contained file) or pdf (A4 pages, the same content); "
                        "default: from the suffix of --output, else html")
    s.add_argument("--output", "-o",
                   help="file to write (default: <results stem>_report.html beside the results, "
                        "or _report.pdf with --format pdf)")
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
