"""A study's report as a PDF: the blocks of the HTML report laid out on A4 pages.

:func:`pdf_pages` lays the blocks of :func:`~shipblock.report.document.report_document` out
top to bottom on A4 portrait pages (matplotlib figures of text, rules and images) and
:func:`write_pdf` writes them with matplotlib's :class:`~matplotlib.backends.backend_pdf.PdfPages`:
no other dependency. Headings, paragraphs and tables are text (TrueType, ``pdf.fonttype = 42``,
so a reader can search and copy it); tables are set in a monospaced font, their columns as wide
as their longest cell within the page, wrapped when the page is too narrow, and split across
pages with the header repeated; each figure is drawn once and placed as an image of
:data:`PDF_DPI` dots per inch, scaled to the page's width, with its description under it. A
heading is kept with what follows it (:func:`_keep_with_next`): with its short introduction
and at least the first rows of its table, the first lines of its text or its whole figure;
when these do not fit below it, the heading starts the next page. Every page has the report's
title at its top and ``page i of n`` at its foot.
"""

from __future__ import annotations

import contextlib
import io
import logging
import textwrap
from dataclasses import dataclass

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.lines import Line2D

from shipblock import __version__
from shipblock.report.document import Figure, Heading, Links, Paragraph, Preformatted, Table

__all__ = ["PAGE_SIZE", "PDF_DPI", "pdf_pages", "write_pdf"]

#: A4 portrait [in].
PAGE_SIZE = (8.27, 11.69)

#: Resolution of the figures placed on the pages [dots per inch].
PDF_DPI = 200

_MARGIN = 0.6  # [in]
_TOP = 0.85  # first line below the running head [in]
_BOTTOM = 0.75  # lowest line above the page number [in]
_WIDTH = PAGE_SIZE[0] - 2 * _MARGIN

#: Font sizes [pt] and the width of a character of each, as a fraction of the size: exact for
#: the monospaced font (DejaVu Sans Mono), a wide average for the proportional one.
_SIZES = {"h1": 15.0, "h2": 12.0, "h3": 10.0, "body": 8.5, "small": 7.5, "mono": 6.5}
_CHAR = {"sans": 0.60, "mono": 0.602}
_LEADING = 1.3  # line height / font size

#: A heading needs this much space below it on its page, or it goes to the next [in].
_KEEP_WITH_NEXT = 1.4

#: A paragraph of at most this many lines between a heading and a table, text or figure
#: introduces it, and is kept with both [lines].
_INTRO_LINES = 3

#: A column is narrowed below its longest word only after every other column [characters].
_LONG_WORD = 24

#: A table shorter than this is kept on one page [in].
_SHORT_TABLE = 3.0


def _line_height(size: float) -> float:
    return _LEADING * size / 72.0


def _columns(size: float, font: str = "sans") -> int:
    """Characters of a line of the text width."""
    return int(_WIDTH * 72.0 / (_CHAR[font] * size))


@dataclass
class _Op:
    """One thing drawn on a page: text (``kind`` "text"), a rule ("rule") or an image."""

    kind: str
    y: float  # top [in from the page's top]
    x: float = _MARGIN  # left [in]
    text: str = ""
    size: float = _SIZES["body"]
    font: str = "sans-serif"
    weight: str = "normal"
    color: str = "black"
    style: str = "normal"
    width: float = 0.0  # rule or image [in]
    height: float = 0.0  # image [in]
    image: np.ndarray | None = None


class _Layout:
    """Pages of drawing operations, filled from the top."""

    def __init__(self):
        self.pages: list[list[_Op]] = [[]]
        self.y = _TOP

    @property
    def room(self) -> float:
        return PAGE_SIZE[1] - _BOTTOM - self.y

    def new_page(self) -> None:
        if self.pages[-1]:
            self.pages.append([])
        self.y = _TOP

    def need(self, height: float) -> None:
        """A new page unless ``height`` fits below the cursor (or the page is empty)."""
        if height > self.room and self.pages[-1]:
            self.new_page()

    def mark(self) -> tuple[int, int, float]:
        """Where the layout stands: pages, operations on the last page, cursor."""
        return len(self.pages), len(self.pages[-1]), self.y

    def undo(self, mark: tuple[int, int, float]) -> None:
        """Back to ``mark``: what was laid out since is taken away."""
        pages, ops, self.y = mark
        del self.pages[pages:]
        del self.pages[-1][ops:]

    def page_after(self, mark: tuple[int, int, float]) -> int | None:
        """The page of the first operation laid out since ``mark`` (None: none)."""
        pages, ops, _ = mark
        if len(self.pages[pages - 1]) > ops:
            return pages - 1
        return next((i for i in range(pages, len(self.pages)) if self.pages[i]), None)

    def add(self, op: _Op, height: float) -> None:
        op.y = self.y
        self.pages[-1].append(op)
        self.y += height

    def text_lines(self, lines, size, **props) -> None:
        step = _line_height(size)
        for line in lines:
            self.need(step)
            self.add(_Op("text", 0.0, text=line, size=size, **props), step)


def _wrap(text: str, width: int) -> list[str]:
    out = []
    for line in str(text).splitlines() or [""]:
        out += textwrap.wrap(line, width, break_long_words=True, replace_whitespace=False,
                             drop_whitespace=True) or [""]
    return out


def _heading(layout: _Layout, block: Heading) -> None:
    size = _SIZES[f"h{min(block.level, 3)}"]
    if block.level > 1:
        layout.need(_KEEP_WITH_NEXT)
        layout.y += 0.35 * size / 72.0 * (2.0 if block.level == 2 else 1.0)
    layout.text_lines(_wrap(block.text, _columns(size)), size, weight="bold")
    if block.level == 2:
        layout.add(_Op("rule", 0.0, width=_WIDTH, color="0.55"), 0.06)
    layout.y += 0.04


def _paragraph(layout: _Layout, block: Paragraph) -> None:
    size = _SIZES["small" if block.small else "body"]
    color = "0.3" if block.small else "black"
    for line in block.lines:
        layout.text_lines(_wrap(line.replace("`", ""), _columns(size)), size, color=color)
    layout.y += 0.06


def _column_widths(rows, available: int) -> list[int]:
    """Each column as wide as its longest cell; while the row is too wide, the widest column
    still wider than its longest word (at most :data:`_LONG_WORD` characters) is narrowed,
    then, if that is not enough, the widest of all (its words broken)."""
    columns = list(zip(*rows, strict=True))
    widths = [max(1, max(len(line) for cell in col for line in str(cell).splitlines() or [""]))
              for col in columns]
    words = [min(_LONG_WORD, max((len(w) for cell in col for w in str(cell).split()), default=1))
             for col in columns]
    while sum(widths) > available:
        wide = [j for j, (w, m) in enumerate(zip(widths, words, strict=True)) if w > m]
        if not wide:
            wide = [j for j, w in enumerate(widths) if w > 6]
        if not wide:
            break
        widths[max(wide, key=lambda j: widths[j])] -= 1
    return widths


def _table(layout: _Layout, block: Table) -> None:
    size = _SIZES["mono"]
    step = _line_height(size)
    gap = 2  # characters between columns
    rows = [list(r) for r in block.rows]
    header = None if block.keys else list(block.header)
    if not rows and header is None:
        return
    ncol = len(header) if header is not None else len(rows[0])
    available = _columns(size, "mono") - gap * (ncol - 1)
    widths = _column_widths(([header] if header else []) + rows, available)
    char = _CHAR["mono"] * size / 72.0
    xs = _MARGIN + np.concatenate([[0.0], np.cumsum(np.array(widths) + gap)[:-1]]) * char
    table_width = min(_WIDTH, (sum(widths) + gap * (ncol - 1)) * char)

    def draw_row(cells, bold_first=False, bold=False):
        wrapped = [_wrap(c, w) for c, w in zip(cells, widths, strict=True)]
        height = max(len(w) for w in wrapped) * step
        layout.need(height + step)
        top = layout.y
        for j, (x, lines) in enumerate(zip(xs, wrapped, strict=True)):
            weight = "bold" if bold or (bold_first and j == 0) else "normal"
            for k, line in enumerate(lines):
                layout.pages[-1].append(_Op("text", top + k * step, x=float(x), text=line,
                                            size=size, font="monospace", weight=weight))
        layout.y = top + height

    def draw_header():
        draw_row(header, bold=True)
        layout.add(_Op("rule", 0.0, width=table_width, color="0.2"), 0.04)

    layout.y += 0.03
    lines = sum(max(len(_wrap(c, w)) for c, w in zip(r, widths, strict=True))
                for r in ([header] if header else []) + rows)
    whole = lines * step + (len(rows) + 1) * 0.04
    if whole < _SHORT_TABLE:  # a short table is not split
        layout.need(whole)
    if header is not None:
        draw_header()
    for row in rows:
        wrapped_height = max(len(_wrap(c, w)) for c, w in zip(row, widths, strict=True)) * step
        if wrapped_height + step > layout.room and layout.pages[-1]:
            layout.new_page()
            if header is not None:
                draw_header()
        draw_row(row, bold_first=block.keys)
        layout.add(_Op("rule", 0.0, width=table_width, color="0.85"), 0.03)
    layout.y += 0.08


def _preformatted(layout: _Layout, block: Preformatted) -> None:
    if block.summary:
        layout.need(_KEEP_WITH_NEXT / 2)
        layout.text_lines([block.summary], _SIZES["body"], style="italic")
    size = _SIZES["mono"]
    lines = _wrap(block.text.expandtabs(4), _columns(size, "mono"))
    layout.text_lines(lines, size, font="monospace", color="0.15")
    layout.y += 0.08


def _rendered(block: Figure) -> np.ndarray:
    """The figure drawn once, as an RGB image of :data:`PDF_DPI` (the figure is closed)."""
    fig = block.draw()
    buffer = io.BytesIO()
    try:
        fig.savefig(buffer, format="png", dpi=PDF_DPI)
    finally:
        plt.close(fig)
    buffer.seek(0)
    # opaque (a figure's white face): RGB only, so the PDF holds one image and no mask
    return (plt.imread(buffer, format="png")[..., :3] * 255).round().astype(np.uint8)


def _figure(layout: _Layout, block: Figure, number: int, image: np.ndarray) -> None:
    height_px, width_px = image.shape[:2]
    caption = _wrap(f"Figure {number}: {block.alt}.", _columns(_SIZES["small"]))
    caption_height = len(caption) * _line_height(_SIZES["small"])
    width = min(_WIDTH, width_px / PDF_DPI)
    height = width * height_px / width_px
    usable = PAGE_SIZE[1] - _TOP - _BOTTOM - caption_height - 0.1
    if height > usable:  # a tall figure fills a page
        height, width = usable, usable * width_px / height_px
    layout.need(height + caption_height + 0.1)
    layout.add(_Op("image", 0.0, width=width, height=height, image=image), height + 0.05)
    layout.text_lines(caption, _SIZES["small"], style="italic", color="0.3")
    layout.y += 0.12


def _links(layout: _Layout, block: Links) -> None:
    layout.text_lines([f"{name}: {link}" for name, link in block.items], _SIZES["body"],
                      font="monospace")


def _is_intro(block) -> bool:
    """Whether ``block`` is a short paragraph, an introduction to what follows it."""
    return isinstance(block, Paragraph) and not block.small and sum(
        len(_wrap(line, _columns(_SIZES["body"]))) for line in block.lines) <= _INTRO_LINES


def _keep_with_next(blocks, start: int) -> int:
    """The end (exclusive) of the group that starts with the heading ``blocks[start]``: the
    headings in a row, the short paragraphs introducing what follows them, and the first
    block that is neither (the content kept with the headings)."""
    end = start
    while end < len(blocks) and isinstance(blocks[end], Heading):
        end += 1
    while (end + 1 < len(blocks) and _is_intro(blocks[end])
           and not isinstance(blocks[end + 1], Heading)):
        end += 1
    return min(end + 1, len(blocks))


def _layout(blocks) -> _Layout:
    """The blocks on pages. A heading's group (:func:`_keep_with_next`) is laid out, and if its
    content begins on a later page than its last heading, laid out again from the top of the
    next page, unless the content would not begin on the heading's page there either (a
    figure as tall as a page), where it stays as it was."""
    layout = _Layout()
    numbers = {id(b): n for n, b in enumerate((b for b in blocks if isinstance(b, Figure)), 1)}
    images = {}  # each figure drawn once, however often its group is laid out

    def lay(block):
        if isinstance(block, Heading):
            _heading(layout, block)
        elif isinstance(block, Paragraph):
            _paragraph(layout, block)
        elif isinstance(block, Table):
            _table(layout, block)
        elif isinstance(block, Preformatted):
            _preformatted(layout, block)
        elif isinstance(block, Figure):
            if id(block) not in images:
                images[id(block)] = _rendered(block)
            _figure(layout, block, numbers[id(block)], images[id(block)])
        elif isinstance(block, Links):
            _links(layout, block)
        else:
            raise TypeError(f"not a report block: {block!r}")

    def lay_group(group) -> bool:
        """Lay ``group`` out; whether its content begins on its last heading's page (so its
        introductions, between them, are there too)."""
        headings = [b for b in group if isinstance(b, Heading)]
        for block in headings:
            lay(block)
        heading_page = len(layout.pages) - 1
        rest = group[len(headings):]
        for block in rest[:-1]:  # the introductions
            lay(block)
        if not rest:  # the document ends with headings
            return True
        before_content = layout.mark()
        lay(rest[-1])
        return layout.page_after(before_content) in (None, heading_page)

    i = 0
    while i < len(blocks):
        if not isinstance(blocks[i], Heading):
            lay(blocks[i])
            i += 1
            continue
        end = _keep_with_next(blocks, i)
        group = blocks[i:end]
        start = layout.mark()
        if not lay_group(group) and start[1] > 0:  # not already at a page's top
            layout.undo(start)
            layout.new_page()
            if not lay_group(group):  # no better on a page of its own: as it was
                layout.undo(start)
                lay_group(group)
        i = end
    return layout


def _draw(ops, title: str, footer: str, first: bool):
    """One page: a new A4 figure with the operations drawn on it."""
    width, height = PAGE_SIZE
    fig = plt.figure(figsize=PAGE_SIZE)

    def text(x, y, s, **kw):  # y: the top of the line [in from the top]
        fig.text(x / width, 1.0 - y / height, s, va="top", ha=kw.pop("ha", "left"),
                 parse_math=False, **kw)

    if not first:  # the running head; the first page has the title itself
        text(_MARGIN, 0.4, title, size=_SIZES["small"], color="0.45")
    text(width - _MARGIN, height - 0.45, footer, size=_SIZES["small"], color="0.45", ha="right")
    for op in ops:
        if op.kind == "text":
            text(op.x, op.y, op.text, size=op.size, family=op.font, weight=op.weight,
                 color=op.color, style=op.style)
        elif op.kind == "rule":
            y = 1.0 - (op.y + 0.015) / height
            fig.add_artist(Line2D([op.x / width, (op.x + op.width) / width], [y, y],
                                  lw=0.5, color=op.color))
        else:
            ax = fig.add_axes((op.x / width, 1.0 - (op.y + op.height) / height,
                               op.width / width, op.height / height))
            ax.imshow(op.image, interpolation="none", aspect="auto")
            ax.set_axis_off()
    return fig


def pdf_pages(blocks, *, name: str = "results"):
    """The pages of a report, one matplotlib figure each (A4 portrait).

    Parameters
    ----------
    blocks : list
        Of :func:`~shipblock.report.document.report_document` (its first block the title).
    name : str
        The results file, as the foot of each page names it.

    Yields
    ------
    matplotlib.figure.Figure
        Each page in order; the caller saves and closes it.
    """
    title = blocks[0].text if blocks and isinstance(blocks[0], Heading) else "shipblock report"
    pages = _layout(blocks).pages
    for i, ops in enumerate(pages, start=1):
        yield _draw(ops, title, f"shipblock report of {name}: page {i} of {len(pages)}", i == 1)


@contextlib.contextmanager
def _quiet_font_subsetting():
    """fontTools, which embeds the fonts' subsets, logs every glyph at INFO: hush it here."""
    logger = logging.getLogger("fontTools")
    level = logger.level
    logger.setLevel(max(level, logging.WARNING))
    try:
        yield
    finally:
        logger.setLevel(level)


def write_pdf(blocks, path, *, name: str = "results") -> int:
    """Write report blocks as a PDF.

    Parameters
    ----------
    blocks : list
        Of :func:`~shipblock.report.document.report_document`.
    path : str or os.PathLike
        The PDF to write.
    name : str
        The results file, as the pages name it.

    Returns
    -------
    int
        The number of pages.
    """
    title = blocks[0].text if blocks and isinstance(blocks[0], Heading) else "shipblock report"
    metadata = {"Title": title, "Subject": f"shipblock study report of {name}",
                "Creator": f"shipblock {__version__}", "Keywords": "fragility, dry dock, risk"}
    count = 0
    with (plt.rc_context({"pdf.fonttype": 42}), _quiet_font_subsetting(),
          PdfPages(path, metadata=metadata) as pdf):
        for page in pdf_pages(blocks, name=name):
            try:
                pdf.savefig(page)
            finally:
                plt.close(page)
            count += 1
    return count
