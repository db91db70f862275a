"""mjeap's Gymnasium ids, registered by entry-point strings: registering imports no
environment module (nor MuJoCo model), only Gymnasium's registry.

``import mjeap`` calls :func:`register_envs` when gymnasium is installed; so do
``gymnasium.make("mjeap:mjeap/HamrWalk-v0")`` (Gymnasium 1.x's ``module:id`` form) and
the ``gymnasium.envs`` entry point of the installed package (Gymnasium 0.26-0.29's plugins).
"""
from __future__ import annotations

__all__ = ["ENVS", "register_envs"]

#: id -> entry point (each environment truncates its own episodes at its time_limit)
ENVS = {
    "mjeap/CurvatureTracking-v0": "mjeap.envs.gymnasium_env:CurvatureTrackingEnv",
    "mjeap/HamrWalk-v0": "mjeap.envs.hamr_walk:HamrWalkEnv",
    "mjeap/GripperGrasp-v0": "mjeap.envs.gripper_grasp:GripperGraspEnv",
}


def register_envs() -> list:
    """Register every id of :data:`ENVS` not yet in Gymnasium's registry (a second call, or a
    re-import, changes nothing); returns the ids registered now."""
    # the registration module, not the package: as a plugin of Gymnasium 0.26-0.29 this runs
    # while the package ``gymnasium`` is still being imported
    from gymnasium.envs.registration import register, registry
    new = [i for i in ENVS if i not in registry]
    for env_id in new:
        register(id=env_id, entry_point=ENVS[env_id])
    return new
