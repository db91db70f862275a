"""RoboBee wing (Jayaram et al. 2018, section 6.1): one pzt-robobee actuator flaps a rigid wing through
its transmission, in air (``mjeap robot robobee-wing``).

The robot in two modules: :mod:`mjeap.robots.robobee_wing.model` (the wing's builder and
read-out) and :mod:`mjeap.robots.robobee_wing.experiments` (stroke against frequency and the
self-sensing estimate, the command line). Their public names are here too; this module
registers the robot (:mod:`mjeap.robots.registry`).
"""
from . import experiments, model
from .experiments import *  # noqa: F401,F403
from .model import *  # noqa: F401,F403
from ..registry import Robot, register, summary

register(Robot("robobee-wing", summary(experiments.__doc__), model.build, experiments.main, model.READOUTS,
               ("robobee", "piezo", "transmission", "fluid", "self-sensing")))
