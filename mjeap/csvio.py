"""Reading users' CSV files the way they save them: UTF-8 with or without a byte-order mark,
Windows code pages (Latin-1), ',', ';' or tab as the delimiter (sniffed), with errors that
say what is wrong. Serves ``mjeap identify`` and ``csv:`` waveforms."""
from __future__ import annotations

import csv
from pathlib import Path
from typing import List

from .errors import ParameterError


def read_rows(path, what: str = "data file") -> List[List[str]]:
    """All rows of a text CSV (header first), stripped of a BOM, the delimiter sniffed."""
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
    sample = "\n".join(text.splitlines()[:20])
    try:
        dialect = csv.Sniffer().sniff(sample, delimiters=",;\t")
        delimiter = dialect.delimiter
    except csv.Error:
        delimiter = ","
    return [row for row in csv.reader(text.splitlines(), delimiter=delimiter) if row]


def number(cell: str, what: str, line: int) -> float:
    """A CSV cell as a float, or a ParameterError naming the column and line (with a hint
    for a decimal comma)."""
    try:
        return float(cell)
    except ValueError:
        hint = " (a decimal comma? write 1.5, not 1,5)" if "," in cell else ""
        raise ParameterError(what, f"'{cell}' on line {line}", "numbers" + hint) from None
