"""Every module of the package stays readable: at most 800 lines (issue 28), the compiled solver
kernel excepted (its hot loop is one function, numba compiles it as a whole).

``OVER_THE_LIMIT`` lists the modules still above the limit, each with the work that splits it;
the second test fails once one of them is split, so that the list only shrinks.
"""

from __future__ import annotations

from pathlib import Path

import shipblock

#: Most lines a module may have.
MAX_LINES = 800

#: The module exempt from the limit, relative to the package.
EXEMPT = {"solver/_kernel.py"}

#: Modules above the limit today, and what splits them.
OVER_THE_LIMIT = {
    "solver/_closed_form.py": "the solver's closed-form spans (813 lines)",
}

ROOT = Path(shipblock.__file__).resolve().parent


def _lines() -> dict[str, int]:
    return {p.relative_to(ROOT).as_posix(): len(p.read_text(encoding="utf-8").splitlines())
            for p in sorted(ROOT.rglob("*.py"))}


def test_no_module_is_longer_than_800_lines():
    lines = _lines()
    assert len(lines) > 50  # the package was found, not an empty directory
    too_long = {path: n for path, n in lines.items()
                if n > MAX_LINES and path not in EXEMPT and path not in OVER_THE_LIMIT}
    assert not too_long, (f"modules over {MAX_LINES} lines (split them along their concerns,"
                          f" docs/architecture.rst): {too_long}")


def test_the_list_of_modules_over_the_limit_only_shrinks():
    lines = _lines()
    split = sorted(path for path in OVER_THE_LIMIT if lines.get(path, 0) <= MAX_LINES)
    assert not split, f"{split} are within {MAX_LINES} lines now: remove them from OVER_THE_LIMIT"
