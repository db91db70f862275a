"""Regenerate the golden tip-curvature trajectories in tests/golden/ (after an intentional
physics change), then review: git diff tests/golden"""
from pathlib import Path

from mjeap.validation.golden import SCENARIOS, write

if __name__ == "__main__":
    out = Path(__file__).resolve().parent.parent / "tests" / "golden"
    write(out)
    print(f"wrote {len(SCENARIOS)} trajectories to {out}")
