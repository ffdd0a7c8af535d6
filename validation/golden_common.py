"""What the MuJoCo golden scripts share (validation/mujoco_*_golden.py): the comparison of a
recomputed reference tree with the committed one, and their `main` — write the JSON file, or with
--check recompute in memory and exit 1 when a number moved beyond 1e-12 or the tree's shape
changed."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Callable

CHECK_ABS = 1e-12


def worst_difference(a, b) -> float:
    """The largest absolute difference between two JSON trees of numbers (inf on a shape change)."""
    if isinstance(a, dict):
        if not isinstance(b, dict) or a.keys() != b.keys():
            return float("inf")
        return max((worst_difference(a[k], b[k]) for k in a), default=0.0)
    if isinstance(a, list):
        if not isinstance(b, list) or len(a) != len(b):
            return float("inf")
        return max((worst_difference(x, y) for x, y in zip(a, b)), default=0.0)
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return abs(a - b)
    return 0.0 if a == b else float("inf")


def golden_main(doc: str, script: str, label: str, out: Path, root: Path, scenes: Callable[[], dict]) -> int:
    """A golden script's `main`: `scenes()` is the reference data, stored under "scenes" with the
    script's name and MuJoCo's version; `label` names it in the --check line."""
    import mujoco

    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    tree = {"generated_by": f"{script} (do not edit)", "mujoco": mujoco.__version__, "scenes": scenes()}
    if args.check:
        old = json.loads(out.read_text())
        worst = worst_difference(tree["scenes"], old["scenes"])
        ok = worst <= CHECK_ABS
        print(f"{label} reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} "
              f"({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    out.write_text(json.dumps(tree, indent=1) + "\n")
    print(f"wrote {out.relative_to(root)}")
    return 0
