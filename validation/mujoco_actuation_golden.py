"""Reference data for the actuation features of issue 30 (gravity compensation with and without
`actuatorgravcomp`, muscles, adhesion, `<flag override>`, joint and tendon `actuatorfrcrange`
reached under implicitfast): for each scene of tests/data/mjcf/actuation,
MuJoCo's mj_forward at random states (qpos from qpos0 moved by a random velocity through
mj_integratePos, random qvel, act and ctrl) — qfrc_gravcomp, qfrc_passive, qfrc_actuator,
actuator_length, actuator_velocity, actuator_force, act_dot, qacc — the model's
actuator_lengthrange and actuator_acc0, and a 200-step mj_step trajectory from qpos0 at fixed controls (qpos, qvel,
act after 1, 50, 100 and 200 steps). Writes tests/data/mujoco/actuation.json (generated: do not
edit); with --check, recomputes and exits 1 when the committed file differs beyond 1e-12 (another
MuJoCo would give other numbers). Read by tests/actuation_mujoco.rs.

  python validation/mujoco_actuation_golden.py [--check]
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from golden_common import golden_main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "tests/data/mjcf/actuation"
OUT = ROOT / "tests/data/mujoco/actuation.json"
#: Per scene: the fixed controls of the trajectory (one per actuator).
CONTROLS = {
    "gravcomp.xml": [0.3, 0.1],
    "muscle_limits.xml": [0.8, 0.2, 1.3, 0.5],
    "muscle_written.xml": [0.6, 1.0, 0.05, 0.9],
    "actfrcrange_implicitfast.xml": [1.0, 0.7, 0.5],
}
NSTATES = 4
SAMPLES = [1, 50, 100, 200]
FORWARD_KEYS = ["qfrc_gravcomp", "qfrc_passive", "qfrc_actuator", "actuator_length", "actuator_velocity",
                "actuator_force", "act_dot", "qacc"]


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
        mujoco.mj_integratePos(m, qpos, rng.uniform(-0.6, 0.6, m.nv), 1.0)
        d.qpos[:] = qpos
        d.qvel[:] = rng.uniform(-1.0, 1.0, m.nv)
        d.act[:] = rng.uniform(0.0, 1.0, m.na)
        lo = np.where(m.actuator_ctrllimited, m.actuator_ctrlrange[:, 0], -1.0)
        hi = np.where(m.actuator_ctrllimited, m.actuator_ctrlrange[:, 1], 1.0)
        d.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_forward(m, d)
        states.append({**lists(d, ["qpos", "qvel", "act", "ctrl"]), **lists(d, FORWARD_KEYS)})
    mujoco.mj_resetData(m, d)
    d.ctrl[:] = CONTROLS[name]
    run = []
    for k in range(1, max(SAMPLES) + 1):
        mujoco.mj_step(m, d)
        if k in SAMPLES:
            run.append({"step": k, **lists(d, ["qpos", "qvel", "act"])})
    return {
        "model": str(path.relative_to(ROOT)),
        "actuator_lengthrange": m.actuator_lengthrange.ravel().tolist(),
        "actuator_acc0": m.actuator_acc0.ravel().tolist(),
        "states": states,
        "ctrl": CONTROLS[name],
        "run": run,
    }


def main() -> int:
    return golden_main(__doc__, "validation/mujoco_actuation_golden.py", "actuation", OUT, ROOT,
                       lambda: {name: scene(name) for name in CONTROLS})


if __name__ == "__main__":
    sys.exit(main())
