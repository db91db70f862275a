#!/usr/bin/env python
"""Regenerate assets/mjcf/: one MJCF file per catalog actuator and representation.

Run after any change to the catalog or the beam builders; tests/validation/test_assets.py fails
while the files are stale. Each MuJoCo writes the representations it runs: run it under
MuJoCo 4.x for the hinge and rod files and under 3.17 for the cable files (the hinge files
are the same from either).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mjeap.assets import ASSET_DIR, write_assets  # noqa: E402

if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ASSET_DIR
    for name in write_assets(out):
        print(out / name)
    from mjeap.model.mjcf import BUILDERS
    for rep, b in BUILDERS.items():
        if b.unavailable_reason() is not None:
            print(f"left as they are: the {rep} files ({b.unavailable_reason()})")
