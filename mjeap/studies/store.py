"""A study's CSV store: rows appended whole, one at a time, a torn last row dropped, the file
read back as users' CSVs are read. The sweep (:mod:`mjeap.studies.sweep`) streams its points
to it and the optimiser (:mod:`mjeap.studies.optimize`) its evaluations; a rerun reads it
back and skips what finished."""
from __future__ import annotations

import io
import os
import stat
import warnings
from pathlib import Path

from ..errors import OutputError, ParameterError
from ..io import csvio
from ..io.outputs import appending

__all__ = ["RowFile", "read_study_csv", "drop_torn_row"]


def drop_torn_row(path: Path) -> None:
    """A file cut mid-line (a killed writer) loses its partial last row, which would
    otherwise count as done and have the next row glued onto it; the point runs again."""
    if not path.exists() or path.stat().st_size == 0:
        return
    with open(path, "rb+") as fh:
        data = fh.read()
        if data.endswith(b"\n"):
            return
        cut = data.rfind(b"\n") + 1
        fh.truncate(cut)
    warnings.warn(f"{path}: dropped a partial last row ({len(data) - cut} bytes, cut mid-line); its point runs again",
                  stacklevel=3)


def read_study_csv(path):
    """A sweep's CSV read as :mod:`mjeap.io.csvio` reads users' files (a UTF-8 BOM, ',', ';'
    or tab as the delimiter: a file re-saved by a spreadsheet): (header, rows as dicts,
    delimiter). Refused, naming the file, where its first row does not name ``point_id`` (the
    header was lost or replaced: the points done could not be told)."""
    rows, delimiter = csvio.read_table(path, "path")
    header = rows[0]
    if "point_id" not in header:
        shown = ", ".join(header[:3]) + (", ..." if len(header) > 3 else "")
        raise ParameterError("path", str(path), "a sweep CSV whose first row is the header mjeap wrote, naming "
                             "point_id (the key of each point done)", f"its first row is [{shown}]: the header row "
                             "was lost or changed (re-saved by a spreadsheet?); restore it, or start a new file")
    pad = [""] * len(header)
    return header, [dict(zip(header, r + pad[len(r):])) for r in rows[1:]], delimiter


class RowFile:
    """The sweep's CSV, appended one whole row at a time: a row is formatted first, then
    written and fsynced; a write that fails (a full disk) cuts the file back to its last
    whole row and raises :class:`OutputError` saying how many rows are kept, so that a rerun
    resumes from them (a stream, e.g. /dev/stdout, is written through)."""

    def __init__(self, path: Path, delimiter: str = ",", name: str = "path"):
        self.path = path
        self.fd = appending(path, name)               # never through a link (mjeap.io.outputs)
        self.regular = stat.S_ISREG(os.fstat(self.fd).st_mode)
        self.buf = io.StringIO()
        self.writer = csvio.writer(self.buf, delimiter=delimiter)

    def write(self, cells, kept: int) -> None:
        self.buf.seek(0)
        self.buf.truncate()
        self.writer.writerow(cells)
        data = memoryview(self.buf.getvalue().encode("utf-8"))
        end = os.lseek(self.fd, 0, os.SEEK_END) if self.regular else None
        try:
            while data:
                data = data[os.write(self.fd, data):]
            if self.regular:
                os.fsync(self.fd)
        except OSError as e:
            if self.regular:
                os.ftruncate(self.fd, end)
            raise OutputError([(str(self.path), f"{e.strerror or e}; the {kept} whole rows written so far are "
                                               "kept: rerun the same sweep to resume from them")]) from None

    def close(self) -> None:
        os.close(self.fd)
