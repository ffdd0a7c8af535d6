"""Reference data for MJCF orientations: MuJoCo 4.0's compiled frames of bodies and geoms given
by `quat`, `axisangle`, `euler` (every `eulerseq` case, degrees and radians), `xyaxes`, `zaxis`
and `fromto`, at random values. Each body sits at the world's top level with one sphere in its
own frame, and some geoms sit on the world body itself, so MuJoCo's `geom_xmat` at qpos0 is the
compiled orientation turned into a matrix (`mju_quat2Mat`) with no product in between: lagrange
must give the same bits (tests/orientation_mujoco.rs). Writes tests/data/mujoco/orientation.json
(generated: do not edit); with --check, recomputes and exits 1 when the committed file differs.

  python validation/mujoco_orientation_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tests/data/mujoco/orientation.json"
PER_KIND = 16


def fmt(values) -> str:
    return " ".join(repr(float(x)) for x in values)


def orientations(rng: np.random.Generator, degree: bool) -> list[tuple[str, str]]:
    """(attribute, value) pairs of every kind, random."""
    out = []
    for _ in range(PER_KIND):
        out.append(("quat", fmt(rng.normal(size=4) * rng.choice([1.0, 0.5, 3.0]))))
        angle = rng.uniform(-180, 180) if degree else rng.uniform(-np.pi, np.pi)
        out.append(("axisangle", fmt([*(rng.normal(size=3) * rng.choice([1.0, 0.2, 7.0])), angle])))
        out.append(("euler", fmt(rng.uniform(-180, 180, size=3) if degree else rng.uniform(-np.pi, np.pi, size=3))))
        x, y = rng.normal(size=3), rng.normal(size=3)
        out.append(("xyaxes", fmt([*x, *y])))
        out.append(("zaxis", fmt(rng.normal(size=3) * rng.choice([1.0, 0.1, 5.0]))))
    # Round angles and axes: the cases written by hand.
    for e in ("90 0 0", "0 90 0", "0 0 90", "45 45 45", "180 0 0", "30 -60 120") if degree else ("1.5707963 0 0",):
        out.append(("euler", e))
    out += [("zaxis", "0 0 1"), ("zaxis", "0 0 -1"), ("zaxis", "1 0 0"), ("zaxis", "0 1 1"),
            ("xyaxes", "0 1 0 -1 0 0"), ("xyaxes", "1 0 0 0 0 1"), ("axisangle", "0 0 1 90" if degree else "0 0 1 1.5707963")]
    return out


def scene(rng: np.random.Generator, compiler: str, degree: bool) -> str:
    bodies, world_geoms = [], []
    for k, (attr, value) in enumerate(orientations(rng, degree)):
        pos = fmt(rng.uniform(-2, 2, size=3))
        bodies.append(f'<body pos="{pos}" {attr}="{value}"><geom type="sphere" size="0.05"/></body>')
        if k % 3 == 0:
            world_geoms.append(f'<geom type="box" size="0.1 0.2 0.3" pos="{pos}" {attr}="{value}" contype="0" conaffinity="0"/>')
    for _ in range(PER_KIND):
        a, b = rng.uniform(-1, 1, size=3), rng.uniform(-1, 1, size=3)
        kind = rng.choice(["capsule", "cylinder", "box", "ellipsoid"])
        size = "0.05" if kind in ("capsule", "cylinder") else "0.05 0.07"
        world_geoms.append(f'<geom type="{kind}" size="{size}" fromto="{fmt([*a, *b])}" contype="0" conaffinity="0"/>')
    for v in ([0, 0, 0, 0, 0, 1], [0.3, 0, 1, 0.3, 0, 0], [0, 0.2, 0, 1, 0.2, 0], [0.1, 0.2, 0.3, 0.1, 0.2, -0.3]):
        world_geoms.append(f'<geom type="capsule" size="0.05" fromto="{fmt(v)}" contype="0" conaffinity="0"/>')
    return (f"<mujoco><compiler {compiler}/><worldbody>" + "".join(world_geoms) + "".join(bodies)
            + "</worldbody></mujoco>")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    rng = np.random.default_rng(20261128)
    cases = []
    for name, compiler, degree in [
        ("degrees_xyz", 'angle="degree"', True),
        ("radians_ZYX", 'angle="radian" eulerseq="ZYX"', False),
        ("degrees_xYz", 'angle="degree" eulerseq="xYz"', True),
        ("radians_zxz", 'angle="radian" eulerseq="zxz"', False),
    ]:
        xml = scene(rng, compiler, degree)
        m = mujoco.MjModel.from_xml_string(xml)
        d = mujoco.MjData(m)
        mujoco.mj_kinematics(m, d)
        cases.append({"name": name, "mjcf": xml, "geom_xmat": d.geom_xmat.tolist(), "geom_xpos": d.geom_xpos.tolist()})
    doc = {"generated_by": "validation/mujoco_orientation_golden.py (do not edit)", "mujoco": mujoco.__version__,
           "cases": cases}
    if args.check:
        old = json.loads(OUT.read_text())
        same = old == json.loads(json.dumps(doc))
        print(f"mujoco_orientation_golden: {'same' if same else 'DIFFERENT'} ({sum(len(c['geom_xmat']) for c in cases)} geoms)")
        return 0 if same else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}: {sum(len(c['geom_xmat']) for c in cases)} geoms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
