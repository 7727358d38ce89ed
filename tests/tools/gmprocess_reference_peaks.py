"""Write the reference table of gmprocess's readings of the real corpus (not a test).

Reads every file of the named corpus folders with gmprocess's own readers
(``gmprocess.io.read.read_data``; RENADIC asked for by name) and prints one CSV row per trace:
file, trace id, npts, delta, start time, peak |x| and gmprocess's units; a file gmprocess refuses
gets one ``ERROR`` row with the exception. ``tests/data/reference/gmprocess_2.8_peaks.csv`` was
made so, with gmprocess 2.8.0 (obspy 1.5.1) in a virtual environment of its own:

    python gmprocess_reference_peaks.py <testdata folder> bhrc,cosmos,csn,... > peaks.csv
"""

import csv
import glob
import logging
import os
import sys
import warnings

import numpy as np


def main(root: str, folders: list[str]) -> None:
    logging.disable(logging.CRITICAL)
    warnings.simplefilter("ignore")
    from gmprocess.io.read import read_data

    out = csv.writer(sys.stdout)
    out.writerow(["format", "file", "trace_id", "npts", "delta_s", "starttime", "peak_abs",
                  "units", "units_type"])
    for folder in folders:
        for path in sorted(glob.glob(f"{root}/{folder}/**/*", recursive=True)):
            if os.path.isdir(path) or path.endswith((".json", ".yml", ".xml", ".zip")):
                continue
            rel = os.path.relpath(path, root)
            try:
                streams = read_data(path, read_format="renadic" if folder == "renadic" else None)
            except BaseException as exc:  # noqa: BLE001 - gmprocess raises BaseException too
                if isinstance(exc, KeyboardInterrupt):
                    raise
                out.writerow([folder, rel, "ERROR", "", "", "", "", type(exc).__name__,
                              str(exc)[:120].replace("\n", " ")])
                continue
            for stream in streams:
                for trace in stream:
                    standard = trace.stats.get("standard", {})
                    out.writerow([folder, rel, trace.id, trace.stats.npts,
                                  repr(float(trace.stats.delta)), str(trace.stats.starttime),
                                  repr(float(np.max(np.abs(trace.data)))),
                                  standard.get("units", ""), standard.get("units_type", "")])


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2].split(","))
