"""Reference data for MuJoCo's fluid forces (`<option density viscosity wind>`, geom
`fluidshape="ellipsoid"`): on tests/data/mjcf/fluid/{inertia_box,ellipsoid}.xml from their
keyframe "moving", mj_forward's qfrc_fluid, qfrc_passive and qacc at the keyframe and after 100
Euler steps, and mj_step trajectories (Euler and RK4, qpos and qvel after 1, 50 and 200 steps).
Writes tests/data/mujoco/fluid.json (generated: do not edit); with --check, recomputes and exits 1
when the committed file differs beyond 1e-12 (another MuJoCo would give other numbers).

  python validation/mujoco_fluid_golden.py [--check]
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
SCENES = ["tests/data/mjcf/fluid/inertia_box.xml", "tests/data/mjcf/fluid/ellipsoid.xml"]
OUT = ROOT / "tests/data/mujoco/fluid.json"
SAMPLES = [1, 50, 200]
FORWARD_KEYS = ("qpos", "qvel", "qfrc_fluid", "qfrc_passive", "qacc")
INTEGRATORS = {"euler": mujoco.mjtIntegrator.mjINT_EULER, "rk4": mujoco.mjtIntegrator.mjINT_RK4}


def start(scene: str, integrator: str = "euler") -> tuple[mujoco.MjModel, mujoco.MjData]:
    m = mujoco.MjModel.from_xml_path(str(ROOT / scene))
    m.opt.integrator = INTEGRATORS[integrator]
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("moving").id)
    return m, d


def forward_sample(m: mujoco.MjModel, d: mujoco.MjData) -> dict:
    mujoco.mj_forward(m, d)
    return {key: getattr(d, key).tolist() for key in FORWARD_KEYS}


def forwards(scene: str) -> list[dict]:
    m, d = start(scene)
    out = [forward_sample(m, d)]
    for _ in range(100):
        mujoco.mj_step(m, d)
    out.append(forward_sample(m, d))
    return out


def run(scene: str, integrator: str) -> list[dict]:
    m, d = start(scene, integrator)
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
        "generated_by": "validation/mujoco_fluid_golden.py (do not edit)",
        "mujoco": mujoco.__version__,
        "scenes": {
            scene: {"forward": forwards(scene), "runs": {name: run(scene, name) for name in INTEGRATORS}}
            for scene in SCENES
        },
    }
    if args.check:
        old = json.loads(OUT.read_text())
        worst = 0.0
        for scene, new in doc["scenes"].items():
            ref = old["scenes"][scene]
            worst = max(worst, max_sample_difference(new["forward"], ref["forward"], FORWARD_KEYS))
            for name, samples in new["runs"].items():
                worst = max(worst, max_sample_difference(samples, ref["runs"][name]))
        ok = worst <= 1e-12
        print(f"fluid reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} ({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
