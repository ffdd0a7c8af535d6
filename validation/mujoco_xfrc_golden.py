"""Reference data for `xfrc_applied` (Cartesian wrenches on bodies): MuJoCo's mj_step on
tests/data/mjcf/applied/xfrc.xml with constant wrenches on the free box, the forearm and the hand
welded to it, stepped by Euler and RK4; qpos and qvel after 1, 50 and 200 steps. Writes
tests/data/mujoco/xfrc.json (generated: do not edit); with --check, recomputes and exits 1 when
the committed file differs beyond 1e-12 (another MuJoCo would give other numbers).

  python validation/mujoco_xfrc_golden.py [--check]
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
SCENE = ROOT / "tests/data/mjcf/applied/xfrc.xml"
OUT = ROOT / "tests/data/mujoco/xfrc.json"
WRENCHES = {
    "box": [3.0, -1.0, 25.0, 0.2, 0.1, -0.3],
    "forearm": [0.0, 0.5, 2.0, 0.05, 0.0, 0.02],
    "hand": [1.0, 0.0, -0.5, 0.0, 0.03, 0.0],
}
SAMPLES = [1, 50, 200]


def run(integrator: str) -> list[dict]:
    m = mujoco.MjModel.from_xml_path(str(SCENE))
    m.opt.integrator = {"euler": mujoco.mjtIntegrator.mjINT_EULER, "rk4": mujoco.mjtIntegrator.mjINT_RK4}[integrator]
    d = mujoco.MjData(m)
    for name, w in WRENCHES.items():
        d.xfrc_applied[m.body(name).id] = w
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
        "generated_by": "validation/mujoco_xfrc_golden.py (do not edit)",
        "mujoco": mujoco.__version__,
        "model": str(SCENE.relative_to(ROOT)),
        "wrenches": WRENCHES,
        "runs": {name: run(name) for name in ("euler", "rk4")},
    }
    if args.check:
        old = json.loads(OUT.read_text())
        worst = max(max_sample_difference(samples, old["runs"][name]) for name, samples in doc["runs"].items())
        ok = worst <= 1e-12 and old["wrenches"] == WRENCHES
        print(f"xfrc reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} ({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
