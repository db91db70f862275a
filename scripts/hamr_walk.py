"""HAMR-VI walks (Jayaram et al. 2018, section 6.2): the whole quadruped trotting open loop on a ground
plane; speed against frequency, the paper's 0.5 m/s at 65 Hz, slip, attitude.

The experiment lives in :mod:`mjeap.robots.hamr_walk`; this is its command line, the same as
``mjeap robot hamr-walk``:

    python scripts/hamr_walk.py --help
"""
import sys

from mjeap.io.commandline import run_script
from mjeap.robots.hamr_walk import main

if __name__ == "__main__":
    sys.exit(run_script(main))
