"""What an output path is and whether a run may write there, decided before any work
(:mod:`mjeap.io.outputs` writes): :func:`output_kind` (a regular file or none, a stream, or
refused: a link, a directory, another device; a name mjeap picks must be a regular file or
none), the descriptors a path names (``/dev/stdout``, ``/dev/fd/N``), :func:`same_file` (a
path and an inode), and :func:`check_outputs` / :func:`check_inputs` (no output one of the
run's inputs)."""
from __future__ import annotations

import os
import re
import stat
from pathlib import Path
from typing import Dict, Iterable, Mapping, Optional

from ..errors import ParameterError

__all__ = ["output_kind", "descriptor", "same_file", "check_inputs", "check_outputs", "stat_kind", "refused",
           "target_of", "output_key", "read_only_folder"]

_STREAMS = "a regular file, or a character device or FIFO to stream to"
#: the names of this process's descriptors: written through them, never reopened
_DESCRIPTOR = re.compile(r"/(?:dev/fd|proc/self/fd|proc/(\d+)/fd)/(\d+)")
_STANDARD = {"/dev/stdout": 1, "/dev/stderr": 2}


def stat_kind(mode: int) -> str:
    for test, word in ((stat.S_ISDIR, "directory"), (stat.S_ISBLK, "block device"), (stat.S_ISSOCK, "socket"),
                       (stat.S_ISCHR, "character device"), (stat.S_ISFIFO, "FIFO")):
        if test(mode):
            return word
    return "special file"


def descriptor(path) -> Optional[int]:
    """The descriptor of this process that ``path`` names (``/dev/stdout`` 1, ``/dev/stderr``
    2, ``/dev/fd/N``, ``/proc/self/fd/N``, ``/proc/PID/fd/N`` of this PID), else None. Such
    a path is written through that descriptor (never reopened: reopening a file behind
    ``>>`` would write from its start)."""
    try:
        text = os.path.normpath(os.fspath(path))
    except TypeError:
        return None
    if text in _STANDARD:
        return _STANDARD[text]
    m = _DESCRIPTOR.fullmatch(text)
    if m and (m.group(1) is None or int(m.group(1)) == os.getpid()):
        return int(m.group(2))
    return None


def refused(name, path, accepted, why):
    return ParameterError(name, str(path), accepted, why)


def output_kind(path, name: str = "path", picked: bool = False) -> str:
    """``"file"`` (a regular file), ``"new"`` (nothing there yet) or ``"stream"`` (a character
    device or FIFO, or a name of one of this process's descriptors, :func:`descriptor`:
    written through, never replaced); anything else is refused with a
    :class:`ParameterError` on ``name``: a symbolic link (never followed), a directory, a
    block device, a socket; with ``picked`` (a name mjeap chose itself, in an output folder)
    a stream too."""
    fd = descriptor(path)
    if fd is not None and not picked:
        try:
            st = os.fstat(fd)
        except OSError:
            raise refused(name, path, "an open stream", f"descriptor {fd} is not open in this process") from None
        if stat.S_ISREG(st.st_mode) or stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode) \
                or stat.S_ISSOCK(st.st_mode):
            return "stream"
        raise refused(name, path, _STREAMS, f"descriptor {fd} is a {stat_kind(st.st_mode)}: refused")
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return "new"
    except OSError as e:
        raise refused(name, path, "a path mjeap can write", f"cannot write {path}: {e.strerror or e}") from None
    if stat.S_ISLNK(st.st_mode):
        try:
            to = os.readlink(path)
        except OSError:  # pragma: no cover - removed meanwhile
            to = "?"
        raise refused(name, path, "a path that is not a symbolic link",
                       f"it is a symbolic link to {to}: refused, never followed (a link planted in a shared folder "
                       "would redirect the write); give the path it points to")
    if stat.S_ISREG(st.st_mode):
        return "file"
    kind = stat_kind(st.st_mode)
    if picked:
        raise refused(name, path, "a regular file or none (mjeap names this file itself)",
                       f"it is a {kind}: refused, never written through or replaced")
    if stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode):
        return "stream"
    raise refused(name, path, "a file path" if kind == "directory" else _STREAMS,
                   f"it is a {kind}: refused, never replaced")


def target_of(path) -> Path:
    """Where a regular file ``path`` lies: its folder resolved, its own name kept (the name
    is never a link: :func:`output_kind`; a rename replaces a link planted later, it does
    not follow it)."""
    p = Path(os.path.abspath(path))
    return Path(os.path.realpath(p.parent)) / p.name


def _stream_stat(path):
    fd = descriptor(path)
    return os.fstat(fd) if fd is not None else os.stat(path)


def output_key(path, kind: str):
    if kind == "stream":
        st = _stream_stat(path)
        return ("stream", st.st_dev, st.st_ino)
    return target_of(path)


def _identity(path):
    """(resolved path, (device, inode) or None) of a path, following links (an input is
    read through them)."""
    fd = descriptor(path)
    try:
        st = os.fstat(fd) if fd is not None else os.stat(path)
        ino = (st.st_dev, st.st_ino)
    except (OSError, ValueError):
        ino = None
    return (None if fd is not None else Path(os.path.realpath(path))), ino


def same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` are one file: the same resolved path, or the same inode
    (a hard link, a descriptor's file)."""
    (pa, ia), (pb, ib) = _identity(a), _identity(b)
    return (pa is not None and pa == pb) or (ia is not None and ia == ib)


def check_inputs(outputs: Mapping, inputs: Optional[Mapping]) -> None:
    """Refuse an output (name -> path) that is one of the run's ``inputs`` (name -> path or
    None, or (name, path) pairs; the same resolved path or the same inode, :func:`same_file`), naming both, before
    any work."""
    pairs = inputs.items() if isinstance(inputs, Mapping) else (inputs or ())
    for iname, ipath in pairs:
        if ipath is None or (isinstance(ipath, str) and not ipath):
            continue
        for name, p in outputs.items():
            if p is not None and same_file(p, ipath):
                raise ParameterError(name, str(p), f"a path other than the {iname} {ipath}",
                                     "it is one of the run's inputs: writing there would replace it")


def check_outputs(*, inputs: Optional[Mapping] = None, picked: Iterable[str] = (), **paths) -> Dict[str, Path]:
    """The outputs a run will write (name -> path or None), checked before any work:
    distinct, none one of the run's ``inputs`` (name -> path, :func:`check_inputs`), each a
    regular file (or none yet; never a link) in a folder that exists or can be made and is
    writable, or a writable stream (:func:`output_kind`; ``picked``: the names of paths
    mjeap chose, a regular file or none)."""
    out, seen = {}, {}
    picked = set(picked)
    check_inputs(paths, inputs)
    for name, p in paths.items():
        if p is None:
            continue
        p = Path(p)
        kind = output_kind(p, name, name in picked)
        key = output_key(p, kind)
        if key in seen:
            raise ParameterError(name, str(p), f"a file other than the {seen[key]} output's")
        seen[key] = name
        if kind == "stream":
            if descriptor(p) is None and not os.access(p, os.W_OK):
                raise ParameterError(name, str(p), "a writable path", f"cannot write {p}: permission denied")
            out[name] = p
            continue
        parent = key.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise ParameterError(name, str(p), "a path in a folder that exists or can be made",
                                 f"cannot write {p}: {e.strerror or e}") from None
        if not parent.is_dir():
            raise ParameterError(name, str(p), "a path in a folder", f"{parent} is not a folder")
        if not os.access(parent, os.W_OK | os.X_OK) or (kind == "file" and not os.access(key, os.W_OK)):
            raise ParameterError(name, str(p), "a writable path", f"cannot write {p}: "
                                 + ("read-only file system" if read_only_folder(parent) else "permission denied"))
        out[name] = p
    return out


def read_only_folder(folder) -> bool:
    try:
        return bool(os.statvfs(folder).f_flag & os.ST_RDONLY)
    except OSError:
        return False
