"""First use: commands that do not simulate compile nothing of the solver; the notice names what
is compiled. Speed is measured by ``shipblock bench`` (its cold start), not here."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from shipblock.cli import COMPILED_PARTS, compile_message, compiled_part, main

ROOT = Path(__file__).resolve().parents[1]

# runs the given commands in a fresh process with an empty numba cache and prints, as JSON, the
# modules of the functions numba compiled and whether the solver was even imported
_CHILD = """
import json, sys
from numba.core import event
from shipblock.cli import main

compiled = []

class Record(event.Listener):
    def on_start(self, ev):
        d = (ev.data or {}).get("dispatcher")
        compiled.append(getattr(getattr(d, "py_func", None), "__module__", "?"))
    def on_end(self, ev):
        pass

codes = []
with event.install_listener("numba:compile", Record()):
    for argv in json.loads(sys.argv[1]):
        codes.append(main(["-q", *argv]))
print(json.dumps({"codes": codes, "compiled": sorted(set(compiled)),
                  "solver_imported": "shipblock.solver._kernel" in sys.modules}))
"""


def test_commands_that_do_not_simulate_compile_nothing_of_the_solver(tmp_path, capsys):
    history = tmp_path / "r.nc"
    # a response history to plot, made here (this process may compile the solver)
    assert main(["-q", "simulate", "--record", "NP.1765", "--scale", "0.5", "--output",
                 str(history)]) == 0
    capsys.readouterr()
    commands = [
        ["info", "--record", "NP.1765"],
        ["process", "--record", "NP.1743", "-o", str(tmp_path / "processed")],
        ["plot", str(history), "--figure", str(tmp_path / "again.png")],
        ["catalogue", str(ROOT / "records"), "-o", str(tmp_path / "catalogue.toml")],
    ]
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "empty-cache"),
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    child = subprocess.run([sys.executable, "-c", _CHILD, json.dumps(commands)], env=env,
                           capture_output=True, text=True, timeout=600, check=True)
    result = json.loads(child.stdout.strip().splitlines()[-1])
    assert result["codes"] == [0, 0, 0, 0]
    solver = [m for m in result["compiled"]
              if compiled_part(m)[0] == "the solver"]
    assert solver == [], f"compiled: {result['compiled']}"
    assert not result["solver_imported"]
    # what they do compile (the intensity measures of info and process) is named as such
    assert all(not m.startswith("shipblock.") or compiled_part(m)[1] is not None
               for m in result["compiled"]), result["compiled"]


def test_notice_names_the_part_and_its_measured_time():
    assert compiled_part("shipblock.solver._kernel")[0] == "the solver"
    assert compiled_part("shipblock.equations")[0] == "the solver"
    assert compiled_part("shipblock.intensity")[0] == "the intensity measures"
    assert compiled_part("shipblock.solverish")[1] is None  # a prefix is a whole module name
    solver_seconds = compiled_part("shipblock.solver")[1]
    intensity_seconds = compiled_part("shipblock.intensity")[1]
    assert 0 < intensity_seconds < solver_seconds < 60  # the first use is no longer minutes
    msg = compile_message("the solver", solver_seconds)
    assert "the solver" in msg and f"{solver_seconds:.2g} s" in msg and "minute" not in msg
    assert {what for _, what, _ in COMPILED_PARTS} == {"the solver", "the contact loads",
                                                       "the intensity measures",
                                                       "the dock-section model"}


def test_every_module_with_compiled_code_is_a_known_part():
    """The notice names what compiles: no numba module of shipblock is left to the generic
    'numba code of ...' wording."""
    import importlib
    import pkgutil

    import shipblock

    compiled = set()
    for info in pkgutil.walk_packages(shipblock.__path__, "shipblock."):
        source = importlib.util.find_spec(info.name).origin
        if source and source.endswith(".py") and "@njit" in Path(source).read_text():
            compiled.add(info.name)
    assert "shipblock.solver._kernel" in compiled and "shipblock.interface_forces" in compiled
    # the bench's own control loop is timed by the bench itself
    assert {m for m in compiled if compiled_part(m)[1] is None} == {"shipblock.bench.timing"}


@pytest.mark.parametrize("module", ["shipblock.solver._kernel", "shipblock.solver._stuck_rocking",
                                    "shipblock.equations", "shipblock.impact"])
def test_every_solver_module_is_a_known_part(module):
    __import__(module)
    assert compiled_part(module)[0] == "the solver"


def test_read_only_records_use_the_same_compiled_solver():
    """numba types a read-only array apart; simulate must not compile the solver again for one."""
    import numpy as np

    from shipblock import ShipBlockSystem, simulate
    from shipblock.solver import _kernel

    system = ShipBlockSystem(ship_mass=2e5, block_mass=500.0, n_blocks=8, half_width=0.3,
                             half_height=0.6, mu_s_ground=0.3, mu_k_ground=0.25, mu_s_ship=0.7,
                             mu_k_ship=0.6)
    t = np.arange(1500) * 0.01
    ax = 4.0 * np.sin(2 * np.pi * 1.5 * t)
    ay = 0.3 * ax
    writable = simulate(system, ax, ay, 0.01)
    signatures = len(_kernel.run_cases.signatures)
    ax.flags.writeable = False
    ay.flags.writeable = False
    read_only = simulate(system, ax, ay, 0.01)
    horizontal_only = simulate(system, ax, None, 0.01)
    assert len(_kernel.run_cases.signatures) == signatures
    np.testing.assert_array_equal(read_only.x_b, writable.x_b)
    assert writable.summary["peak_block_slip"] > 0.0  # the record does move the blocks
    assert horizontal_only.summary["peak_block_slip"] > 0.0


_ONE_KERNEL = """
import json
import numpy as np
from shipblock import RecordSet, ShipBlockSystem, simulate, simulate_batch
from shipblock.solver import _kernel as K

system = ShipBlockSystem.example()
ax = 3.0 * np.sin(np.linspace(0.0, 20.0, 400))
simulate(system, ax, 0.3 * ax, 0.01)
simulate(system, ax, None, 0.01)
simulate_batch(system, [(ax, None), (ax, 0.5 * ax)], 0.01, [(0, 0, 1.0, 1.0), (1, 0, 2.0, 1.0)])
simulate_batch([system, system.replace(n_blocks=10)], RecordSet([(ax, None)], [0.01]),
               cases=[(0, 1, 1.0, 1.0)])
print(json.dumps({"run_cases": len(K.run_cases.signatures)}))
"""


def test_every_entry_point_shares_one_compiled_kernel():
    """simulate (histories, with and without a vertical input) and simulate_batch (one system
    or several, records listed or packed) all call the kernel with the same argument types:
    the solver is compiled once, not once more for, say, a read-only parameter array."""
    out = subprocess.run([sys.executable, "-c", _ONE_KERNEL], capture_output=True, text=True,
                         cwd=ROOT, timeout=600, check=True)
    assert json.loads(out.stdout.strip().splitlines()[-1]) == {"run_cases": 1}
