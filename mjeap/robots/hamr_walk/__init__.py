"""HAMR-VI walks (issue 25; Jayaram et al. 2018, section 6.2): a free-floating 1.43 g, 4.51 cm
quadruped, four legs of two pzt-hamr-small actuators each, trotting on a ground plane
(``mjeap robot hamr-walk``).

The robot in three modules: :mod:`mjeap.robots.hamr_walk.model` (the walker's builder, its
ground contact and its read-outs), :mod:`mjeap.robots.hamr_walk.experiments` (the trot open
and closed loop, the rest, segment and incline checks, the command line) and
:mod:`mjeap.robots.hamr_walk.study` (one-parameter studies of why it rolls over at 65 Hz).
The model's and the experiments' public names are here too; this module registers the
robot (:mod:`mjeap.robots.registry`).
"""
from . import experiments, model
from .experiments import *  # noqa: F401,F403
from .model import *  # noqa: F401,F403
from ..registry import Robot, register, summary

register(Robot("hamr-walk", summary(experiments.__doc__), model.build, experiments.main, model.READOUTS,
               ("hamr", "piezo", "transmission", "legged", "contact")))
