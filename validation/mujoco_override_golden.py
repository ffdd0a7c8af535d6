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

import sys
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from golden_common import golden_main  # noqa: E402

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


def main() -> int:
    return golden_main(__doc__, "validation/mujoco_override_golden.py", "override", OUT, ROOT,
                       lambda: {name: scene(name) for name in SETUP})


if __name__ == "__main__":
    sys.exit(main())
