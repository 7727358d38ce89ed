"""``shipblock report --format pdf``: the HTML report's content on A4 pages (matplotlib's
PdfPages, no other dependency); the numbers on the pages are those of the CSV tables."""

from __future__ import annotations

import re
import shutil
import subprocess

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
import xarray as xr

from shipblock.cli import main
from shipblock.errors import ParameterError
from shipblock.plot import study_caption
from shipblock.report import pdf_pages, report_document, write_report
from shipblock.report.document import Figure, Heading, Paragraph, Table
from shipblock.risk import run_risk

from .test_report_html import PGA_CURVES, demo  # noqa: F401 - the module's study fixture


@pytest.fixture(scope="module")
def risk_file(demo, tmp_path_factory):  # noqa: F811 - the fixture imported above
    out = tmp_path_factory.mktemp("risk") / "risk.nc"
    run_risk(demo, PGA_CURVES, 120, site="San Francisco CA", output=out)
    return out


@pytest.fixture(scope="module")
def written(demo, risk_file, tmp_path_factory):  # noqa: F811
    """The PDF report of the demo study with its risk, by the command line."""
    out = tmp_path_factory.mktemp("pdf") / "rep" / "report.pdf"
    assert main(["-q", "report", str(demo), "--hazard-results", str(risk_file),
                 "--format", "pdf", "-o", str(out)]) == 0
    return out


def _page_texts(blocks, name):
    pages = []
    for page in pdf_pages(blocks, name=name):
        pages.append([t.get_text() for t in page.texts])
        plt.close(page)
    return pages


def _blocks(risk_file, tables):
    with xr.open_dataset(risk_file) as ds:
        ds = ds.load()
    return ds, report_document(ds, name="demo.nc", tables=tables)


def test_the_pdf_has_a_page_per_laid_out_page_and_the_report_title(written, risk_file):
    data = written.read_bytes()
    assert data.startswith(b"%PDF-") and data.rstrip().endswith(b"%%EOF")
    ds, blocks = _blocks(risk_file, {"runs.csv": "report_csv/runs.csv",
                                     "fragility.csv": "report_csv/fragility.csv"})
    pages = _page_texts(blocks, "demo.nc")
    # the page objects and the page tree's count (matplotlib writes them uncompressed)
    assert len(re.findall(rb"/Type /Page\b", data)) == len(pages) >= 4
    assert re.search(rb"/Type /Pages /Kids \[[^\]]*\] /Count %d\b" % len(pages), data)
    # the document information: title, and shipblock as its creator
    assert b"/Title (" + ds.attrs["title"].encode() + b")" in data
    assert b"/Creator (shipblock " in data
    # one image per figure (opaque: no soft masks), the figures of the HTML report
    figures = [b for b in blocks if isinstance(b, Figure)]
    assert len(re.findall(rb"/Subtype /Image", data)) == len(figures) == 3
    # every page numbered, the sections in the HTML's order, each figure captioned
    for i, texts in enumerate(pages, start=1):
        assert f"shipblock report of demo.nc: page {i} of {len(pages)}" in texts
    lines = [t for texts in pages for t in texts]
    headings = [b.text for b in blocks if isinstance(b, Heading) and b.level == 2]
    assert headings == ["1. Study", "2. Records", "3. Limit states", "4. Fragility",
                        "5. Risk over the docking period", "6. Tables"]
    assert [t for t in lines if t in headings] == headings
    for n, fig in enumerate(figures, start=1):
        assert f"Figure {n}: {fig.alt}." in lines


def test_numbers_on_the_pages_are_those_of_the_csv_tables(written, risk_file):
    table = pd.read_csv(written.parent / "report_csv" / "fragility.csv")
    _, blocks = _blocks(risk_file, None)
    pages = _page_texts(blocks, "demo.nc")
    lines = [t for texts in pages for t in texts]
    # the fit table: each cell on its own line of text, in the row's order
    for _, row in table.iterrows():
        cells = [row["limit_state"], f"{row['median_g [g]']:.3g}",
                 f"{row['median_lower_g [g]']:.3g} to {row['median_upper_g [g]']:.3g}",
                 f"{row['beta [-]']:.3f}"]
        first = [i for i, t in enumerate(lines) if t == cells[0]]
        assert any(lines[i:i + 4] == cells for i in first), cells
        rate = row["risk_annual_rate [1/yr]"]
        lo, hi = row["risk_annual_rate_lower [1/yr]"], row["risk_annual_rate_upper [1/yr]"]
        assert f"{rate:.3g} ({lo:.3g} to {hi:.3g})" in lines
        assert f"{1 / rate:.4g}" in lines
    # the same cells as the HTML report's tables: one content, two renderings
    cells = {c for b in blocks if isinstance(b, Table) for r in b.rows for c in r
             if re.fullmatch(r"[-+0-9.e]+", c)}
    assert cells and cells <= set(lines)


@pytest.mark.skipif(shutil.which("pdftotext") is None, reason="poppler's pdftotext not installed")
def test_a_pdf_reader_finds_the_text(written):
    """The fonts are embedded as TrueType (pdf.fonttype 42): a reader extracts the text."""
    text = subprocess.run(["pdftotext", "-layout", str(written), "-"], capture_output=True,
                          text=True, check=True).stdout
    table = pd.read_csv(written.parent / "report_csv" / "fragility.csv")
    assert "4. Fragility" in text and "5. Risk over the docking period" in text
    for _, row in table.iterrows():
        assert re.search(rf"{row['limit_state']}\s+{row['median_g [g]']:.3g}\s+"
                         rf"{row['median_lower_g [g]']:.3g} to {row['median_upper_g [g]']:.3g}",
                         text), row["limit_state"]


def test_figures_are_titled_with_study_system_and_design(risk_file):
    ds, blocks = _blocks(risk_file, None)
    caption = study_caption(ds)
    assert caption[1].startswith("system:") and caption[2].startswith("design:")
    for block in (b for b in blocks if isinstance(b, Figure)):
        fig = block.draw()
        titles = [fig._suptitle.get_text() if fig._suptitle else ""]
        titles += [ax.get_title(loc="left") for ax in fig.axes]
        plt.close(fig)
        text = " ".join(titles).replace("\n", " ")
        for line in caption:  # each line wrapped, so compare word by word
            assert " ".join(line.split()) in " ".join(text.split()), (block.alt, line)


def test_format_from_the_suffix_the_flag_and_refused_by_name(demo, tmp_path, monkeypatch):  # noqa: F811
    written = write_report(demo, tmp_path / "r.pdf")
    assert written[0].read_bytes().startswith(b"%PDF-")
    html = write_report(demo, tmp_path / "r.html")
    assert html[0].read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    monkeypatch.chdir(tmp_path)
    assert main(["-q", "report", str(demo), "--format", "pdf"]) == 0
    # without --output, beside the results it reads and named after them; not in the cwd
    beside = demo.with_name(f"{demo.stem}_report.pdf")
    assert beside.read_bytes().startswith(b"%PDF-")
    assert (demo.parent / f"{demo.stem}_report_csv" / "fragility.csv").exists()
    assert not (tmp_path / "report.pdf").exists()
    with pytest.raises(ParameterError, match="format"):
        write_report(demo, tmp_path / "r.doc", format="docx")
    assert not list(tmp_path.glob("*.part"))
    # the same study through the API and the command line: as many pages
    a, b = (np.array(re.findall(rb"/Type /Page\b", p.read_bytes())).size
            for p in (tmp_path / "r.pdf", beside))
    assert a == b


# -- a heading is kept with what follows it --------------------------------------------------

def _filler(n):
    """A paragraph of ``n`` lines: moves what follows it down the first page, line by line."""
    return Paragraph(tuple(f"filler line {i}" for i in range(n)))


def _plain_figure():
    fig = plt.figure(figsize=(7.0, 4.5))
    fig.add_subplot().plot([0.0, 1.0], [0.0, 1.0])
    return fig


def _page_of(pages, text):
    (page,) = [i for i, texts in enumerate(pages) if text in texts]
    return page


@pytest.mark.parametrize("filler", range(40, 80, 3))
def test_a_heading_starts_the_page_of_its_table_or_figure(filler):
    """From every height of the text above, a section's heading (and its one-line
    introduction) shares its page with the first row of its table and with its figure: a
    heading was left alone at a page's foot when its table (short, kept whole) or its figure
    did not fit below it but 1.4 in did."""
    rows = tuple((f"cell {i}", f"{i}") for i in range(14))  # 2.1 in: short, kept on one page
    blocks = [Heading("Report", 1), _filler(filler),
              Heading("A table", 2), Paragraph(("The rows, one per record.",)),
              Table(("name", "value"), rows),
              _filler(filler // 2),
              Heading("A figure", 3), Figure(_plain_figure, "a line"),
              Heading("The end", 2), Paragraph(("Last words.",))]
    pages = _page_texts(blocks, "t.nc")
    for heading, first in (("A table", "cell 0"), ("A figure", "Figure 1: a line."),
                           ("The end", "Last words.")):
        assert _page_of(pages, heading) == _page_of(pages, first), (heading, pages)
    assert _page_of(pages, "The rows, one per record.") == _page_of(pages, "A table")
    assert len(pages) <= 4  # nothing moved more than it had to


def test_a_heading_over_a_page_filling_figure_stays_where_it_was():
    """A figure as tall as a page cannot share one with its heading: the heading is not moved
    to a page of its own."""
    tall = Figure(lambda: plt.figure(figsize=(7.0, 12.0)), "a tall one")
    blocks = [Heading("Report", 1), _filler(20), Heading("Tall", 2), tall]
    pages = _page_texts(blocks, "t.nc")
    assert len(pages) == 2
    assert _page_of(pages, "Tall") == 0 and _page_of(pages, "Figure 1: a tall one.") == 1
