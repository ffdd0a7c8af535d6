"""Reference data for adhesion: body transmissions (`<adhesion>`, `<general body=...>`) on
the scenes of tests/data/mjcf/adhesion. MuJoCo's mj_forward at states (qpos0 moved by a small random
velocity through mj_integratePos, so that contacts stay within margin and gap, random qvel and ctrl)
— the dense actuator_moment, actuator_length, actuator_velocity, actuator_force, qfrc_actuator,
qacc and the contact count — and a 200-step mj_step trajectory from qpos0 at fixed controls
(qpos, qvel after every step). Writes tests/data/mujoco/adhesion.json (generated: do not edit);
with --check, recomputes and exits 1 when the committed file differs beyond 1e-12. Read by
tests/adhesion_mujoco.rs.

  python validation/mujoco_adhesion_golden.py [--check]
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from golden_common import golden_main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "tests/data/mjcf/adhesion"
OUT = ROOT / "tests/data/mujoco/adhesion.json"
#: Per scene: the fixed controls of the trajectory (one per actuator).
CONTROLS = {
    "sphere_plane.xml": [0.8, 1.0],
    "suction_box.xml": [0.3, 1.0, 0.5],
    "box_elliptic.xml": [1.5],
}
NSTATES = 4
SAMPLES = list(range(1, 201))
FORWARD_KEYS = ["qfrc_actuator", "actuator_length", "actuator_velocity", "actuator_force", "qacc"]


def lists(d, keys):
    return {k: np.asarray(getattr(d, k)).ravel().tolist() for k in keys}


def scene(name: str) -> dict:
    path = SCENES / name
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(30)
    states = []
    for _ in range(NSTATES):
        qpos = m.qpos0.copy()
        mujoco.mj_integratePos(m, qpos, rng.uniform(-0.02, 0.02, m.nv), 1.0)
        d.qpos[:] = qpos
        d.qvel[:] = rng.uniform(-1.0, 1.0, m.nv)
        d.act[:] = rng.uniform(0.0, 1.0, m.na)
        lo = np.where(m.actuator_ctrllimited, m.actuator_ctrlrange[:, 0], -1.0)
        hi = np.where(m.actuator_ctrllimited, m.actuator_ctrlrange[:, 1], 1.0)
        d.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_forward(m, d)
        moment = np.zeros((m.nu, m.nv))
        mujoco.mju_sparse2dense(moment, d.actuator_moment, d.moment_rownnz, d.moment_rowadr, d.moment_colind)
        states.append({**lists(d, ["qpos", "qvel", "act", "ctrl"]), **lists(d, FORWARD_KEYS),
                       "actuator_moment": moment.ravel().tolist(), "ncon": int(d.ncon)})
    mujoco.mj_resetData(m, d)
    d.ctrl[:] = CONTROLS[name]
    run = []
    for k in range(1, max(SAMPLES) + 1):
        mujoco.mj_step(m, d)
        if k in SAMPLES:
            run.append({"step": k, **lists(d, ["qpos", "qvel"])})
    return {
        "model": str(path.relative_to(ROOT)),
        "states": states,
        "ctrl": CONTROLS[name],
        "run": run,
    }


def main() -> int:
    return golden_main(__doc__, "validation/mujoco_adhesion_golden.py", "adhesion", OUT, ROOT,
                       lambda: {name: scene(name) for name in CONTROLS})


if __name__ == "__main__":
    sys.exit(main())
