"""A study's report (``shipblock report``): one HTML or PDF document with the study's
definition, records, limit states, fragility with bands and risk, and its tables as CSV.

:mod:`.document` makes the content once, as blocks; :mod:`.html` and :mod:`.pdf` render them;
:mod:`.write` reads the results file and writes the report and the tables.
"""

from shipblock.report.document import check_study, record_spectra, report_document, study_spectra
from shipblock.report.html import report_html
from shipblock.report.pdf import pdf_pages, write_pdf
from shipblock.report.write import REPORT_FORMATS, write_report

__all__ = ["REPORT_FORMATS", "check_study", "pdf_pages", "record_spectra", "report_document",
           "report_html", "study_spectra", "write_pdf", "write_report"]
