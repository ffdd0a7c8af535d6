"""Reference data for MuJoCo's no-slip post-process (`<option noslip_iterations
noslip_tolerance>`, mj_solNoSlip in engine_solver.c): on tests/data/mjcf/noslip/*.xml (a box on a
20 degree incline, pyramidal and elliptic cones, condim 3 and 6; a two-finger squeeze of a box on
slide joints with friction loss), for noslip_iterations 0, 10 and 100: mj_forward's efc_force, qacc
and qfrc_constraint after 20 mj_step (contacts established), and the 200-step mj_step trajectory
(qpos and qvel after 1, 50 and 200 steps). The scenes' main solver is tight (tolerance 1e-12).
Writes tests/data/mujoco/noslip.json (generated: do not edit); with --check, recomputes and exits 1
when the committed file differs beyond 1e-12 (another MuJoCo would give other numbers).

  python validation/mujoco_noslip_golden.py [--check]
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
SCENES = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "tests/data/mjcf/noslip").glob("*.xml"))
OUT = ROOT / "tests/data/mujoco/noslip.json"
NOSLIP_ITERATIONS = [0, 10, 100]
SAMPLES = [1, 50, 200]
WARMUP = 20
CTRL = 5.0  # squeeze force on each finger (scenes with actuators)
FORWARD_KEYS = ("qpos", "qvel", "efc_force", "qacc", "qfrc_constraint")


def start(scene: str, iterations: int) -> tuple[mujoco.MjModel, mujoco.MjData]:
    m = mujoco.MjModel.from_xml_path(str(ROOT / scene))
    m.opt.noslip_iterations = iterations
    d = mujoco.MjData(m)
    d.ctrl[:] = CTRL
    return m, d


def forward(scene: str, iterations: int) -> dict:
    m, d = start(scene, iterations)
    for _ in range(WARMUP):
        mujoco.mj_step(m, d)
    mujoco.mj_forward(m, d)
    out = {key: getattr(d, key).tolist() for key in FORWARD_KEYS}
    out["efc_type"] = d.efc_type.tolist()
    return out


def run(scene: str, iterations: int) -> list[dict]:
    m, d = start(scene, iterations)
    out = []
    for k in range(1, max(SAMPLES) + 1):
        mujoco.mj_step(m, d)
        if k in SAMPLES:
            out.append({"step": k, "qpos": d.qpos.tolist(), "qvel": d.qvel.tolist()})
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    doc = {
        "generated_by": "validation/mujoco_noslip_golden.py (do not edit)",
        "mujoco": mujoco.__version__,
        "warmup_steps": WARMUP,
        "ctrl": CTRL,
        "scenes": {
            scene: {
                str(n): {"forward": forward(scene, n), "run": run(scene, n)} for n in NOSLIP_ITERATIONS
            }
            for scene in SCENES
        },
    }
    if args.check:
        old = json.loads(OUT.read_text())
        worst = 0.0
        for scene, cases in doc["scenes"].items():
            for n, new in cases.items():
                ref = old["scenes"][scene][n]
                worst = max(worst, max_sample_difference([new["forward"]], [ref["forward"]], FORWARD_KEYS))
                worst = max(worst, max_sample_difference(new["run"], ref["run"]))
        ok = worst <= 1e-12
        print(f"noslip reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} ({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
