"""PEDOT micro-gripper (Dadras et al. 2021's actuator, built for micromanipulation): two pedot-micro
fingers close on a steel bead resting on a table, hold it and lift it (``mjeap robot
gripper``).

The robot in two modules: :mod:`mjeap.robots.gripper.model` (the gripper's builder and
read-out) and :mod:`mjeap.robots.gripper.experiments` (the grip force, the lift threshold and
the hard-finger check, the command line). Their public names are here too; this module
registers the robot (:mod:`mjeap.robots.registry`).
"""
from . import experiments, model
from .experiments import *  # noqa: F401,F403
from .model import *  # noqa: F401,F403
from ..registry import Robot, register, summary

register(Robot("gripper", summary(experiments.__doc__), model.build, experiments.main, model.READOUTS,
               ("pedot", "contact", "friction")))
