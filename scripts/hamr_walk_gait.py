"""HAMR-VI's open-loop trot per frequency (10-65 Hz) at full drive and reduced amplitude,
beside the robot's published speeds (mjeap.robots.hamr_walk.study.gait_study); about 2 min
per run on one core:

    python scripts/hamr_walk_gait.py [--out out/hamr_walk_gait.json] [--figure out/hamr_walk_gait.png]
        [--frequencies 10 20 30 40 50 65] [--amplitudes 100 50 30] [--from-json FILE]
"""
import sys

from mjeap.io.commandline import run_script
from mjeap.robots.hamr_walk.study import gait_main

if __name__ == "__main__":
    sys.exit(run_script(gait_main))
