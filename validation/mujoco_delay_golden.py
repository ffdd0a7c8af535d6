"""Reference data for delayed controls (MuJoCo 4.0's actuator `delay`, `nsample`, `interp`: the
history buffers `d.history`): the scenes of tests/data/mjcf/delay (one arm, each integrator) run
for 60 `mj_step` from `mj_resetData` with controls that change every step (seeded), recording
after every step qpos, qvel, act, actuator_force and history; plus the initial history. Writes
tests/data/mujoco/delay.json (generated: do not edit); with --check, recomputes and exits 1 when
the committed file differs beyond 1e-12. Read by tests/delay_mujoco.rs.

  python validation/mujoco_delay_golden.py [--check]
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from golden_common import golden_main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "tests/data/mjcf/delay"
OUT = ROOT / "tests/data/mujoco/delay.json"
NSTEPS = 60
KEYS = ["qpos", "qvel", "act", "actuator_force", "history"]


def lists(d, keys):
    return {k: np.asarray(getattr(d, k)).ravel().tolist() for k in keys}


def scene(path: Path) -> dict:
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_resetData(m, d)
    rng = np.random.default_rng(33)
    initial = lists(d, ["history"])
    steps = []
    for k in range(NSTEPS):
        d.ctrl[:] = rng.uniform(-1.5, 1.5, m.nu)
        ctrl = d.ctrl.tolist()
        mujoco.mj_step(m, d)
        steps.append({"step": k + 1, "ctrl": ctrl, **lists(d, KEYS)})
    return {
        "nhistory": int(m.nhistory),
        "actuator_history": m.actuator_history.ravel().tolist(),
        "actuator_historyadr": m.actuator_historyadr.tolist(),
        "actuator_delay": m.actuator_delay.tolist(),
        "initial": initial,
        "steps": steps,
    }


def scenes() -> dict:
    return {p.name: scene(p) for p in sorted(SCENES.glob("*.xml"))}


if __name__ == "__main__":
    sys.exit(golden_main(__doc__, "validation/mujoco_delay_golden.py", "delay", OUT, ROOT, scenes))
