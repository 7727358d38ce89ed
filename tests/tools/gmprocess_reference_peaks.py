"""Read every file of the gmprocess test corpus with gmprocess's own readers; print a CSV of peaks."""
import csv, sys, os, glob, warnings, logging
import numpy as np
logging.disable(logging.CRITICAL)
warnings.simplefilter("ignore")
from gmprocess.io.read import read_data
root = sys.argv[1]
fmts = sys.argv[2].split(",")
w = csv.writer(sys.stdout)
w.writerow(["format", "file", "trace_id", "npts", "delta_s", "starttime", "peak_abs", "units", "units_type"])
for fmt in fmts:
    for path in sorted(glob.glob(f"{root}/{fmt}/**/*", recursive=True)):
        if os.path.isdir(path) or path.endswith((".json", ".yml", ".xml", ".zip")):
            continue
        rel = os.path.relpath(path, root)
        try:
            streams = read_data(path, read_format=('renadic' if fmt=='renadic' else None))
        except (Exception, BaseException) as exc:
            w.writerow([fmt, rel, "ERROR", "", "", "", "", type(exc).__name__, str(exc)[:120].replace("\n", " ")])
            continue
        for st in streams:
            for tr in st:
                std = tr.stats.get("standard", {})
                w.writerow([fmt, rel, tr.id, tr.stats.npts, repr(float(tr.stats.delta)), str(tr.stats.starttime),
                            repr(float(np.max(np.abs(tr.data)))), std.get("units", ""), std.get("units_type", "")])
        sys.stdout.flush()
