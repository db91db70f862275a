"""Controllers for mjeap's actuators and robots (the controllers floor, above analysis: they
use scenes, rollouts and the frequency tools, and nothing of the environments, studies or
robots that use them): curvature tracking (Dadras et al. 2021), self-sensing of velocity from the
drive current (Jayaram et al. 2018, eqs. 7-9), and the HAMR leg's phase loops."""
