"""Controllers for mjeap's actuators and robots, installed as ``mjeap.controllers`` (the
repository keeps them in its top-level ``controllers/`` folder): curvature tracking
(seed 000), self-sensing of velocity from the drive current (seed 003, eqs. 7-9), and the
HAMR leg's phase loops."""
