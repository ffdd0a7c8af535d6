"""Reference data for sleeping islands (`<flag sleep>`): MuJoCo's mj_step on
tests/data/mjcf/sleep/drop.xml (three boxes and a sphere dropped on a floor fall asleep; a sphere
dropped from higher up lands on box b1, wakes it, and the two fall asleep together), Euler, sleep
enabled. Records `tree_asleep` after every step and qpos, qvel every 10 steps, for 500 steps, and
the model's `dof_length` and `tree_sleep_policy`. Writes tests/data/mujoco/sleep.json (generated:
do not edit); with --check, recomputes and exits 1 when the committed file differs beyond 1e-12.

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
SCENES = {"drop": ROOT / "tests/data/mjcf/sleep/drop.xml"}
STEPS = 500
EVERY = 10


def run(path: Path) -> dict:
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    asleep, samples = [], []
    for k in range(1, STEPS + 1):
        mujoco.mj_step(m, d)
        asleep.append([int(x) for x in d.tree_asleep])
        if k % EVERY == 0:
            samples.append({"step": k, "qpos": d.qpos.tolist(), "qvel": d.qvel.tolist(), "ncon": int(d.ncon)})
    return {
        "model": str(path.relative_to(ROOT)),
        "dof_length": m.dof_length.tolist(),
        "tree_sleep_policy": [int(x) for x in m.tree_sleep_policy],
        "tree_asleep": asleep,
        "samples": samples,
    }


def scenes() -> dict:
    return {name: run(path) for name, path in SCENES.items()}


if __name__ == "__main__":
    sys.exit(golden_main(__doc__, "validation/mujoco_sleep_golden.py", "sleep", OUT, ROOT, scenes))
