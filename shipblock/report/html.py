"""A study's report as one self-contained HTML file.

The blocks of :func:`~shipblock.report.document.report_document`, each as its HTML element;
figures embedded as base64 PNG, so the file opens anywhere, without network or the files it
came from.
"""

from __future__ import annotations

import base64
import html
import io
import re
from collections.abc import Mapping

import matplotlib.pyplot as plt
import xarray as xr

from shipblock.report.document import (
    Figure,
    Heading,
    Links,
    Paragraph,
    Preformatted,
    Table,
    report_document,
)

__all__ = ["render_html", "report_html"]

#: Resolution of the embedded figures [dots per inch].
HTML_DPI = 110

_STYLE = """
body { font-family: sans-serif; max-width: 1100px; margin: 2em auto; color: #222; }
h1 { font-size: 1.5em; } h2 { border-bottom: 1px solid #999; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 3px 7px; text-align: left; vertical-align: top; }
th { background: #eee; } table.keys thead { display: none; }
table.keys td:first-child { font-weight: bold; white-space: nowrap; }
figure { margin: 1em 0; } img { max-width: 100%; border: 1px solid #ddd; }
pre { background: #f6f6f6; padding: 0.6em; overflow-x: auto; font-size: 0.85em; }
.small { font-size: 0.85em; color: #555; }
"""


def _e(value) -> str:
    return html.escape(str(value), quote=True)


def _inline(text: str) -> str:
    """Escaped text with each `command` as <code>."""
    return re.sub(r"`([^`]+)`", r"<code>\1</code>", _e(text))


def _table(block: Table) -> str:
    head = "".join(f"<th>{_e(h)}</th>" for h in block.header)
    body = "".join("<tr>" + "".join(f"<td>{_e(c)}</td>" for c in row) + "</tr>"
                   for row in block.rows)
    cls = "keys" if block.keys else ""
    return f'<table class="{cls}"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'


def _figure(block: Figure) -> str:
    """The figure drawn, as an embedded PNG (the figure is closed)."""
    fig = block.draw()
    buffer = io.BytesIO()
    try:
        fig.savefig(buffer, format="png", dpi=HTML_DPI)
    finally:
        plt.close(fig)
    data = base64.b64encode(buffer.getvalue()).decode("ascii")
    return f'<figure><img alt="{_e(block.alt)}" src="data:image/png;base64,{data}"></figure>'


def _element(block) -> str:
    if isinstance(block, Heading):
        return f"<h{block.level}>{_e(block.text)}</h{block.level}>"
    if isinstance(block, Paragraph):
        cls = " class='small'" if block.small else ""
        return f"<p{cls}>" + "<br>".join(_inline(line) for line in block.lines) + "</p>"
    if isinstance(block, Table):
        return _table(block)
    if isinstance(block, Preformatted):
        if block.summary:
            return (f"<details><summary>{_e(block.summary)}</summary><pre>{_e(block.text)}"
                    "</pre></details>")
        return f"<pre>{_e(block.text)}</pre>"
    if isinstance(block, Figure):
        return _figure(block)
    if isinstance(block, Links):
        return "<ul>" + "".join(f"<li><a href='{_e(link)}'>{_e(name)}</a></li>"
                                for name, link in block.items) + "</ul>"
    raise TypeError(f"not a report block: {block!r}")


def render_html(blocks) -> str:
    """The HTML document of report blocks (the first, a level-1 heading, is its title)."""
    title = blocks[0].text if blocks and isinstance(blocks[0], Heading) else "shipblock report"
    return "\n".join([f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
                      f"<title>{_e(title)}</title><style>{_STYLE}</style></head><body>",
                      *(_element(b) for b in blocks), "</body></html>"])


def report_html(ds: xr.Dataset, *, name: str = "results", spectra: Mapping | None = None,
                tables: Mapping[str, str] | None = None) -> str:
    """The report of a study result as one HTML document.

    Parameters
    ----------
    ds, name, spectra, tables
        As :func:`~shipblock.report.document.report_document`.

    Returns
    -------
    str
    """
    return render_html(report_document(ds, name=name, spectra=spectra, tables=tables))
