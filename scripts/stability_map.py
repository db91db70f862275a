"""Stability map of the PEDOT micro trilayer standing up (Dadras et al. 2021): payload mass x drive
amplitude, each point a 0.1 Hz square-wave rollout judged by Dadras et al. 2021's criterion (the tip
curvature still changes sign in the third period), run as an mjeap sweep.

    python scripts/stability_map.py [--out out/stability] [--workers 2] [--executor processes|dask]
                                    [--accuracy 1e-2]

Writes results.csv (resumable), stability_map.png, report.md and stability_map.rrd. The
theory drawn over it is amplitude independent: the Euler column with the payload on a rigid
arm (k a tan(kL) = 1) with the instantaneous EI and with the relaxed EI (eq. 8's DC
stiffness, x 0.3/0.52), and the paper's own Region 3 model's marginal mass.
"""
import sys

from mjeap.io.commandline import run_script
from mjeap.studies.stability_map import main

if __name__ == "__main__":
    sys.exit(run_script(main))
