"""One episode of the dm_env curvature-tracking environment, driven by the controller of
:mod:`mjeap.controllers.curvature_tracking`, recorded to a Rerun file.

    python scripts/env_episode.py [--seed 0] [--duration 20] [--out out/env-episode.rrd]

pedot-micro standing up with a payload at 6.27 mm whose mass is drawn per episode from
1-12.6 mg, initial curvature from -20..20 1/m; reference: 50 1/m at 0.05 Hz.

The episode lives in :func:`mjeap.envs.environment.main`; this is its command line.
"""
import sys

from mjeap.io.commandline import run_script
from mjeap.envs.environment import main

if __name__ == "__main__":
    sys.exit(run_script(main))
