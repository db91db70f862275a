"""Drive models: voltage in, bending moments out (see :mod:`mjeap.drives.base`)."""
from .base import DRIVES, Drive, ExactLTI, NativeForm, OpenLoop, default_drive_name, get_drive_class, make_drive, register_drive
from . import blocking_force, electrostrictive, passive, piezo, piezo_laminate, rc_relaxation  # noqa: F401  (registers)
from .small_signal import SmallSignal
from ..model import actuator_file as _actuator_file

__all__ = ["DRIVES", "Drive", "OpenLoop", "NativeForm", "ExactLTI", "SmallSignal", "default_drive_name",
           "get_drive_class", "make_drive", "register_drive"]

# actuator files name a drive and its parameters: the model layer checks them with this
# layer's answers (it does not import the drives above it)
_actuator_file.set_drive_info(_actuator_file.DriveInfo(
    units=lambda name: get_drive_class(name).parameter_units(),
    extra=lambda name: get_drive_class(name).extra_parameters(None),
    stack_reason=lambda name, act: get_drive_class(name).stack_reason(act),
    default=default_drive_name))
