"""Files that survive a stop, a kill or a second writer.

* :func:`replacing`: every file mjeap writes is written to a temporary file beside it and
  renamed onto its path when complete (fsynced first), so a reader sees the old file or the
  whole new one, never a part; SIGINT and SIGTERM wait for the rename.
* :func:`hold`: a lock (``PATH.lock``, ``fcntl.flock``) refuses a second writer of the same
  path, from this or another process, at once. The OS drops the lock of a process that
  dies, so a lock file left by a killed one blocks nothing; a released lock file is removed.
* :func:`check_outputs` checks a run's output paths before any work; :func:`write_outputs`
  writes each on its own at the end, one failure not stopping the others.
* :func:`guarded`: a run (a stepping loop) checks and locks its outputs before any work and,
  within it, SIGTERM takes Ctrl-C's path: the run stops and writes what it simulated.
"""
from __future__ import annotations

import functools
import glob
import inspect
import os
import secrets
import signal
import threading
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Dict, Optional

from ..errors import OutputError, ParameterError, sigterm_as_interrupt

_held: dict = {}                       # real path -> [(pid, thread), count, fd]
_held_lock = threading.Lock()


def _lock_file(path: Path, name: str, holder: str, given) -> int:
    """An exclusive flock on ``path``.lock (its fd), or ParameterError naming the ``given`` path."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX: no lock, as the sweep before
        return -1
    lock = path.with_name(path.name + ".lock")
    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            other = os.read(fd, 200).decode(errors="replace").strip()
            os.close(fd)
            raise ParameterError(name, str(given), f"a file no other {holder} is writing",
                                 f"another {other or holder} holds its lock ({lock}): refused, not waiting; "
                                 "let it finish or choose another path") from None
        try:
            same = os.path.samestat(os.stat(lock), os.fstat(fd))
        except FileNotFoundError:
            same = False
        if same:           # else its last holder removed it meanwhile: lock the file now there
            os.ftruncate(fd, 0)
            os.write(fd, f"{holder} (pid {os.getpid()})".encode())
            return fd
        os.close(fd)


@contextmanager
def hold(path, name: str = "path", holder: str = "mjeap run"):
    """Hold the lock of output ``path`` for the block: another process or thread holding it
    is refused at once (ParameterError on ``name``, naming the path and the holder); the
    same thread may hold it again (a run's writers within the run)."""
    key = Path(os.path.realpath(path))
    me = (os.getpid(), threading.get_ident())
    with _held_lock:
        entry = _held.get(key)
        if entry is not None and entry[0] != me and entry[0][0] == os.getpid():
            raise ParameterError(name, str(path), f"a file no other {holder} is writing",
                                 "another thread of this process is writing it: refused, not waiting")
        if entry is not None and entry[0] == me:
            entry[1] += 1
        else:                                          # none here (or one inherited through fork)
            entry = _held[key] = [me, 1, _lock_file(key, name, holder, path)]
    try:
        yield key
    finally:
        with _held_lock:
            entry[1] -= 1
            if entry[1] == 0:
                del _held[key]
                if entry[2] >= 0:
                    try:
                        os.unlink(key.with_name(key.name + ".lock"))   # still locked: no one else has it
                    except OSError:
                        pass
                    os.close(entry[2])


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
    except OSError:  # pragma: no cover - a directory on a file system that refuses it
        pass
    finally:
        os.close(fd)


@contextmanager
def replacing(path, name: str = "path"):
    """A temporary path beside ``path`` (same suffix) for the block to write, renamed onto
    ``path`` when the block ends, fsynced first. A block that raises still puts what it
    wrote in place (a partial output is kept; the error says so); one that wrote nothing
    leaves ``path`` as it was. The path's lock is held meanwhile (:func:`hold`), SIGINT
    and SIGTERM are delivered after the rename, and temporaries of a writer killed mid-write
    are removed."""
    target = Path(os.path.realpath(path))
    target.parent.mkdir(parents=True, exist_ok=True)
    with hold(target, name), deferred_signals():
        for stale in target.parent.glob(glob.escape(f".{target.name}.") + "*" + glob.escape(f".tmp{target.suffix}")):
            stale.unlink()                          # left by a writer killed mid-write (we hold the lock)
        tmp = target.with_name(f".{target.name}.{secrets.token_hex(4)}.tmp{target.suffix}")
        ok = False
        try:
            yield tmp
            ok = True
        finally:
            if tmp.exists() and (ok or tmp.stat().st_size > 0):
                try:
                    os.chmod(tmp, os.stat(target).st_mode & 0o7777)    # an existing file keeps its mode
                except OSError:
                    pass
                _fsync(tmp)
                os.replace(tmp, target)
                _fsync(target.parent)
            elif tmp.exists():
                tmp.unlink()


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
    """The outputs a run will write (name -> path or None), checked before any work: distinct
    files, not directories, in a folder that exists or can be made and is writable."""
    out, seen = {}, {}
    for name, p in paths.items():
        if p is None:
            continue
        p = Path(p)
        key = p.resolve()
        if key in seen:
            raise ParameterError(name, str(p), f"a file other than the {seen[key]} output's")
        seen[key] = name
        if p.is_dir():
            raise ParameterError(name, str(p), "a file path (it is a directory)")
        parent = p.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise ParameterError(name, str(p), "a path in a folder that exists or can be made",
                                 f"cannot write {p}: {e.strerror or e}") from None
        if not os.access(parent, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
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
                failures.append((path, f"{type(e).__name__}: {e}"))
    if not failures:
        return
    if error is not None:
        notes = getattr(error, "__notes__", None)
        if notes is None:
            notes = error.__notes__ = []
        notes.extend(f"cannot write {p}: {why}" for p, why in failures)
        return
    raise OutputError(failures, result)
