"""CSV files: reading users' files the way they save them (UTF-8 with or without a
byte-order mark, Windows code pages (Latin-1), ',', ';' or tab as the delimiter, sniffed),
with errors that say what is wrong, for ``mjeap identify`` and ``csv:`` waveforms; and the
one writer of mjeap's own CSVs (:class:`writer`), safe to open in a spreadsheet.

Spreadsheets run a cell that begins with ``=``, ``+``, ``-``, ``@``, a tab or a carriage
return as a formula (CSV injection: a sweep value ``=1+1``, a signal's name). The writer
prefixes such a text cell with ``'`` (OWASP's advice, as spreadsheet-safe writers do);
numbers, and text that reads as one (-1.5), are written unchanged. :func:`plain_cell` undoes
it, and the readers here apply it.
"""
from __future__ import annotations

import csv
import io
import numbers
import re
from pathlib import Path
from typing import List, Tuple

import numpy as np

from ..errors import ParameterError

#: text a spreadsheet runs as a formula: one of these first, after any quotes (so that the
#: quote added to it reads back unambiguously)
_FORMULA = re.compile(r"'*[=+\-@\t\r]")
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|[+-]?(inf|infinity|nan)", re.IGNORECASE)


def safe_cell(value):
    """``value`` as mjeap writes it to a CSV: text a spreadsheet would run as a formula gets
    a leading ``'``; numbers (and None, an empty cell) and other text are unchanged."""
    if value is None or isinstance(value, numbers.Number):
        return value
    text = str(value)
    return "'" + text if _FORMULA.match(text) and not _NUMBER.fullmatch(text) else value


def plain_cell(text):
    """A cell as read from a CSV written by :func:`safe_cell`, back to its text (anything
    but text is returned as it is)."""
    if isinstance(text, str) and text[:1] == "'" and safe_cell(text[1:]) != text[1:]:
        return text[1:]
    return text


class writer:
    """``csv.writer`` over ``fh`` whose cells go through :func:`safe_cell`: every CSV mjeap
    writes is written with it."""

    def __init__(self, fh, **kwargs):
        self._w = csv.writer(fh, **kwargs)

    def writerow(self, row) -> None:
        self._w.writerow([safe_cell(c) for c in row])

    def writerows(self, rows) -> None:
        if isinstance(rows, np.ndarray) and rows.dtype.kind in "biuf":
            self._w.writerows(rows.tolist())          # numbers only: nothing to neutralise
            return
        for row in rows:
            self.writerow(row)


def read_rows(path, what: str = "data file") -> List[List[str]]:
    """All rows of a text CSV (header first), stripped of a BOM, the delimiter sniffed."""
    return read_table(path, what)[0]


def read_table(path, what: str = "data file") -> Tuple[List[List[str]], str]:
    """:func:`read_rows` and the delimiter it found (',', ';' or a tab): a file mjeap
    appends to (a sweep's CSV re-saved by a spreadsheet) goes on in its own form."""
    p = Path(path)
    if not p.is_file():
        raise ParameterError(what, str(path), "an existing CSV file")
    raw = p.read_bytes()
    if b"\x00" in raw[:65536]:
        raise ParameterError(what, str(path), "a text CSV file (this one holds binary data)")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")          # every byte is a character: Windows-saved files
    if not text.strip():
        raise ParameterError(what, str(path), "a CSV with a header row and data")
    delimiter = _delimiter("\n".join(text.splitlines()[:20]))
    return [[plain_cell(c) for c in row] for row in csv.reader(io.StringIO(text, newline=""), delimiter=delimiter)
            if row], delimiter


def _delimiter(sample: str) -> str:
    """The delimiter of a CSV's first lines: of ',', ';' and tab, the one that splits the
    header into two or more columns and the most rows into as many (csv's Sniffer alone took
    ',' for a ';' file whose cells hold commas, a sweep's settings); the Sniffer's choice
    among equals, ',' for a single column."""
    try:
        sniffed = csv.Sniffer().sniff(sample, delimiters=",;\t").delimiter
    except csv.Error:
        sniffed = ","
    scores = {}
    for d in ",;\t":
        try:
            rows = [r for r in csv.reader(io.StringIO(sample, newline=""), delimiter=d) if r]
        except csv.Error:
            continue
        if rows and len(rows[0]) >= 2:
            scores[d] = (sum(len(r) == len(rows[0]) for r in rows), len(rows[0]))
    if not scores:
        return sniffed
    best = max(scores.values())
    return sniffed if scores.get(sniffed) == best else max(scores, key=scores.get)


def number(cell: str, what: str, line: int) -> float:
    """A CSV cell as a float, or a ParameterError naming the column and line (with a hint
    for a decimal comma)."""
    try:
        return float(cell)
    except ValueError:
        hint = " (a decimal comma? write 1.5, not 1,5)" if "," in cell else ""
        raise ParameterError(what, f"'{cell}' on line {line}", "numbers" + hint) from None
