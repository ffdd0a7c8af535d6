"""Reference data for MJCF `springdamper` (MuJoCo's mjCModel::AutoSpringDamper): on
tests/data/mjcf/passive/springdamper.xml, MuJoCo 4.0's compiled `jnt_stiffness` and `dof_damping`,
and `qfrc_passive` after mj_forward at a few fixed states, plus qpos and qvel after 1, 100 and 300
mj_step from one of them. Writes tests/data/mujoco/springdamper.json (generated: do not edit);
with --check, recomputes and exits 1 when the committed file differs beyond 1e-12.

  python validation/mujoco_springdamper_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "tests/data/mjcf/passive/springdamper.xml"
OUT = ROOT / "tests/data/mujoco/springdamper.json"
STATES = [
    {"q": [0.3, -0.4, 0.02, 0.5], "v": [1.0, -2.0, 0.3, 0.7], "ctrl": [0.5]},
    {"q": [-0.7, 0.9, -0.04, -1.2], "v": [-0.4, 0.6, -0.9, 2.0], "ctrl": [-1.0]},
]
SAMPLES = [1, 100, 300]


def run() -> dict:
    m = mujoco.MjModel.from_xml_path(str(SCENE))
    d = mujoco.MjData(m)
    states = []
    for s in STATES:
        d.qpos[:], d.qvel[:], d.ctrl[:] = s["q"], s["v"], s["ctrl"]
        mujoco.mj_forward(m, d)
        states.append({**s, "qfrc_passive": d.qfrc_passive.tolist()})
    mujoco.mj_resetData(m, d)
    s = STATES[0]
    d.qpos[:], d.qvel[:], d.ctrl[:] = s["q"], s["v"], s["ctrl"]
    steps = []
    for k in range(1, max(SAMPLES) + 1):
        mujoco.mj_step(m, d)
        if k in SAMPLES:
            steps.append({"step": k, "qpos": d.qpos.tolist(), "qvel": d.qvel.tolist()})
    return {"jnt_stiffness": m.jnt_stiffness.tolist(), "dof_damping": m.dof_damping.tolist(),
            "actuator_damping": m.actuator_damping.tolist(), "states": states, "steps": steps}


def flat(doc: dict) -> np.ndarray:
    parts = [doc["jnt_stiffness"], doc["dof_damping"], doc["actuator_damping"]]
    parts += [s["qfrc_passive"] for s in doc["states"]]
    parts += [s["qpos"] + s["qvel"] for s in doc["steps"]]
    return np.concatenate([np.asarray(p, float) for p in parts])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    doc = {"generated_by": "validation/mujoco_springdamper_golden.py (do not edit)", "mujoco": mujoco.__version__,
           "model": str(SCENE.relative_to(ROOT)), **run()}
    if args.check:
        old = json.loads(OUT.read_text())
        worst = float(np.max(np.abs(flat(doc) - flat(old))))
        ok = worst <= 1e-12
        print(f"springdamper reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} "
              f"({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
