"""Writes tests/data/mujoco/soft/*.json: MuJoCo's soft-constraint solution for tests/soft.rs.

For each scene, MuJoCo 4.0's mj_forward (Newton, tolerance 1e-15, 1000 iterations, ls_tolerance
1e-12, dense Jacobians: the tight copy of validation/crossval_soft.py) at the states of
crossval_soft.random_states: qacc, qacc_smooth, qfrc_constraint and nefc. Plus the rolling
cylinder of docs/physics.md §2.5 (models/textbook/incline_cylinder.xml) stepped by MuJoCo's Euler for
500 steps from rest: the distance travelled along the incline. Regenerate with
  validation/.venv/bin/python validation/mujoco_soft_golden.py
(the files say they are generated).
"""

import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import crossval_soft as cs  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tests/data/mujoco/soft"
SCENES = {
    "go1": "models/mjcf/unitree_go1/scene.xml",
    "humanoid": "models/mjcf/humanoid/humanoid.xml",
    "incline_box": "models/textbook/incline_box.xml",
    "weld_bodies_torquescale": "tests/data/mjcf/constraints/weld_bodies_torquescale.xml",
    "tendon_limit": "tests/data/mjcf/constraints/tendon_limit.xml",
}


def main():
    import mujoco as mj

    OUT.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(7)
    for name, rel in SCENES.items():
        copy = cs.tight_copy(ROOT / rel)
        try:
            m = mj.MjModel.from_xml_path(str(copy))
        finally:
            copy.unlink()
        states = []
        for q, v in cs.random_states(mj, m, rng, 6):
            d = mj.MjData(m)
            d.qpos[:], d.qvel[:] = q, v
            mj.mj_forward(m, d)
            states.append({"q": q.tolist(), "v": v.tolist(), "qacc": d.qacc.tolist(),
                           "qacc_smooth": d.qacc_smooth.tolist(), "qfrc_constraint": d.qfrc_constraint.tolist(),
                           "nefc": int(d.nefc)})
        doc = {"generated_by": "validation/mujoco_soft_golden.py", "mujoco": mj.__version__, "model": rel,
               "options": "solver Newton, tolerance 1e-15, iterations 1000, ls_iterations 100, ls_tolerance 1e-12",
               "states": states}
        (OUT / f"{name}.json").write_text(json.dumps(doc) + "\n")
        print(name, len(states), "states, nefc", [s["nefc"] for s in states])
    # Rolling cylinder (docs/physics.md §2.5): 500 Euler steps from rest.
    copy = cs.tight_copy(ROOT / "models/textbook/incline_cylinder.xml")
    try:
        m = mj.MjModel.from_xml_path(str(copy))
    finally:
        copy.unlink()
    m.opt.integrator = mj.mjtIntegrator.mjINT_EULER
    d = mj.MjData(m)
    steps = 500
    x0 = d.qpos[:3].copy()
    for _ in range(steps):
        mj.mj_step(m, d)
    theta = math.radians(30)
    downhill = np.array([math.cos(theta), 0, -math.sin(theta)])
    travelled = float((d.qpos[:3] - x0) @ downhill)
    t = steps * m.opt.timestep
    doc = {"generated_by": "validation/mujoco_soft_golden.py", "mujoco": mj.__version__,
           "model": "models/textbook/incline_cylinder.xml", "integrator": "Euler", "steps": steps,
           "timestep": m.opt.timestep, "travelled": travelled, "qpos": d.qpos.tolist(),
           "acceleration": 2 * travelled / t ** 2, "closed_form": 2 / 3 * 9.81 * math.sin(theta)}
    (OUT / "incline_cylinder_roll.json").write_text(json.dumps(doc) + "\n")
    print("cylinder: MuJoCo", doc["acceleration"], "closed form", doc["closed_form"],
          "rel", doc["acceleration"] / doc["closed_form"] - 1)


if __name__ == "__main__":
    main()
