"""Reference data for `<flag override>` (issue 30): for each scene of tests/data/mjcf/override,
MuJoCo's mj_forward at a few states (the box at given heights, tilted by a random rotation through
mj_integratePos, random qvel) — the contacts' dist, includemargin, friction, solref,
solreffriction and solimp, efc_force, qacc — and a 200-step mj_step trajectory from qpos0 at a
given initial qvel (qpos, qvel after 1, 50, 100 and 200 steps). Writes
tests/data/mujoco/override.json (generated: do not edit); with --check, recomputes and exits 1 when
the committed file differs beyond 1e-12 (another MuJoCo would give other numbers). Read by
tests/override_mujoco.rs.

  python validation/mujoco_override_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "tests/data/mjcf/override"
OUT = ROOT / "tests/data/mujoco/override.json"
#: Per scene: the heights of the box's centre at the forward states, and the trajectory's qvel0.
SETUP = {
    "box_on_plane.xml": {"heights": [0.097, 0.104, 0.1085, 0.2], "qvel0": [0.8, 0.2, 0.0, 0.0, 0.0, 1.5]},
}
SAMPLES = [1, 50, 100, 200]
CONTACT_KEYS = ["dist", "includemargin", "friction", "solref", "solreffriction", "solimp"]


def lists(d, keys):
    return {k: np.asarray(getattr(d, k)).ravel().tolist() for k in keys}


def scene(name: str) -> dict:
    path = SCENES / name
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(30)
    setup = SETUP[name]
    states = []
    for z in setup["heights"]:
        qpos = m.qpos0.copy()
        qpos[2] = z
        mujoco.mj_integratePos(m, qpos, np.r_[0, 0, 0, rng.uniform(-0.02, 0.02, 3)], 1.0)
        d.qpos[:] = qpos
        d.qvel[:] = rng.uniform(-0.5, 0.5, m.nv)
        mujoco.mj_forward(m, d)
        contacts = [{k: np.asarray(getattr(c, k)).ravel().tolist() for k in CONTACT_KEYS}
                    for c in d.contact[:d.ncon]]
        states.append({**lists(d, ["qpos", "qvel", "qacc", "efc_force"]), "contacts": contacts})
    mujoco.mj_resetData(m, d)
    d.qvel[:] = setup["qvel0"]
    run = []
    for k in range(1, max(SAMPLES) + 1):
        mujoco.mj_step(m, d)
        if k in SAMPLES:
            run.append({"step": k, **lists(d, ["qpos", "qvel"])})
    return {"model": str(path.relative_to(ROOT)), "qvel0": setup["qvel0"], "states": states, "run": run}


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


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    doc = {
        "generated_by": "validation/mujoco_override_golden.py (do not edit)",
        "mujoco": mujoco.__version__,
        "scenes": {name: scene(name) for name in SETUP},
    }
    if args.check:
        old = json.loads(OUT.read_text())
        worst = worst_difference(doc["scenes"], old["scenes"])
        ok = worst <= 1e-12
        print(f"override reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} ({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
