"""HAMR single leg (Jayaram et al. 2018, section 6.2): two pzt-hamr-small actuators drive a rigid leg
through its swing and lift transmissions (``mjeap robot hamr-leg``).

The robot in two modules: :mod:`mjeap.robots.hamr_leg.model` (the leg's design, builder and
read-out) and :mod:`mjeap.robots.hamr_leg.experiments` (the resonance sweeps and the
closed-loop run, the command line). Their public names are here too; this module registers
the robot (:mod:`mjeap.robots.registry`).
"""
from . import experiments, model
from .experiments import *  # noqa: F401,F403
from .model import *  # noqa: F401,F403
from ..registry import Robot, register, summary

register(Robot("hamr-leg", summary(experiments.__doc__), model.build, experiments.main, model.READOUTS,
               ("hamr", "piezo", "transmission", "self-sensing")))
