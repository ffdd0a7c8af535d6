"""Reference data for inline meshes (`<mesh vertex=... face=...>`, no file): MuJoCo's mj_step on
tests/data/mjcf/applied/mesh_inline_rest.xml (an inline box, an inline point cloud without
faces and a built-in icosphere dropped onto a plane) for 200 steps, qpos and qvel after 1, 50, 100 and 200 steps and the
contacts' count; and each mesh's compiled vertices (mesh_vert, MuJoCo's inertial frame, f32) with
the body's mass. Writes tests/data/mujoco/mesh_inline_rest.json (generated: do not edit); with
--check, recomputes and exits 1 when the committed file differs beyond 1e-12. Masses, inertias,
M and qfrc_bias of inline meshes are in validation/mujoco_golden.py (tests/data/mjcf/mesh_inline.xml).

  python validation/mujoco_meshsrc_golden.py [--check]
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
SCENE = ROOT / "tests/data/mjcf/applied/mesh_inline_rest.xml"
OUT = ROOT / "tests/data/mujoco/mesh_inline_rest.json"
SAMPLES = [1, 50, 100, 200]


def run() -> tuple[list[dict], list[dict]]:
    m = mujoco.MjModel.from_xml_path(str(SCENE))
    d = mujoco.MjData(m)
    meshes = []
    for i in range(m.nmesh):
        a, n = m.mesh_vertadr[i], m.mesh_vertnum[i]
        meshes.append({"name": m.mesh(i).name, "vert": m.mesh_vert[a:a + n].tolist(),
                       "body_mass": float(m.body_mass[i + 1])})
    out = []
    for k in range(1, max(SAMPLES) + 1):
        mujoco.mj_step(m, d)
        if k in SAMPLES:
            out.append({"step": k, "qpos": d.qpos.tolist(), "qvel": d.qvel.tolist(), "ncon": int(d.ncon)})
    return out, meshes


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    samples, meshes = run()
    doc = {"generated_by": "validation/mujoco_meshsrc_golden.py (do not edit)", "mujoco": mujoco.__version__,
           "model": str(SCENE.relative_to(ROOT)), "meshes": meshes, "samples": samples}
    if args.check:
        old = json.loads(OUT.read_text())
        worst = max_sample_difference(doc["samples"], old["samples"])
        worst = max([worst] + [abs(a["ncon"] - b["ncon"]) for a, b in zip(doc["samples"], old["samples"])])
        for a, b in zip(doc["meshes"], old["meshes"]):
            worst = max([worst, abs(a["body_mass"] - b["body_mass"])]
                        + [abs(x - y) for va, vb in zip(a["vert"], b["vert"]) for x, y in zip(va, vb)])
        ok = worst <= 1e-12 and len(doc["meshes"]) == len(old["meshes"])
        print(f"inline mesh reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} "
              f"({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
