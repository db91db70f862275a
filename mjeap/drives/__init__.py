"""Drive models: voltage in, bending moments out (see :mod:`mjeap.drives.base`)."""
from .base import DRIVES, Drive, ExactLTI, NativeForm, OpenLoop, default_drive_name, get_drive_class, make_drive, register_drive
from . import blocking_force, electrostrictive, passive, piezo, rc_relaxation  # noqa: F401  (registers)

__all__ = ["DRIVES", "Drive", "OpenLoop", "NativeForm", "ExactLTI", "default_drive_name", "get_drive_class", "make_drive",
           "register_drive"]
