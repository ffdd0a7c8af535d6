"""Reference data for sleeping islands (`<flag sleep>`): MuJoCo's mj_step, sleep enabled, on
tests/data/mjcf/sleep/drop.xml (three boxes and a sphere dropped on a floor fall asleep; a sphere
dropped from higher up lands on box b1, wakes it, and the two fall asleep together; Euler and
implicitfast, 500 steps — not RK4: MuJoCo's RK4 wakes a tree again at the step after it sleeps, by
its stage configurations), tests/data/mjcf/sleep/bin50.xml (50 spheres dropped in a bin, all
asleep at step 147; Euler, 300 steps) and MuJoCo's model/sleep/dominos.xml (96 dominos, the chain
reaction waking them one by one; Euler, 300 steps). Records `tree_asleep` after every step (a
line of integers), qpos every 20 steps (60 for the dominos), and the model's `dof_length` and
`tree_sleep_policy`. Writes tests/data/mujoco/sleep.json (generated: do not edit); with --check,
recomputes and exits 1 when the committed file differs beyond 1e-12.

  python validation/mujoco_sleep_golden.py [--check]
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco

sys.path.insert(0, str(Path(__file__).resolve().parent))
from golden_common import golden_main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tests/data/mujoco/sleep.json"
SCENES = {
    "drop": (ROOT / "tests/data/mjcf/sleep/drop.xml", ["euler", "implicitfast"], 500, 20),
    "bin50": (ROOT / "tests/data/mjcf/sleep/bin50.xml", ["euler"], 300, 20),
    "dominos": (ROOT / "tests/data/mjcf/sleep/dominos.xml", ["euler"], 300, 60),
}
INTEGRATORS = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
}


def run(path: Path, integrator: str, steps: int, every: int) -> dict:
    m = mujoco.MjModel.from_xml_path(str(path))
    m.opt.integrator = INTEGRATORS[integrator]
    d = mujoco.MjData(m)
    asleep, samples = [], []
    for k in range(1, steps + 1):
        mujoco.mj_step(m, d)
        asleep.append(" ".join(str(int(x)) for x in d.tree_asleep))
        if k % every == 0:
            samples.append({"step": k, "qpos": d.qpos.tolist(), "ncon": int(d.ncon)})
    return {
        "model": str(path.relative_to(ROOT)),
        "integrator": integrator,
        "dof_length": m.dof_length.tolist(),
        "tree_sleep_policy": [int(x) for x in m.tree_sleep_policy],
        "tree_asleep": asleep,
        "samples": samples,
    }


def scenes() -> dict:
    return {
        f"{name}_{i}": run(path, i, n, every) for name, (path, integrators, n, every) in SCENES.items() for i in integrators
    }


if __name__ == "__main__":
    sys.exit(golden_main(__doc__, "validation/mujoco_sleep_golden.py", "sleep", OUT, ROOT, scenes))
