"""Files that survive a stop, a kill, a full disk or a second writer, and never replace what
is not a regular file of ours.

* :func:`output_kind`: what a path is. A regular file (or none yet) is written whole; a
  character device or a FIFO (``/dev/null``, ``/dev/stdout`` on a pipe, a named pipe) is a
  stream, written through, never replaced; anything else (a directory, a block device, a
  socket) is refused, naming the parameter.
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
* :func:`check_outputs` checks a run's output paths before any work; :func:`write_outputs`
  writes each on its own at the end, one failure not stopping the others.
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
from typing import Dict, Optional

from ..errors import OutputError, ParameterError, sigterm_as_interrupt

_held: dict = {}                       # key -> [(pid, thread), count, fd, kind, lock path, holder]
_held_lock = threading.Lock()
#: what a lock file of mjeap's starts with
LOCK_TAG = "mjeap "
_STREAMS = "a regular file, or a character device or FIFO to stream to"


def _stat_kind(mode: int) -> str:
    for test, word in ((stat.S_ISDIR, "directory"), (stat.S_ISBLK, "block device"), (stat.S_ISSOCK, "socket"),
                       (stat.S_ISCHR, "character device"), (stat.S_ISFIFO, "FIFO")):
        if test(mode):
            return word
    return "special file"


def output_kind(path, name: str = "path") -> str:
    """``"file"`` (a regular file, through any links), ``"new"`` (nothing there yet) or
    ``"stream"`` (a character device or FIFO: written through, never replaced); anything
    else is refused with a :class:`ParameterError` on ``name``. The path is followed as the
    kernel does (``/dev/stdout`` is whatever fd 1 is)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return "new"
    except OSError as e:
        raise ParameterError(name, str(path), "a path mjeap can write",
                             f"cannot write {path}: {e.strerror or e}") from None
    if stat.S_ISREG(st.st_mode):
        return "file"
    if stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode):
        return "stream"
    kind = _stat_kind(st.st_mode)
    raise ParameterError(name, str(path), "a file path" if kind == "directory" else _STREAMS,
                         f"it is a {kind}: refused, never replaced")


def _key(path, kind: str):
    if kind == "stream":
        st = os.stat(path)
        return ("stream", st.st_dev, st.st_ino)
    return Path(os.path.realpath(path))


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
                              else f"is a {_stat_kind(st.st_mode)}, not mjeap's lock file")
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
        _write_lock(fd, holder)
        return fd


def _write_lock(fd: int, holder: str, temporary: Optional[str] = None) -> None:
    if fd < 0:
        return
    text = f"{LOCK_TAG}{holder.removeprefix(LOCK_TAG)} (pid {os.getpid()})" + (f" tmp={temporary}" if temporary else "")
    os.ftruncate(fd, 0)
    os.pwrite(fd, text.encode(), 0)


def _open_stream(path, name: str) -> int:
    """An fd writing to the stream ``path``; a FIFO must have a reader now (else refused:
    waiting for one could hang forever)."""
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
def hold(path, name: str = "path", holder: str = "mjeap run"):
    """Hold the lock of output ``path`` for the block (a stream: hold it open): another
    process or thread holding it is refused at once (ParameterError on ``name``, naming the
    path and the holder); the same thread may hold it again (a run's writers within the
    run). Yields the key the path is held under."""
    kind = output_kind(path, name)
    key = _key(path, kind)
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


@contextmanager
def replacing(path, name: str = "path"):
    """A temporary path for the block to write, put in place when the block ends.

    A regular file (or none yet): the temporary lies beside ``path`` (an unguessable name,
    created exclusively, named in the path's lock so that only it is ever cleaned up), is
    fsynced and renamed onto ``path``; an existing file keeps its mode. A block that raises,
    or a write that fails (a full disk), leaves ``path`` as it was and removes the
    temporary: a reader sees the old file or the whole new one. A stream (a character
    device or FIFO) gets the finished bytes written through, and is never replaced. The
    path's lock is held meanwhile (:func:`hold`); SIGINT and SIGTERM are delivered after."""
    kind = output_kind(path, name)
    if kind == "stream":
        with hold(path, name) as key, deferred_signals():
            folder = Path(tempfile.mkdtemp(prefix="mjeap-"))
            try:
                tmp = folder / f"out{Path(path).suffix}"
                yield tmp
                if tmp.exists():
                    _write_all(_held[key][2], tmp)
            finally:
                shutil.rmtree(folder, ignore_errors=True)
        return
    target = Path(os.path.realpath(path))
    target.parent.mkdir(parents=True, exist_ok=True)
    with hold(target, name) as key, deferred_signals():
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
        _write_lock(entry[2], entry[5], tmp.name)
        try:
            yield tmp
            if not tmp.exists():                      # the block wrote nothing: the path stays
                return
            try:
                mode = os.stat(target).st_mode & 0o7777
            except FileNotFoundError:
                mode = 0o666 & ~_umask()
            os.chmod(tmp, mode)
            _fsync(tmp)
            os.replace(tmp, target)
            _fsync(target.parent)
        finally:
            try:
                if stat.S_ISREG(os.lstat(tmp).st_mode):
                    os.unlink(tmp)
            except OSError:
                pass
            _write_lock(entry[2], entry[5])


@contextmanager
def run_guard(**paths):
    """The block of a run that writes ``paths`` (name -> path or None): they are checked
    (:func:`check_outputs`) and locked before it starts, and SIGTERM raises
    :class:`~mjeap.errors.Terminated` (a KeyboardInterrupt) within it, as Ctrl-C does."""
    with ExitStack() as stack:
        out = check_outputs(**paths)
        for name, p in out.items():
            stack.enter_context(hold(p, name))
        stack.enter_context(sigterm_as_interrupt())
        yield out


def guarded(*names: str):
    """Decorator of a run (a stepping loop) whose arguments ``names`` are output paths: the
    run is called within :func:`run_guard` of them, the one interrupt path of every run."""
    def wrap(fn):
        sig = inspect.signature(fn)

        @functools.wraps(fn)
        def run(*args, **kwargs):
            given = sig.bind(*args, **kwargs)
            given.apply_defaults()
            with run_guard(**{n: given.arguments[n] for n in names}):
                return fn(*args, **kwargs)
        return run
    return wrap


def provenance() -> dict:
    """What every result's metadata (and so its recording and CSV's sidecar) says about the
    software that made it: the MuJoCo and mjeap versions."""
    import mujoco
    from ..versions import MJEAP_VERSION
    return {"mujoco": mujoco.__version__, "mjeap": MJEAP_VERSION}


def check_outputs(**paths) -> Dict[str, Path]:
    """The outputs a run will write (name -> path or None), checked before any work:
    distinct, each a regular file (or none yet) in a folder that exists or can be made and
    is writable, or a writable stream (:func:`output_kind`)."""
    out, seen = {}, {}
    for name, p in paths.items():
        if p is None:
            continue
        p = Path(p)
        kind = output_kind(p, name)
        key = _key(p, kind)
        if key in seen:
            raise ParameterError(name, str(p), f"a file other than the {seen[key]} output's")
        seen[key] = name
        if kind == "stream":
            if not os.access(p, os.W_OK):
                raise ParameterError(name, str(p), "a writable path", f"cannot write {p}: permission denied")
            out[name] = p
            continue
        parent = key.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise ParameterError(name, str(p), "a path in a folder that exists or can be made",
                                 f"cannot write {p}: {e.strerror or e}") from None
        if not os.access(parent, os.W_OK | os.X_OK) or (kind == "file" and not os.access(key, os.W_OK)):
            raise ParameterError(name, str(p), "a writable path", f"cannot write {p}: permission denied")
        out[name] = p
    return out


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
            except Exception as e:                   # noqa: BLE001 - reported, never masks the run's error
                why = e.strerror if isinstance(e, OSError) and e.strerror and not isinstance(e, OutputError) else e
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
