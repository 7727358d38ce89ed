"""Cold start: the README's demo command from an empty numba cache, as a new user meets it.

Part of ``shipblock bench`` (:func:`shipblock.bench.run.run_benchmarks`). Each command runs in a
fresh Python process whose numba cache is a new, empty directory (``NUMBA_CACHE_DIR``), so
that everything the command needs is compiled, as after a fresh install; then again with that
cache filled. The child process, the command line with ``--compile-report``, measures how long
numba compiled each part (the solver, the intensity measures: :func:`shipblock.cli.compiled_part`)
with its own compile notice (:func:`shipblock.cli.compile_notice`); the parent measures the wall
time of the whole process, interpreter start included. The benchmark runs the command line as a
program and does not import it: the command line imports the benchmarks (``shipblock bench``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: Target of issue 21 [s]: the demo command from a fresh install, compilation included.
COLD_START_TARGET = 30.0


def demo_pipeline() -> Path | None:
    """The README's demo pipeline (``pipelines/demo.toml`` of a source checkout), or None."""
    path = Path(__file__).resolve().parents[2] / "pipelines" / "demo.toml"
    return path if path.is_file() else None


def run_command(args, cache_dir, work_dir):
    """Run ``shipblock <args>`` in a fresh process with numba's cache in ``cache_dir``.

    Returns
    -------
    dict
        ``wall`` [s] (the whole process), ``cpu`` [s] (the child's user + system time),
        ``compiled`` (seconds numba compiled, by part) and the exit ``code``.
    """
    result = Path(work_dir) / "cold-start-result.json"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache_dir)}
    package_root = str(Path(__file__).resolve().parents[2])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (package_root, env.get("PYTHONPATH")) if p)
    # The command line as its entry point runs it, with its report of what numba compiled
    # (``--compile-report``, written by the child: :func:`shipblock.cli.main`).
    cmd = [sys.executable, "-c",
           "import sys; from shipblock.cli import main; sys.exit(main(sys.argv[1:]))",
           "-q", "--compile-report", str(result), *map(str, args)]
    t0 = time.perf_counter()
    subprocess.run(cmd, env=env, cwd=work_dir, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    return {"wall": wall, **json.loads(result.read_text())}


def cold_start(directory=None):
    """Time the demo command with an empty numba cache, then with it filled; and ``info``.

    The demo is ``shipblock run pipelines/demo.toml --output demo.nc --figure demo.png``
    (48 runs, 14 histories, fits with 200 bootstrap resamples each); ``info --record NP.1765``
    compiles only the intensity measures.

    Parameters
    ----------
    directory : str or os.PathLike, optional
        Work directory (outputs and the numba caches; kept); default: a temporary one.

    Returns
    -------
    dict or None
        ``cold`` and ``warm`` (see :func:`run_command`) of the demo, ``info_cold``, the load
        average before and after, ``target`` [s]; None outside a source checkout (no demo
        pipeline).
    """
    pipeline = demo_pipeline()
    if pipeline is None:
        return None
    with tempfile.TemporaryDirectory(prefix="shipblock-cold-") as tmp:
        work = Path(directory) if directory is not None else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        load = os.getloadavg() if hasattr(os, "getloadavg") else None
        demo = ["run", str(pipeline), "--output", str(work / "demo.nc"), "--figure",
                str(work / "demo.png")]
        cold = run_command(demo, work / "numba-cache", work)
        warm = run_command(demo, work / "numba-cache", work)
        info = run_command(["info", "--record", "NP.1765"], work / "numba-cache-info", work)
    return {"cold": cold, "warm": warm, "info_cold": info, "target": COLD_START_TARGET,
            "load_average_before": load,
            "load_average_after": os.getloadavg() if hasattr(os, "getloadavg") else None}


def write_cold_start(out, c):
    """Print the figures of :func:`cold_start`."""
    if c is None:
        out.write("cold start        : skipped (pipelines/demo.toml of a source checkout not "
                  "found)\n")
        return
    cold, warm, info = c["cold"], c["warm"], c["info_cold"]
    parts = ", ".join(f"{what} {seconds:.1f} s" for what, seconds in cold["compiled"].items())
    load = c["load_average_before"]
    load = "" if load is None else f"; load average {load[0]:.2f} before"
    ok = cold["wall"] <= c["target"] and cold["code"] == 0
    out.write(f"cold start        : README demo from an empty numba cache {cold['wall']:.1f} s "
              f"(CPU {cold['cpu']:.1f} s; compiling {parts}), with the cache filled "
              f"{warm['wall']:.1f} s (target {c['target']:.0f} s: {'met' if ok else 'NOT met'}"
              f"{load}); 'shipblock info' from an empty cache {info['wall']:.1f} s (compiling "
              + (", ".join(f"{w} {s:.2f} s" for w, s in info["compiled"].items()) or "nothing")
              + ")\n")
