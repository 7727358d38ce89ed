"""The ``shipblock`` command: simulate, process, info, catalogue, run, history, plot, export, risk,
select, report, bench.

The command only parses arguments, calls the library and prints; every computation lives in the
library. User errors print one line ``shipblock: error: ...`` and exit with status 2.
"""

from __future__ import annotations

import json
import logging
import signal
import sys
import time
from contextlib import contextmanager
from pathlib import Path

from shipblock.cli._common import SYSTEM_FLAGS, UserError, log
from shipblock.cli.parser import build_parser
from shipblock.cli.simulate import _system_from_args  # noqa: F401 (imported from here by tests)
from shipblock.processes import Terminated, terminate_as_interrupt

__all__ = ["COMPILED_PARTS", "SYSTEM_FLAGS", "UserError", "build_parser", "compile_message",
           "compile_notice", "compiled_part", "main"]


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
    # the dock-section model's kernel (shipblock.section): 51 s of one core for a first run's
    # call from an empty cache, nothing else running (session 21; 79-99 s before its spring
    # kinematics and forces were compiled once instead of inlined at every call site)
    ("shipblock.section", "the dock-section model", 50.0),
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
