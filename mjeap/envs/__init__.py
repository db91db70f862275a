"""Environments for learning and control (the envs floor, above the controllers): one task,
curvature tracking with one bending actuator, posed through dm_control's dm_env
(:mod:`mjeap.envs.environment`, MuJoCo 3.x with dm-control 1.0.50) and through Gymnasium 1.x
(:mod:`mjeap.envs.gymnasium_env`, MuJoCo 3.17 and 4.x; the optional ``gym`` extra), with the
pieces both share (:mod:`mjeap.envs.tracking`). Nothing is imported here: each environment
imports its own framework. The top level has them too: ``mjeap.make_environment`` and
``mjeap.CurvatureTrackingEnv``."""
