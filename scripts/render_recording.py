#!/usr/bin/env python
"""Render Rerun recordings (.rrd) to PNG, headless: what a reviewer sees when opening them.

    python scripts/render_recording.py out/pedot-micro.rrd [more.rrd ...] [--out-dir out/png]
        [--size 1600x900] [--time SECONDS] [--timeout 120]

Set-up (optional, not needed by the tests): Rerun's native viewer draws through Vulkan; on a
machine without a GPU install Mesa's software rasterizer, e.g. on Debian/Ubuntu
``apt-get install mesa-vulkan-drivers``. The script starts ``rerun --headless`` on a free
local port, opens each file through Rerun's viewer-control API
(``rerun.experimental.ViewerClient``), waits until the viewer reports that nothing is
loading any more and every recording has its timelines, moves the time cursor (``--time``,
default: the start, where the layout opens), waits for a few painted frames and saves the
screenshot. A PNG per recording, named after it.
"""
import argparse
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _loaded(state) -> bool:
    # static-only recordings have no timeline; a timeline without an end is still arriving
    return (not state.loading and bool(state.recordings)
            and all(t.end is not None for r in state.recordings for t in r.timelines))


def _stop(proc, wait: float = 10.0) -> None:
    """Stop the viewer: ``rerun`` is a wrapper that starts the viewer binary as its child, so
    the whole process group it leads (a session of its own, :func:`_start`) is signalled:
    SIGTERM, up to ``wait`` s for the wrapper, then SIGKILL for whatever is left. Stopping
    the wrapper alone left the viewer (~360 MB) running."""
    try:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(wait)
        except subprocess.TimeoutExpired:
            pass
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:                     # the group is gone
        pass
    proc.wait()


def _start(size: str, timeout: float, state_dir: str):
    """A headless viewer on a free port, and a client connected to it. The viewer keeps its
    state (the last blueprint of each application) in ``state_dir``, a fresh folder: a
    blueprint saved by an earlier session would replace the recording's own layout."""
    from rerun.experimental import ViewerClient
    port = _free_port()
    env = {**os.environ, "XDG_DATA_HOME": state_dir, "XDG_CONFIG_HOME": state_dir}
    proc = subprocess.Popen(["rerun", "--headless", "--window-size", size, "--port", str(port),
                             "--hide-welcome-screen"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
                            start_new_session=True)      # its own group: _stop reaches the viewer it starts
    t0 = time.monotonic()
    while True:
        try:
            viewer = ViewerClient.connect(f"rerun+http://127.0.0.1:{port}/proxy")
            viewer.get_state()
            return proc, viewer
        except Exception:
            if time.monotonic() - t0 > timeout or proc.poll() is not None:
                _stop(proc)
                raise RuntimeError("the headless Rerun viewer did not start (is a Vulkan driver installed? "
                                   "apt-get install mesa-vulkan-drivers)") from None
            time.sleep(0.5)


def render_one(path, png: Path, size: str = "1600x900", at_time: float = None, timeout: float = 120.0) -> Path:
    """One recording in a fresh viewer (a viewer keeps the first blueprint it saw for an
    application), screenshot once everything has loaded."""
    path = Path(path).resolve()
    if not path.is_file():
        raise FileNotFoundError(f"no recording at {path}")
    state = tempfile.TemporaryDirectory()
    proc, viewer = _start(size, timeout, state.name)
    try:
        viewer.open(str(path))
        t1 = time.monotonic()
        while not _loaded(viewer.get_state()):
            if time.monotonic() - t1 > timeout:
                raise TimeoutError(f"{path} still loading after {timeout:g} s")
            time.sleep(0.25)
        rec = viewer.get_state().recordings[-1]
        tl = next((t for t in rec.timelines if t.name == "time"), None)
        if tl is not None:
            ns = tl.start if at_time is None else int(round(at_time * 1e9))
            viewer.set_time("time", duration=ns * 1e-9, recording=rec.store_id)
        time.sleep(1.0)                           # a few frames for the views to lay out their data
        from mjeap.io.outputs import replacing
        with replacing(png, "png") as tmp:        # mjeap's one writer: whole, never through a link
            viewer.save_screenshot(str(Path(tmp).resolve()))
        return png
    finally:
        _stop(proc)
        state.cleanup()


def render(paths, out_dir: Path, size: str = "1600x900", at_time: float = None, timeout: float = 120.0):
    out = []
    for p in paths:
        png = render_one(p, Path(out_dir) / (Path(p).stem + ".png"), size, at_time, timeout)
        print(png)
        out.append(png)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("recordings", nargs="+")
    ap.add_argument("--out-dir", default="out/png")
    ap.add_argument("--size", default="1600x900", help="window size in logical points, WIDTHxHEIGHT")
    ap.add_argument("--time", type=float, default=None, help="time cursor in s (default: the start)")
    ap.add_argument("--timeout", type=float, default=120.0, help="s to wait for the viewer and each file")
    a = ap.parse_args(argv)
    render(a.recordings, Path(a.out_dir), a.size, a.time, a.timeout)


if __name__ == "__main__":
    sys.exit(main())
