"""Sphinx configuration of the shipblock documentation.

Build with warnings as errors (as ``tests/test_docs.py`` does)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The example scripts (``docs/examples/plot_*.py``) run during every build; the verification page
shows figures they produce.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
# shipblock is normally installed (editable); this also lets a plain source tree build.
sys.path.insert(0, str(ROOT))

from docutils import nodes  # noqa: E402
from docutils.parsers.rst import directives  # noqa: E402
from docutils.statemachine import StringList  # noqa: E402
from sphinx.directives.other import TocTree  # noqa: E402
from sphinx.util import docname_join  # noqa: E402
from sphinx.util.docutils import SphinxDirective  # noqa: E402

import shipblock  # noqa: E402

# -- Project -------------------------------------------------------------------------------------
project = "shipblock"
author = "shipblock developers"
copyright = "shipblock developers"  # noqa: A001
release = shipblock.__version__
version = ".".join(release.split(".")[:2])

# -- Extensions ----------------------------------------------------------------------------------
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "auto_examples/*.ipynb",
                    "auto_examples/*.py", "auto_examples/*.zip", "**/*.codeobj.json",
                    "examples/README.rst"]
templates_path = ["_templates"]

# No intersphinx: the docs must build offline. References to numpy/obspy/xarray objects stay
# plain text.

# -- autodoc / autosummary / numpydoc ------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # the numpydoc sections carry types and units
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# -- MyST (Markdown pages) -----------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# -- sphinx-gallery ------------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(DOCS / "examples"),
    "gallery_dirs": str(DOCS / "auto_examples"),
    "filename_pattern": r"plot_",
    "plot_gallery": "True",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib",),
    "matplotlib_animations": False,
    "min_reported_time": 1,
    "show_memory": False,
    "abort_on_example_error": True,
}

# -- HTML ----------------------------------------------------------------------------------------
html_theme = "alabaster"
html_title = f"shipblock {release}"
html_static_path: list[str] = []
html_theme_options = {
    "description": "A ship on keel blocks in an earthquake",
    "fixed_sidebar": False,
    "page_width": "1100px",
    "sidebar_width": "230px",
}
html_sidebars = {"**": ["about.html", "navigation.html", "searchbox.html"]}

# -- Other ---------------------------------------------------------------------------------------
nitpicky = False
math_number_all = False
suppress_warnings = [
    # Module docstrings list their references without citing each one in the text
    # (``.. [1]`` with no ``[1]_``); that is intended, not a broken link.
    "ref.citation",
]

# -- Docstring fixes -----------------------------------------------------------------------------
# Known reST slips in docstrings, patched at build time so the build stays clean under -W.
# Each entry is (object name, text as written, text to render); an entry whose text is no longer
# found does nothing, so fixing the docstring in the source makes it obsolete (then delete it).
DOCSTRING_FIXES: list = []  # source docstrings are fixed; keep the hook for future ones


def _fix_docstrings(app, what, name, obj, options, lines):
    for target, old, new in DOCSTRING_FIXES:
        if name != target:
            continue
        for i, line in enumerate(lines):
            if old in line:
                lines[i] = line.replace(old, new)


class CommandHelp(SphinxDirective):
    """``.. shipblock-help:: [subcommand]``: the ``--help`` text of the command, at build time.

    Taken from :func:`shipblock.cli.build_parser`, so the page never drifts from the code.
    """

    optional_arguments = 1

    def run(self):
        from shipblock.cli import build_parser

        parser = build_parser()
        if self.arguments:
            name = self.arguments[0]
            sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
            parser = sub.choices[name]
        text = parser.format_help()
        node = nodes.literal_block(text, text)
        node["language"] = "text"
        return [node]


class PipelineKeys(SphinxDirective):
    """``.. pipeline-keys:: [model]``: the table of every pipeline key, at build time.

    Written by :func:`shipblock.fragility.keys.key_table` from the keys' declarations (those of
    ``[system]``, ``[solver]`` and ``[sweep]`` from the model named, default ``rigid``), so the
    page lists exactly what the parser accepts, with its type, unit, range and default. The
    option ``:sections: system sweep solver`` lists only those sections (a model's keys).
    """

    optional_arguments = 1
    option_spec = {"sections": directives.unchanged}

    def run(self):
        from shipblock.fragility.keys import key_table

        sections = self.options.get("sections")
        text = key_table(self.arguments[0] if self.arguments else None,
                         sections.split() if sections else None)
        container = nodes.container()
        self.state.nested_parse(StringList(text.splitlines(), source="<pipeline-keys>"),
                                self.content_offset, container)
        return container.children


class OptionalTocTree(TocTree):
    """``.. optional-toctree::``: a toctree that leaves out entries with no source file.

    Used for pages written separately (``theory/errata.md``, ``theory/derivation.md``), so the
    build does not depend on when they land.
    """

    def run(self):
        kept = [line for line in self.content
                if not line.strip()
                or docname_join(self.env.docname, line.strip()) in self.env.found_docs]
        self.content = StringList(kept, source=self.content.source(0) if self.content else "")
        return super().run()


def setup(app):
    os.environ["COLUMNS"] = "96"  # argparse wraps help text to this width
    app.connect("autodoc-process-docstring", _fix_docstrings)
    app.add_directive("shipblock-help", CommandHelp)
    app.add_directive("pipeline-keys", PipelineKeys)
    app.add_directive("optional-toctree", OptionalTocTree)
