"""Reference data for mocap bodies: MuJoCo's mj_step on tests/data/mjcf/applied/mocap.xml, with
the mocap poses set before every step by the same formulas as tests/mocap.rs (the pusher slides
along x; the hand rises and turns about z), stepped by Euler for 300 steps; qpos and qvel after
1, 50, 150 and 300 steps, and the contacts' count at each sample. Writes tests/data/mujoco/mocap.json
(generated: do not edit); with --check, recomputes and exits 1 when the committed file differs
beyond 1e-12.

  python validation/mujoco_mocap_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import mujoco

sys.path.insert(0, str(Path(__file__).resolve().parent))
from crossval_common import max_sample_difference  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "tests/data/mjcf/applied/mocap.xml"
OUT = ROOT / "tests/data/mujoco/mocap.json"
SAMPLES = [1, 50, 150, 300]


def mocap_at(t: float) -> tuple[list[list[float]], list[list[float]]]:
    """Poses of the two mocap bodies (pusher, hand) at time t: tests/mocap.rs uses the same."""
    pusher = [-0.3 + 0.6 * t, 0.0, 0.1]
    angle = math.radians(20.0) + 1.5 * t
    hand = [1.0, 0.0, 0.8 + 0.2 * t]
    quat = [math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2)]
    return [pusher, hand], [[1.0, 0.0, 0.0, 0.0], quat]


def run() -> list[dict]:
    m = mujoco.MjModel.from_xml_path(str(SCENE))
    d = mujoco.MjData(m)
    out = []
    for k in range(1, max(SAMPLES) + 1):
        pos, quat = mocap_at(d.time)
        d.mocap_pos[:] = pos
        d.mocap_quat[:] = quat
        mujoco.mj_step(m, d)
        if k in SAMPLES:
            out.append({"step": k, "qpos": d.qpos.tolist(), "qvel": d.qvel.tolist(), "ncon": int(d.ncon)})
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    doc = {"generated_by": "validation/mujoco_mocap_golden.py (do not edit)", "mujoco": mujoco.__version__,
           "model": str(SCENE.relative_to(ROOT)), "samples": run()}
    if args.check:
        old = json.loads(OUT.read_text())
        worst = max_sample_difference(doc["samples"], old["samples"])
        worst = max([worst] + [abs(a["ncon"] - b["ncon"]) for a, b in zip(doc["samples"], old["samples"])])
        ok = worst <= 1e-12
        print(f"mocap reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} ({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
