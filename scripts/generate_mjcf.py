#!/usr/bin/env python
"""Regenerate assets/mjcf/: one MJCF file per catalog actuator and representation.

Run after any change to the catalog or the beam builders; tests/test_assets.py fails
while the files are stale.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mjeap.assets import ASSET_DIR, write_assets  # noqa: E402

if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ASSET_DIR
    for name in write_assets(out):
        print(out / name)
