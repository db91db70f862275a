"""What the environments can render in this process, and the renderer they share.

Gymnasium's ``check_env`` makes an environment in every mode it declares, so an environment
declares only the modes that work here (:func:`render_modes`): none with ``MUJOCO_GL=disable``
(mjeap's default when MUJOCO_GL is unset) or without an OpenGL library; ``rgb_array``
where ``mujoco.Renderer`` opens an offscreen context (``MUJOCO_GL=egl`` or ``osmesa``, or
GLFW with a display); ``human`` (MuJoCo's passive viewer) only with a display.
"""
from __future__ import annotations

import functools
import importlib.util
import os
import sys
from typing import Optional

import mujoco

from ..errors import MjeapError, ParameterError, check_integer

__all__ = ["render_modes", "check_render_mode", "SceneRenderer", "MAX_IMAGE_SIZE"]

MAX_IMAGE_SIZE = 4096
#: MuJoCo's values of MUJOCO_GL that turn OpenGL off (mujoco.rendering's gl_context)
GL_OFF = ("disable", "disabled", "off", "false", "0")


def _has_display() -> bool:
    """A window can open: macOS or Windows, or an X11 / Wayland display on Linux, and GLFW installed."""
    if importlib.util.find_spec("glfw") is None:
        return False
    return sys.platform in ("darwin", "win32") or bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


@functools.lru_cache(maxsize=None)
def render_modes() -> tuple:
    """The render modes that work in this process, probed once: ``rgb_array`` if an
    offscreen MuJoCo renderer opens, ``human`` if a window can open."""
    if os.environ.get("MUJOCO_GL", "").lower().strip() in GL_OFF:
        return ()
    modes = []
    try:
        mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 8, 8).close()
        modes.append("rgb_array")
    except Exception:       # no GL library, no display for GLFW, a context that fails
        pass
    if _has_display():
        modes.append("human")
    return tuple(modes)


class SceneRenderer:
    """Renders ``data`` of ``model``: an (height, width, 3) uint8 image from ``camera`` (a
    free camera framing the model if None) in ``rgb_array`` mode, MuJoCo's passive viewer
    synchronised in ``human`` mode (render returns None). Refuses a mode that does not work
    here (:func:`render_modes`), naming what would make it work."""

    def __init__(self, mode: str, model: mujoco.MjModel, data: mujoco.MjData, width: int = 480, height: int = 480,
                 camera: Optional[mujoco.MjvCamera] = None):
        width = check_integer("width", width, 1, MAX_IMAGE_SIZE)
        height = check_integer("height", height, 1, MAX_IMAGE_SIZE)
        check_render_mode(mode)
        self.mode, self.data = mode, data
        self._renderer = self._viewer = None
        if mode == "rgb_array":
            vis = model.vis.global_
            vis.offwidth, vis.offheight = max(vis.offwidth, width), max(vis.offheight, height)
            self._renderer = mujoco.Renderer(model, height, width)
            if camera is None:
                camera = mujoco.MjvCamera()
                mujoco.mjv_defaultFreeCamera(model, camera)
            self.camera = camera
        else:
            from mujoco import viewer
            self._viewer = viewer.launch_passive(model, data)

    def render(self):
        if self._renderer is None and self._viewer is None:
            raise MjeapError("render() after close(): the renderer was released")
        if self._viewer is not None:
            self._viewer.sync()
            return None
        self._renderer.update_scene(self.data, camera=self.camera)
        return self._renderer.render()

    def close(self) -> None:
        """Release the GL context or the window; safe to call twice."""
        if self._renderer is not None:
            self._renderer.close()
        if self._viewer is not None:
            self._viewer.close()
        self._renderer = self._viewer = None


def check_render_mode(mode: Optional[str]) -> Optional[str]:
    """``mode`` if None or one that works here, else a ParameterError saying what does."""
    if mode is None or mode in render_modes():
        return mode
    gl = os.environ.get("MUJOCO_GL", "")
    raise ParameterError("render_mode", mode, f"None or one of {list(render_modes())} in this process",
                         f"MUJOCO_GL={gl!r}: 'rgb_array' needs an OpenGL backend (MUJOCO_GL=egl or osmesa, set "
                         "before mujoco and mjeap are imported), 'human' a display")
