"""HAMR-VI walks (issue 25; Jayaram et al. 2018, section 6.2): a free-floating 1.43 g, 4.51 cm
quadruped, four legs of two pzt-hamr-small actuators each, trotting on a ground plane
(``mjeap robot hamr-walk``).

The robot in modules by job: :mod:`~mjeap.robots.hamr_walk.model` (the walker's builder, its
ground contact and its read-outs), :mod:`~mjeap.robots.hamr_walk.experiments` (the trot open
and closed loop, the rest, segment and incline checks), :mod:`~mjeap.robots.hamr_walk.metrics`
(a walk's read-outs), :mod:`~mjeap.robots.hamr_walk.recording` (its Rerun recording),
:mod:`~mjeap.robots.hamr_walk.cli` (the command line) and :mod:`~mjeap.robots.hamr_walk.study`
(one-parameter studies and the gait study); the phase loops are
:mod:`mjeap.controllers.hamr_walk`. Their public names are here too; this module registers the
robot (:mod:`mjeap.robots.registry`).
"""
from . import cli, experiments, metrics, model, recording
from .cli import main
from .experiments import *  # noqa: F401,F403
from .metrics import *  # noqa: F401,F403
from .model import *  # noqa: F401,F403
from .recording import write_recording  # noqa: F401
from ..registry import Robot, register, summary

register(Robot("hamr-walk", summary(cli.__doc__), model.build, cli.main, model.READOUTS,
               ("hamr", "piezo", "transmission", "legged", "contact")))
