"""Reference data for MuJoCo 4.0's built-in meshes (`<mesh builtin=... params=...>`), each at 2-3
parameter sets: one free body with one mesh geom (scaled, density 800) over a plane. Per case: the
compiled vertices (mesh_vert, MuJoCo's inertial frame, f32), the generated ones (the spec's
uservert/userface, mesh frame, before scale), the body's mass, com (body_ipos) and
principal inertia (body_inertia), and qpos/qvel after 1, 40 and 120 steps of mj_step as the body falls
onto the plane on its collision hull. Built-ins MuJoCo refuses as such a geom are listed with its
error. Writes tests/data/mujoco/mesh_builtin.json (generated: do not edit); with --check,
recomputes and exits 1 when the committed file differs beyond 1e-12.

  python validation/mujoco_builtin_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mujoco

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tests/data/mujoco/mesh_builtin.json"
SAMPLES = [1, 40, 120]
# A visual mesh geom (no hull needed) beside a colliding sphere: a flat shell alone fails
# MuJoCo's A + B >= C check on the body's inertia by round-off.
VISUAL = 'contype="0" conaffinity="0"/><geom type="sphere" size="0.03" density="800"'
CASES = [
    ("sphere", "1"), ("cone", "6 0.5"),
    ("hemisphere", "0"), ("hemisphere", "2"), ("hemisphere", "5"),
    ("supersphere", "8 1 1"), ("supersphere", "12 0.5 2"), ("supersphere", "6 2 0.3"),
    ("supertorus", "8 0.5 1 1"), ("supertorus", "12 0.3 0.5 2"), ("supertorus", "10 1 2 0.5"),
    ("wedge", "8 8 60 30 0"), ("wedge", "6 4 120 45 0.5"), ("wedge", "5 7 180 90 1"),
    ("grid", "3 3 3 1 1 1"), ("grid", "2 4 3 1 0.5 0.7 3"),
    ("box", "3 3 3 1 1 1"), ("box", "4 3 2 0.7 1 1.5"), ("box", "2 3 4 1 0.5 0.8 2"),
    ("cylinder", "3 3 3 1 1 1"), ("cylinder", "6 4 2 1 1 1"), ("cylinder", "6 5 3 0.6 0.5 1 2"),
    ("ellipsoid", "3 3 3 1 1 1"), ("ellipsoid", "5 4 4 0.5 0.6 0.5"), ("ellipsoid", "4 4 3 1 1 1 2"),
    # MuJoCo's inertia switches: a dim-2 surface keeps a non-legacy mode; the plate is always shell.
    ("box", "3 3 3 1 1 1 2", 'inertia="convex"'), ("box", "3 4 2 1 1 1 2", 'inertia="exact"'),
    ("ellipsoid", "3 3 3 1 1 1", 'inertia="shell"'),
    # The flat built-ins as visual geoms (contype/conaffinity 0: no hull needed), shell mass, on a
    # body with a sphere.
    ("plate", "3 3", "", VISUAL), ("plate", "4 2", 'inertia="exact"', VISUAL),
    ("square", "3 4 1 0.5 0.4 0.3", "", VISUAL), ("grid", "3 4 1 0.5 0.3 0.1 2", "", VISUAL),
    ("disc", "5 5 1 0.4 0.4 0.1", "", VISUAL), ("disc", "4 6 1 0.3 0.5 0.1", "", VISUAL),
]
# Refused as a mesh geom: flat surfaces and point sets (MuJoCo's convex hull fails), and each
# parameter check of the sampled built-ins (MuJoCo's message; ours quotes its reason).
REFUSED = [
    ("plate", "3 3"), ("square", "3 3 1 0.1 0.1 0.1"), ("disc", "4 4 1 0.1 0.1 0.1"),
    ("grid", "3 3 1 0.1 0.1 0.1 2"), ("wedge", "2 2 60 30 0"), ("wedge", "2 1 60 30 0"),
    ("wedge", "1 1 1 1"), ("wedge", "2 2 0 30 0"), ("wedge", "2 2 60 91 0"), ("wedge", "0 2 60 30 0"),
    ("wedge", "2 2 60 30 1.5"), ("plate", "3"), ("plate", "0 3"),
    ("grid", "3 3 3 0.1 0.1"), ("grid", "3 3 3 0.1 0.1 0.1 4"), ("grid", "0 3 3 0.1 0.1 0.1"),
    ("grid", "3 3 3 0.1 0.1 0.1 2"), ("grid", "1 3 3 0.1 0.1 0.1"), ("grid", "3 3 3 0 0.1 0.1"),
    ("box", "3 3 3 0.1 0.1"), ("box", "3 3 3 0.1 0.1 0.1 1"), ("cylinder", "1 3 3 0.1 0.1 0.1"),
    ("ellipsoid", "3 3 1 0.1 0.1 0.1 2"),
    ("square", "3 3 1 0.1 0.1 0.1 2"), ("square", "0 3 1 0.1 0.1 0.1"), ("disc", "3 3 2 0.1 0.1 0.1"),
    ("disc", "1 3 1 0.1 0.1 0.1"), ("cone", "2 0.5"), ("cone", "6 1.5"),
]


def xml(builtin: str, params: str, mesh_attrs: str = "", geom_attrs: str = "") -> str:
    return (f'<mujoco><option timestep="0.002"/><asset><mesh name="m" builtin="{builtin}" params="{params}" '
            f'scale="0.1 0.08 0.06"{" " + mesh_attrs if mesh_attrs else ""}/></asset><worldbody>'
            f'<geom type="plane" size="2 2 0.1"/><body pos="0.01 -0.02 0.12" euler="20 30 10"><freejoint/>'
            f'<geom type="mesh" mesh="m" density="800"{" " + geom_attrs if geom_attrs else ""}/></body>'
            f'</worldbody></mujoco>')


def case(builtin: str, params: str, mesh_attrs: str = "", geom_attrs: str = "") -> dict:
    text = xml(builtin, params, mesh_attrs, geom_attrs)
    m = mujoco.MjModel.from_xml_string(text)
    spec = mujoco.MjSpec.from_string(text)
    d = mujoco.MjData(m)
    out = {"builtin": builtin, "params": params, "xml": text, "collides": not geom_attrs,
           "vert": m.mesh_vert.tolist(), "nface": int(m.mesh_facenum[0]),
           "uservert": [float(x) for x in spec.meshes[0].uservert],
           "userface": [int(x) for x in spec.meshes[0].userface],
           "body_mass": float(m.body_mass[1]), "body_ipos": m.body_ipos[1].tolist(),
           "body_inertia": m.body_inertia[1].tolist(), "samples": []}
    for k in range(1, max(SAMPLES) + 1):
        mujoco.mj_step(m, d)
        if k in SAMPLES:
            out["samples"].append({"step": k, "qpos": d.qpos.tolist(), "qvel": d.qvel.tolist(),
                                   "ncon": int(d.ncon)})
    return out


def refused(builtin: str, params: str) -> dict:
    try:
        mujoco.MjModel.from_xml_string(xml(builtin, params))
        return {"builtin": builtin, "params": params, "error": None}
    except ValueError as e:
        return {"builtin": builtin, "params": params, "error": str(e).splitlines()[0]}


def flat(x):
    return [y for v in x for y in (flat(v) if isinstance(v, list) else [v])]


def diff(a: dict, b: dict) -> float:
    keys = ["vert", "uservert", "userface", "body_mass", "body_ipos", "body_inertia"]
    xs = [flat([a[k]]) for k in keys] + [flat([s["qpos"], s["qvel"], s["ncon"]]) for s in a["samples"]]
    ys = [flat([b[k]]) for k in keys] + [flat([s["qpos"], s["qvel"], s["ncon"]]) for s in b["samples"]]
    if any(len(x) != len(y) for x, y in zip(xs, ys)):
        return float("inf")
    return max(abs(p - q) for x, y in zip(xs, ys) for p, q in zip(x, y))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    doc = {"generated_by": "validation/mujoco_builtin_golden.py (do not edit)", "mujoco": mujoco.__version__,
           "cases": [case(*c) for c in CASES], "refused": [refused(b, p) for b, p in REFUSED]}
    if args.check:
        old = json.loads(OUT.read_text())
        worst = max(diff(a, b) for a, b in zip(doc["cases"], old["cases"]))
        ok = (worst <= 1e-12 and len(doc["cases"]) == len(old["cases"])
              and doc["refused"] == old["refused"])
        print(f"built-in mesh reference data: live MuJoCo {mujoco.__version__} differs by {worst:.1e} "
              f"({'ok' if ok else 'CHANGED'})")
        return 0 if ok else 1
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
