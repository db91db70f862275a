"""HAMR-VI's open-loop trot per frequency (10-65 Hz): the robot's drive (the swing within its
travel, the no-flight lift) at full and half swing, and the full drive (100 V on every
actuator), beside the robot's published speeds (mjeap.robots.hamr_walk.study.gait_study);
about 1 min per run on one core:

    python scripts/hamr_walk_gait.py [--out out/hamr_walk_gait.json] [--figure out/hamr_walk_gait.png]
        [--frequencies 10 20 30 40 50 65] [--from-json FILE]
"""
import sys

from mjeap.io.commandline import run_script
from mjeap.robots.hamr_walk.study import gait_main

if __name__ == "__main__":
    sys.exit(run_script(gait_main))
