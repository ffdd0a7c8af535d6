"""Reference contacts of MuJoCo's height-field collision (`mjc_ConvexHField`): a sphere on a free
joint over a small committed terrain (`<hfield elevation=...>` on a posed, rotated body), at
hand-made poses (above, touching, penetrating, over cell edges, diagonals and corners, near and
beyond the border) and seeded random ones, with and without a margin; per pose mj_collision's
contacts (geom pair, pos, frame, dist, includemargin). Writes tests/data/mujoco/hfield_collision.json
(generated: do not edit); with --check, recomputes with the live MuJoCo and exits 1 when the
committed file differs beyond 1e-12. The same for a capsule, box, cylinder and ellipsoid at
random poses and orientations (tests/data/mujoco/hfield_convex_collision.json).

  python validation/mujoco_hfield_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tests/data/mujoco/hfield_collision.json"
OUT_CONVEX = ROOT / "tests/data/mujoco/hfield_convex_collision.json"

# The other geoms MuJoCo collides with a height field (by mjc_ConvexHField's prisms).
CONVEX_GEOMS = [
    ("capsule", 'type="capsule" size="0.1 0.15"'),
    ("box", 'type="box" size="0.15 0.1 0.08"'),
    ("cylinder", 'type="cylinder" size="0.12 0.1"'),
    ("ellipsoid", 'type="ellipsoid" size="0.15 0.1 0.08"'),
]

TERRAIN = (
    '<hfield name="t" nrow="4" ncol="5" size="1 0.8 0.3 0.1" '
    'elevation="0 1 2 3 2  1 1 0.5 1 0  3 2 0 1 2  0 0.2 0.4 2.5 1"/>'
)


def scene(name: str, margin: float) -> dict:
    mjcf = f"""<mujoco model="{name}">
  <asset>{TERRAIN}</asset>
  <worldbody>
    <body name="ground" pos="0.1 -0.2 0.05" euler="4 -3 20">
      <geom name="terrain" type="hfield" hfield="t"/>
    </body>
    <body name="ball">
      <freejoint/>
      <geom name="ball" type="sphere" size="0.15" margin="{margin}"/>
    </body>
  </worldbody>
</mujoco>
"""
    return {"name": name, "mjcf": mjcf}


def convex_scene(name: str, geom: str, margin: float) -> dict:
    mjcf = f"""<mujoco model="{name}">
  <asset>{TERRAIN}</asset>
  <worldbody>
    <body name="ground" pos="0.1 -0.2 0.05" euler="4 -3 20">
      <geom name="terrain" type="hfield" hfield="t"/>
    </body>
    <body name="thing">
      <freejoint/>
      <geom name="thing" {geom} margin="{margin}"/>
    </body>
  </worldbody>
</mujoco>
"""
    return {"name": name, "mjcf": mjcf}


def hand_made() -> list[tuple[str, list[float]]]:
    """Sphere centres in the terrain's frame (before its pose), named."""
    return [
        ("above", [0.0, 0.0, 0.8]),
        ("touching-high-corner", [-0.5, 0.8 / 3.0 * 2 - 0.8, 0.15 + 0.3 * 2 / 3]),
        ("penetrating-centre", [0.0, 0.0, 0.1]),
        ("cell-diagonal", [-0.25, -0.4, 0.12]),
        ("cell-edge-x", [0.0, -0.3, 0.05]),
        ("grid-corner", [0.5, 0.8 / 3.0 - 0.8 + 1.6 / 3, 0.2]),
        ("near-border", [0.98, 0.7, 0.3]),
        ("beyond-border", [1.2, 0.0, 0.1]),
        ("side-contact", [1.1, 0.1, 0.0]),
        ("below-base", [0.0, 0.0, -0.3]),
        ("deep", [0.3, 0.2, -0.05]),
    ]


def world_pos(m: mujoco.MjModel, d: mujoco.MjData, local: list[float]) -> list[float]:
    g = m.geom("terrain").id
    return (d.geom_xpos[g] + d.geom_xmat[g].reshape(3, 3) @ np.array(local)).tolist()


def cases(sc: dict, nrandom: int = 200, turn: bool = False) -> list[dict]:
    m = mujoco.MjModel.from_xml_string(sc["mjcf"])
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    poses = [(n, world_pos(m, d, p)) for n, p in hand_made()]
    rng = np.random.default_rng(25)
    for k in range(nrandom):
        local = [rng.uniform(-1.15, 1.15), rng.uniform(-0.95, 0.95), rng.uniform(-0.2, 0.45)]
        poses.append((f"random-{k}", world_pos(m, d, local)))
    quats = [[np.cos(0.3), np.sin(0.3) * 0.6, np.sin(0.3) * 0.8, 0.0]]
    if turn:
        for _ in poses:
            q = rng.normal(size=4)
            quats.append((q / np.linalg.norm(q)).tolist())
    out = []
    for k, (name, p) in enumerate(poses):
        d.qpos[:] = 0
        d.qpos[:3] = p
        d.qpos[3:7] = quats[k + 1] if turn else quats[0]
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        out.append(
            {
                "name": name,
                "qpos": d.qpos.tolist(),
                "contacts": [
                    {
                        "geom": [int(c.geom1), int(c.geom2)],
                        "pos": c.pos.tolist(),
                        "frame": c.frame.tolist(),
                        "dist": float(c.dist),
                        "includemargin": float(c.includemargin),
                    }
                    for c in d.contact[: d.ncon]
                ],
            }
        )
    return out


def flat(doc: dict) -> list[float]:
    vals = []
    for sc in doc["scenes"]:
        for c in sc["cases"]:
            vals += c["qpos"] + [len(c["contacts"])]
            for k in c["contacts"]:
                vals += k["pos"] + k["frame"] + [k["dist"], k["includemargin"]] + k["geom"]
    return vals


def convex_doc() -> dict:
    scenes = [convex_scene(n, g, 0.0) for n, g in CONVEX_GEOMS]
    scenes += [convex_scene(n + "-margin", g, 0.02) for n, g in CONVEX_GEOMS]
    for sc in scenes:
        sc["cases"] = cases(sc, nrandom=60, turn=True)
    return {"generator": "validation/mujoco_hfield_golden.py (do not edit)", "mujoco": mujoco.__version__, "scenes": scenes}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    scenes = [scene("sphere", 0.0), scene("sphere-margin", 0.03)]
    for sc in scenes:
        sc["cases"] = cases(sc)
    doc = {"generator": "validation/mujoco_hfield_golden.py (do not edit)", "mujoco": mujoco.__version__, "scenes": scenes}
    cdoc = convex_doc()
    if args.check:
        bad = 0
        for path, d in ((OUT, doc), (OUT_CONVEX, cdoc)):
            old, new = flat(json.loads(path.read_text())), flat(d)
            worst = float("inf") if len(old) != len(new) else max((abs(a - b) for a, b in zip(old, new)), default=0.0)
            ok = worst <= 1e-12
            bad += not ok
            print(f"{path.name}: live MuJoCo {mujoco.__version__} differs by {worst:.1e} ({'ok' if ok else 'CHANGED'})")
        return 0 if bad == 0 else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    OUT_CONVEX.write_text(json.dumps(cdoc, indent=1) + "\n")
    ccounts = [len(c["contacts"]) for sc in cdoc["scenes"] for c in sc["cases"]]
    print(f"wrote {OUT_CONVEX.relative_to(ROOT)}: {len(ccounts)} cases, {sum(ccounts)} contacts, max {max(ccounts)} per case")
    counts = [len(c["contacts"]) for sc in scenes for c in sc["cases"]]
    print(f"wrote {OUT.relative_to(ROOT)}: {len(counts)} cases, {sum(counts)} contacts, max {max(counts)} per case")
    return 0


if __name__ == "__main__":
    sys.exit(main())
