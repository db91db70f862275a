"""Environments for learning and control. This floor sits above the robots, because a robot
is also a task. One module per environment:

* dm_env: curvature tracking with one bending actuator, ``mjeap.make_environment``
  (:mod:`mjeap.envs.environment`). Its ``dm_env`` backend (:mod:`mjeap.envs.dm_tracking`)
  runs on any MuJoCo; its ``dm_control`` backend (:mod:`mjeap.envs.dm_control_env`) is
  dm_control's ``control.Environment`` on MuJoCo 3.x.
* Gymnasium 1.x (the optional ``gym`` extra; MuJoCo 3.17 and 4.x): ``mjeap/CurvatureTracking-v0``
  (:mod:`mjeap.envs.gymnasium_env`), ``mjeap/HamrWalk-v0`` (:mod:`mjeap.envs.hamr_walk`) and
  ``mjeap/GripperGrasp-v0`` (:mod:`mjeap.envs.gripper_grasp`). The two robots are built on
  :mod:`mjeap.envs.system_env`. ``import mjeap`` registers the ids by entry-point strings
  (:mod:`mjeap.envs.registration`). An environment declares only the render modes that work
  in the process (:mod:`mjeap.envs.rendering`).
* :mod:`mjeap.envs.tracking` holds what the tracking environments share.

Nothing is imported here: each environment imports its own framework."""
