"""The one writer of every output of mjeap (its commands, its API, its scripts): files that
survive a stop, a kill, a full disk or a second writer, never replace what is not a regular
file of ours, never follow a link and never overwrite one of the run's inputs.

* :func:`output_kind`: what a path is. A regular file (or none yet) is written whole; a
  character device or a FIFO (``/dev/null``, a named pipe) is a stream, written through,
  never replaced; a name of one of this process's descriptors (``/dev/stdout``,
  ``/dev/stderr``, ``/dev/fd/N``, ``/proc/self/fd/N``) is written through that descriptor,
  at its offset, so a file behind a shell's ``>>`` keeps what it held. A symbolic link is
  refused (never followed: a link planted in a shared folder cannot redirect a write), and
  so is anything else (a directory, a block device, a socket), naming the parameter. A name
  mjeap picks itself (``picked``: a report in an output folder) must be a regular file or
  none: a device or FIFO there is refused too.
* :func:`check_outputs` (before any work) refuses an output that is one of the run's
  ``inputs`` (the same resolved path or the same inode: an actuator file, a data or
  waveform CSV), naming both.
* :func:`replacing`: a regular file is written to a temporary file beside it (an
  unguessable name, created exclusively) and renamed onto its path when complete and
  fsynced, so a reader sees the old file or the whole new one, never a part. A write that
  fails (a full disk: ENOSPC) leaves the old file in place and raises; SIGINT and SIGTERM
  wait for the rename. A stream gets the finished bytes, copied through.
* :func:`hold`: a lock (``PATH.lock``, ``fcntl.flock``) refuses a second writer of the same
  path, from this or another process, at once. The lock file is opened without following
  links; one that is a link, not a regular file, has other hard links or holds what mjeap
  did not write is refused, naming it. The OS drops the lock of a process that dies, so a
  lock file left by a killed one blocks nothing; the temporary it names (ours) is removed
  then, and nothing else. A released lock file is removed. A stream is held open instead
  (a FIFO's reader then sees one writer from the check to the end).
* :func:`write_outputs` writes each of a run's outputs on its own at the end, one failure not
  stopping the others; a failed write (ENOSPC, EPERM, EROFS, ...) is one line,
  :class:`~mjeap.errors.OutputError`, the old file left whole.
* :func:`appending` opens a file to append whole rows to (a sweep's CSV), by the same rules.
* :func:`guarded`: a run (a stepping loop) checks and locks its outputs before any work and,
  within it, SIGTERM takes Ctrl-C's path: the run stops and writes what it simulated.
"""
from __future__ import annotations

import errno
import functools
import inspect
import os
import re
import secrets
import shutil
import signal
import stat
import tempfile
import threading
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Callable, Iterable, Mapping, Optional

from ..errors import OutputError, ParameterError, sigterm_as_interrupt
from .output_paths import (check_inputs, check_outputs, descriptor, output_key, output_kind, refused, same_file,
                           stat_kind, target_of)

__all__ = ["hold", "replacing", "run_guard", "guarded", "write_text", "appending", "write_outputs", "provenance",
           "deferred_signals", "WRITE_ERRORS", "LOCK_TAG",
           # what a path is, checked before any work (mjeap.io.output_paths), as the writer's callers use it
           "output_kind", "check_outputs", "check_inputs", "same_file", "descriptor"]

#: the errors of a write the disk or the system refused (one line, never a traceback)
WRITE_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EPERM, errno.EACCES, errno.EROFS, errno.EIO, errno.EFBIG,
                          errno.ENXIO})

_held: dict = {}                       # key -> [(pid, thread), count, fd, kind, lock path, holder]
_held_lock = threading.Lock()
#: what a lock file of mjeap's starts with
LOCK_TAG = "mjeap "




# ---------------------------------------------------------------- locks and held streams
def _refuse(name, given, lock, why):
    return ParameterError(name, str(given), "a path whose lock file mjeap can create and own",
                          f"{lock} {why}: refused, not overwritten; remove it if it is yours")


def _temporary_pattern(target: Path) -> re.Pattern:
    return re.compile(re.escape(f".{target.name}.") + r"[0-9a-f]{16}" + re.escape(f".tmp{target.suffix}"))


def _lock_file(target: Path, name: str, holder: str, given) -> int:
    """An exclusive flock on ``target``.lock (its fd), or ParameterError naming the ``given``
    path: the lock file is opened without following links and must be a regular file of
    ours (one name, mjeap's text or empty)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX: no lock, as the sweep before
        return -1
    lock = target.with_name(target.name + ".lock")
    while True:
        try:
            st = os.lstat(lock)
            if not stat.S_ISREG(st.st_mode):      # never open a device, FIFO or link named like it
                raise _refuse(name, given, lock, "is a symbolic link" if stat.S_ISLNK(st.st_mode)
                              else f"is a {stat_kind(st.st_mode)}, not mjeap's lock file")
        except FileNotFoundError:
            pass
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, 0o644)
        except OSError as e:
            if e.errno == errno.ELOOP:
                raise _refuse(name, given, lock, "is a symbolic link") from None
            raise ParameterError(name, str(given), "a path in a folder where mjeap can create its lock file",
                                 f"cannot create {lock}: {e.strerror or e}") from None
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_nlink != 1:
            os.close(fd)
            raise _refuse(name, given, lock, "has another hard link" if stat.S_ISREG(st.st_mode)
                          else "is not a regular file")
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            other = os.pread(fd, 200, 0).decode(errors="replace").strip()
            os.close(fd)
            raise ParameterError(name, str(given), f"a file no other {holder} is writing",
                                 f"another {other or holder} holds its lock ({lock}): refused, not waiting; "
                                 "let it finish or choose another path") from None
        try:
            same = os.path.samestat(os.lstat(lock), st)
        except FileNotFoundError:
            same = False
        if not same:       # its last holder removed it meanwhile: lock the file now there
            os.close(fd)
            continue
        text = os.pread(fd, 4096, 0).decode(errors="replace")
        if text and not text.startswith(LOCK_TAG):
            os.close(fd)
            raise _refuse(name, given, lock, f"exists and is not an mjeap lock file (it holds {text[:40]!r})")
        # a writer killed mid-write left its temporary: ours (named in our lock), so removed
        m = re.search(r" tmp=(\S+)", text)
        if m and _temporary_pattern(target).fullmatch(m.group(1)):
            stale = target.with_name(m.group(1))
            try:
                if stat.S_ISREG(os.lstat(stale).st_mode):
                    os.unlink(stale)
            except OSError:
                pass
        try:
            _write_lock(fd, holder)
        except OSError as e:                          # a full or read-only disk: said before any work
            if not text:
                try:
                    os.unlink(lock)
                except OSError:
                    pass
            os.close(fd)
            raise ParameterError(name, str(given), "a path on a disk mjeap can write",
                                 f"cannot write its lock file {lock}: {e.strerror or e}") from None
        return fd


def _write_lock(fd: int, holder: str, temporary: Optional[str] = None) -> None:
    if fd < 0:
        return
    text = f"{LOCK_TAG}{holder.removeprefix(LOCK_TAG)} (pid {os.getpid()})" + (f" tmp={temporary}" if temporary else "")
    os.ftruncate(fd, 0)
    os.pwrite(fd, text.encode(), 0)


def _open_stream(path, name: str) -> int:
    """An fd writing to the stream ``path`` (a descriptor's name: a duplicate of it, sharing
    its offset); a FIFO must have a reader now (else refused: waiting for one could hang
    forever)."""
    fd = descriptor(path)
    if fd is not None:
        return os.dup(fd)
    fifo = stat.S_ISFIFO(os.stat(path).st_mode)
    try:
        fd = os.open(path, os.O_WRONLY | os.O_NOCTTY | os.O_CLOEXEC | (os.O_NONBLOCK if fifo else 0))
    except OSError as e:
        if e.errno == errno.ENXIO:
            raise ParameterError(name, str(path), "a FIFO that a process is reading",
                                 "nobody reads it: start its reader first") from None
        raise ParameterError(name, str(path), "a stream mjeap can write",
                             f"cannot open {path}: {e.strerror or e}") from None
    if fifo:
        import fcntl
        fcntl.fcntl(fd, fcntl.F_SETFL, fcntl.fcntl(fd, fcntl.F_GETFL) & ~os.O_NONBLOCK)
    return fd


@contextmanager
def hold(path, name: str = "path", holder: str = "mjeap run", picked: bool = False):
    """Hold the lock of output ``path`` for the block (a stream: hold it open): another
    process or thread holding it is refused at once (ParameterError on ``name``, naming the
    path and the holder); the same thread may hold it again (a run's writers within the
    run). ``picked``: a name mjeap chose (:func:`output_kind`). Yields the key the path is
    held under."""
    kind = output_kind(path, name, picked)
    key = output_key(path, kind)
    me = (os.getpid(), threading.get_ident())
    with _held_lock:
        entry = _held.get(key)
        if entry is not None and entry[0] != me and entry[0][0] == os.getpid():
            raise ParameterError(name, str(path), f"a file no other {holder} is writing",
                                 "another thread of this process is writing it: refused, not waiting")
        if entry is not None and entry[0] == me:
            entry[1] += 1
        else:                                          # none here (or one inherited through fork)
            fd = _open_stream(path, name) if kind == "stream" else _lock_file(key, name, holder, path)
            lock = None if kind == "stream" else key.with_name(key.name + ".lock")
            entry = _held[key] = [me, 1, fd, kind, lock, holder]
    try:
        yield key
    finally:
        with _held_lock:
            entry[1] -= 1
            if entry[1] == 0:
                del _held[key]
                fd, lock = entry[2], entry[4]
                if fd >= 0:
                    if lock is not None:
                        try:                           # still ours (locked): no one else has it
                            if os.path.samestat(os.lstat(lock), os.fstat(fd)):
                                os.unlink(lock)
                        except OSError:
                            pass
                    os.close(fd)


class deferred_signals:
    """Context manager: within it (in the main thread) SIGINT and SIGTERM wait and are
    delivered when it ends, so the files being written are completed first; a second one of
    the same kind is delivered at once (a writer that hangs can still be stopped). Nested,
    the outermost one defers."""

    _depth = 0                                        # main thread only

    def __enter__(self):
        self._old, self._got = {}, []
        self._main = threading.current_thread() is threading.main_thread()
        if self._main:
            deferred_signals._depth += 1
            if deferred_signals._depth == 1:
                for s in (signal.SIGINT, signal.SIGTERM):
                    if signal.getsignal(s) is not None:      # None: set outside Python, left alone
                        self._old[s] = signal.signal(s, self._note)
        return self

    def _note(self, signum, frame):
        if signum not in self._got:
            self._got.append(signum)
            return
        self._got.remove(signum)                      # the second: now, as it would have been
        h = self._old[signum]
        if callable(h):
            h(signum, frame)
        elif h == signal.SIG_DFL:
            signal.signal(signum, h)
            os.kill(os.getpid(), signum)

    def __exit__(self, *exc):
        if self._main:
            deferred_signals._depth -= 1
        for s, h in self._old.items():
            signal.signal(s, h)
        for s in self._got:
            signal.raise_signal(s)
        return False


def _fsync(path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    except OSError as e:  # a directory on a file system that refuses it is fine; a file is not
        if not os.path.isdir(path):
            raise
        del e
    finally:
        os.close(fd)


def _umask() -> int:
    m = os.umask(0)
    os.umask(m)
    return m


def _write_all(fd: int, src) -> None:
    with open(src, "rb") as fh:
        while True:
            chunk = fh.read(1 << 20)
            if not chunk:
                return
            view = memoryview(chunk)
            while view:
                view = view[os.write(fd, view):]


def _write_failed(path, e: OSError) -> "OutputError":
    """A refused write as one line, naming the path (OutputError)."""
    return OutputError([(str(path), e.strerror or str(e))])


@contextmanager
def _one_line(path):
    """Within the block a write the system refuses (:data:`WRITE_ERRORS`: ENOSPC, EPERM,
    EROFS, ...) is an :class:`OutputError` naming ``path``, one line."""
    try:
        yield
    except OutputError:
        raise
    except OSError as e:
        if e.errno not in WRITE_ERRORS:
            raise
        raise _write_failed(path, e) from None


def _flush_std() -> None:
    import sys
    for fh in (sys.stdout, sys.stderr):
        try:
            fh.flush()
        except (OSError, ValueError, AttributeError):
            pass


@contextmanager
def replacing(path, name: str = "path", picked: bool = False):
    """A temporary path for the block to write, put in place when the block ends.

    A regular file (or none yet): the temporary lies beside ``path`` (an unguessable name,
    created exclusively, named in the path's lock so that only it is ever cleaned up), is
    fsynced and renamed onto ``path``; an existing file keeps its mode. A block that raises,
    or a write that fails (a full disk: an :class:`OutputError`, one line), leaves ``path``
    as it was and removes the temporary: a reader sees the old file or the whole new one. A
    stream (a character device, a FIFO, a descriptor's name such as ``/dev/stdout``) gets
    the finished bytes written through, and is never replaced nor truncated. A symbolic
    link is refused, never followed; ``picked``: a name mjeap chose, a regular file or none
    (:func:`output_kind`). The path's lock is held meanwhile (:func:`hold`); SIGINT and
    SIGTERM are delivered after."""
    kind = output_kind(path, name, picked)
    if kind == "stream":
        with hold(path, name) as key, deferred_signals(), _one_line(path):
            folder = Path(tempfile.mkdtemp(prefix="mjeap-"))
            try:
                tmp = folder / f"out{Path(path).suffix}"
                yield tmp
                if tmp.exists():
                    _flush_std()
                    _write_all(_held[key][2], tmp)
            finally:
                shutil.rmtree(folder, ignore_errors=True)
        return
    target = target_of(path)
    with _one_line(path):
        target.parent.mkdir(parents=True, exist_ok=True)
    with hold(target, name, picked=picked) as key, deferred_signals(), _one_line(path):
        entry = _held[key]
        while True:
            tmp = target.with_name(f".{target.name}.{secrets.token_hex(8)}.tmp{target.suffix}")
            try:
                os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666))
                break
            except FileExistsError:
                continue
            except OSError as e:
                raise OutputError([(str(path), f"cannot create a temporary file beside it: {e.strerror or e}")]) \
                    from None
        try:
            _write_lock(entry[2], entry[5], tmp.name)
            yield tmp
            if not os.path.lexists(tmp):              # the block wrote nothing: the path stays
                return
            try:
                now = os.lstat(target)
                mode = now.st_mode & 0o7777
                if not stat.S_ISREG(now.st_mode):       # planted meanwhile: refused, never replaced
                    kind = "symbolic link" if stat.S_ISLNK(now.st_mode) else stat_kind(now.st_mode)
                    raise OutputError([(str(path), f"it became a {kind} while mjeap wrote: refused, not replaced")])
            except FileNotFoundError:
                mode = 0o666 & ~_umask()
            try:
                fd = os.open(tmp, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC)
            except OSError as e:
                raise OutputError([(str(path), f"its temporary file is gone or was replaced: {e.strerror or e}")]) \
                    from None
            try:
                if not stat.S_ISREG(os.fstat(fd).st_mode):
                    raise OutputError([(str(path), "its temporary file was replaced: not put in place")])
                os.fchmod(fd, mode)
                os.fsync(fd)
            finally:
                os.close(fd)
            os.replace(tmp, target)
            _fsync(target.parent)
        finally:
            try:
                if stat.S_ISREG(os.lstat(tmp).st_mode):
                    os.unlink(tmp)
            except OSError:
                pass
            try:
                _write_lock(entry[2], entry[5])
            except OSError:
                pass


@contextmanager
def run_guard(*, inputs: Optional[Mapping] = None, picked: Iterable[str] = (), **paths):
    """The block of a run that writes ``paths`` (name -> path or None): they are checked
    (:func:`check_outputs`, against the run's ``inputs`` too; ``picked``: the names mjeap
    chose) and locked before it starts, and SIGTERM raises
    :class:`~mjeap.errors.Terminated` (a KeyboardInterrupt) within it, as Ctrl-C does."""
    picked = set(picked)
    with ExitStack() as stack:
        out = check_outputs(inputs=inputs, picked=picked, **paths)
        for name, p in out.items():
            stack.enter_context(hold(p, name, picked=name in picked))
        stack.enter_context(sigterm_as_interrupt())
        yield out


def guarded(*names: str, inputs: Optional[Callable[[dict], Mapping]] = None):
    """Decorator of a run (a stepping loop) whose arguments ``names`` are output paths: the
    run is called within :func:`run_guard` of them, the one interrupt path of every run.
    ``inputs(arguments)`` (the bound arguments by name) gives the run's input files (name
    -> path), which no output may be."""
    def wrap(fn):
        sig = inspect.signature(fn)

        @functools.wraps(fn)
        def run(*args, **kwargs):
            given = sig.bind(*args, **kwargs)
            given.apply_defaults()
            read = inputs(given.arguments) if inputs is not None else None
            with run_guard(inputs=read, **{n: given.arguments[n] for n in names}):
                return fn(*args, **kwargs)
        return run
    return wrap


def provenance() -> dict:
    """What every result's metadata (and so its recording and CSV's sidecar) says about the
    software that made it: the MuJoCo and mjeap versions."""
    import mujoco
    from ..versions import MJEAP_VERSION
    return {"mujoco": mujoco.__version__, "mjeap": MJEAP_VERSION}


def write_text(path, text: str, name: str = "path", picked: bool = False) -> Path:
    """Write ``text`` (UTF-8) to ``path`` through :func:`replacing`: whole or not at all,
    never through a link, a stream written through; the path returned."""
    with replacing(path, name, picked) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def appending(path, name: str = "path") -> int:
    """A descriptor appending to output ``path`` (a sweep's CSV, one whole row at a time):
    a regular file is opened without following a link (created if none), a stream is
    written through (a descriptor's name: a duplicate of it, its offset shared). Refused
    as :func:`output_kind` refuses."""
    fd = descriptor(path)
    if fd is not None:
        output_kind(path, name)
        return os.dup(fd)
    kind = output_kind(path, name)
    flags = os.O_WRONLY | os.O_CLOEXEC | os.O_NOFOLLOW | os.O_NOCTTY
    if kind != "stream":
        flags |= os.O_APPEND | os.O_CREAT
    try:
        fd = os.open(path, flags, 0o666)
    except OSError as e:
        if e.errno == errno.ELOOP:
            output_kind(path, name)             # a link planted meanwhile: refused, naming it
        raise refused(name, path, "a path mjeap can write", f"cannot open {path}: {e.strerror or e}") from None
    st = os.fstat(fd)
    if kind != "stream" and not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise refused(name, path, "a regular file", f"it is a {stat_kind(st.st_mode)}: refused")
    return fd


def write_outputs(writers, error: Optional[BaseException], result=None) -> None:
    """Run each ``(path, write)`` on its own: one failing write does not stop the others.
    The run's own error stays the error raised (the write failures are added to its notes);
    without one, the failures raise :class:`OutputError` carrying the result. Ctrl-C and
    SIGTERM wait until all are written."""
    failures = []
    with deferred_signals():
        for path, write in writers:
            try:
                write()
            except OutputError as e:                 # one line each, as the writer said it
                failures.extend(e.failures)
            except Exception as e:                   # noqa: BLE001 - reported, never masks the run's error
                why = e.strerror if isinstance(e, OSError) and e.strerror else e
                failures.append((path, f"{type(e).__name__}: {why}"))
    if not failures:
        return
    if error is not None:
        notes = getattr(error, "__notes__", None)
        if notes is None:
            notes = error.__notes__ = []
        notes.extend(f"cannot write {p}: {why}" for p, why in failures)
        return
    raise OutputError(failures, result)
