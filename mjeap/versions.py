"""What the installed MuJoCo and dm_control offer: mjeap runs on MuJoCo 3.17 and 4.x.

Measured differences (MuJoCo 4.0.0 against 3.17.0):
* the hinge chain, its native drives and ``mujoco.rollout`` give bit-identical trajectories;
* the cable plugin (``mujoco.elasticity.cable``) and ``<composite>`` are gone (1D
  ``flexcomp`` rods replace them): the ``cable`` representation is refused on 4.x;
* dm-control 1.0.50's ``Physics`` reads ``MjModel.flex_vertedge``, removed in 4.0: the dm_env
  environment is refused there, naming the versions;
* 4.0.0's sparse Cholesky factorisation gives the Newton solver a wrong Hessian factor when
  the constraint Jacobian is sparse (fixed in 4.0.1, google-deepmind/mujoco#3767): systems
  with contact diverge; mjeap builds them with a dense Jacobian on 4.0.0.
"""
from __future__ import annotations

import mujoco

__all__ = ["MJEAP_VERSION", "MUJOCO_VERSION", "mujoco_major", "cable_available", "dm_control_problem", "newton_sparse_broken"]

#: this package's version (``mjeap.__version__``), in every result's provenance
MJEAP_VERSION = "0.1.0"
MUJOCO_VERSION = mujoco.__version__


def mujoco_major() -> int:
    return int(MUJOCO_VERSION.split(".")[0])


def cable_available() -> bool:
    """The cable plugin and <composite> (MuJoCo 3.x only)."""
    return mujoco_major() < 4


def dm_control_problem() -> str:
    """Why dm_control's Physics cannot run on this MuJoCo ('' where it can)."""
    if hasattr(mujoco.MjModel, "flex_vertedge"):
        return ""
    try:
        from importlib.metadata import version
        dmc = version("dm-control")
    except Exception:  # pragma: no cover - not installed
        dmc = "?"
    return (f"dm-control {dmc}'s Physics reads MjModel.flex_vertedge, which MuJoCo {MUJOCO_VERSION} no longer has: "
            "dm_control's control.Environment needs MuJoCo 3.x (pip install 'mujoco>=3.17,<4'); "
            "make_environment's dm_env backend runs here")


def newton_sparse_broken() -> bool:
    """MuJoCo 4.0.0's sparse Cholesky bug (Newton solver, sparse constraint Jacobian)."""
    return MUJOCO_VERSION == "4.0.0"
