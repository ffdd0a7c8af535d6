"""Reference data for the solver edge <option iterations="0"> (issue 27, item 6): MuJoCo's mj_step
on tests/data/mjcf/edges/box_iterations0.xml for each solver (Newton, CG, PGS), the box dropped
from z = 0.2 m (qpos, qvel, qacc and the first contact rows' efc_force after 1, 100, 200 and 500
steps: no iteration, so the box falls through the floor at qacc_smooth while Newton and CG still
report the forces of the cost at that acceleration and PGS reports none), and mj_forward with the
box resting 1 cm into the floor from a fresh data (zero warm start: Newton and CG keep qacc = 0).
Writes tests/data/mujoco/edges.json (generated: do not edit); with --check, recomputes and exits
1 when the committed file differs beyond 1e-12.

  python validation/mujoco_edges_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mujoco

sys.path.insert(0, str(Path(__file__).resolve().parent))
from crossval_common import max_sample_difference  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "tests/data/mjcf/edges/box_iterations0.xml"
OUT = ROOT / "tests/data/mujoco/edges.json"
SAMPLES = [1, 100, 200, 500]
SOLVERS = {"Newton": mujoco.mjtSolver.mjSOL_NEWTON, "CG": mujoco.mjtSolver.mjSOL_CG, "PGS": mujoco.mjtSolver.mjSOL_PGS}
KEYS = ("qpos", "qvel", "qacc", "efc_force")


def sample(d: mujoco.MjData, label: str, k: int) -> dict:
    return {"solver": label, "step": k, "nefc": int(d.nefc), "qpos": d.qpos.tolist(), "qvel": d.qvel.tolist(),
            "qacc": d.qacc.tolist(), "efc_force": d.efc_force[:4].tolist() if d.nefc else [0.0] * 4}


def run() -> list[dict]:
    out = []
    for label, solver in SOLVERS.items():
        m = mujoco.MjModel.from_xml_path(str(SCENE))
        m.opt.solver = solver
        d = mujoco.MjData(m)
        for k in range(1, max(SAMPLES) + 1):
            mujoco.mj_step(m, d)
            if k in SAMPLES:
                out.append(sample(d, label, k))
        d = mujoco.MjData(m)
        d.qpos[2] = 0.09
        mujoco.mj_forward(m, d)
        out.append(sample(d, label, 0))
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    doc = {"generated_by": "validation/mujoco_edges_golden.py (do not edit)", "mujoco": mujoco.__version__,
           "model": str(SCENE.relative_to(ROOT)), "samples": run()}
    if args.check:
        old = json.loads(OUT.read_text())
        worst = max_sample_difference(doc["samples"], old["samples"], KEYS)
        worst = max([worst] + [abs(a["nefc"] - b["nefc"]) for a, b in zip(doc["samples"], old["samples"])])
        ok = worst <= 1e-12
        print(f"iterations=0 reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} ({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
