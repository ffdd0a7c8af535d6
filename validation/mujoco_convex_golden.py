#!/usr/bin/env python3
"""MuJoCo's contacts for the pairs of its convex solver (mjc_Convex), for lagrange's tests.

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_convex_golden.py            # (re)write tests/data/mujoco/convex/*.json
    python validation/mujoco_convex_golden.py --check    # recompute in memory, exit 1 if a file differs beyond round-off

One file per pair type MuJoCo sends through mjc_Convex (GJK/EPA and, with multiccd on by default,
its multi-point contacts): box-mesh and mesh-mesh (face and edge clipping), capsule-mesh,
capsule-cylinder, cylinder against box, cylinder and mesh (perturbed poses), and the one-contact
pairs with a sphere or an ellipsoid. Meshes: a cube and a corpus convex piece (Franka Panda's
link5_collision_1.obj, Apache-2.0, tests/data/meshes/mujoco/franka_emika_panda/LICENSE). The
scenes' MJCF names the mesh directory MESHDIR (the test and this script put the repository's
tests/data/meshes there). Cases as validation/mujoco_collision_golden.py makes them: seeded random
relative poses placed by bisection at a chosen smallest distance (penetrating, within the margin,
outside), resting poses with small tilts (parallel faces), edges and corners on faces.

Deterministic: a fixed seed per scene, floats written with repr, keys sorted. --check compares
numbers relative to the largest magnitude of their quantity (1e-12) and structure exactly.
"""

from __future__ import annotations

import json
import math
import pathlib
import sys
import zlib

import mujoco
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import mujoco_collision_golden as base  # noqa: E402
from mujoco_collision_golden import (ORIGIN, Q_I, Q_ZX, Scene, at, axis_angle, placed,  # noqa: E402
                                     qmul, random_cases, resting_cases, yaw_tilt)
from mujoco_golden import dump  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parent.parent
OUT_DIR = REPO / "tests" / "data" / "mujoco" / "convex"
MESHDIR = REPO / "tests" / "data" / "meshes"
SCRIPT = "validation/mujoco_convex_golden.py"
SEED = 20261126
CHECK_REL = 1e-12

BOX = 'type="box" size="0.25 0.1875 0.125"'
CUBE_MESH = 'type="mesh" mesh="cube"'
LINK5 = 'type="mesh" mesh="link5" pos="0 -0.16 0.24"'
CAPSULE = 'type="capsule" size="0.0625 0.25"'
CYLINDER = 'type="cylinder" size="0.125 0.25"'
CYLINDER_B = 'type="cylinder" size="0.09375 0.125"'
ELLIPSOID = 'type="ellipsoid" size="0.25 0.15625 0.125"'
SPHERE = 'type="sphere" size="0.125"'
ASSETS = ('<asset><mesh name="cube" file="cube.obj" scale="0.25 0.25 0.25"/>'
          '<mesh name="link5" file="mujoco/franka_emika_panda/link5_collision_1.obj" scale="2 2 2"/></asset>')
NO_MARGIN = (0.0, 0.0)
MARGIN = (0.015625, 0.0)


def mjcf(name, geom1, geom2, margins, flags="", assets="") -> str:
    margin, gap = margins
    extra = f' margin="{margin!r}" gap="{gap!r}"' if margin or gap else ""
    return "\n".join([
        f'<mujoco model="{name}">', '<compiler angle="radian" meshdir="MESHDIR"/>',
        f'<option><flag contact="enable"{flags}/></option>', ASSETS.replace("</asset>", assets + "</asset>"),
        "<worldbody>",
        f'<body name="b1"><freejoint/><geom name="g1" {geom1}{extra}/></body>',
        f'<body name="b2"><freejoint/><geom name="g2" {geom2}{extra}/></body>',
        "</worldbody>", "</mujoco>"]) + "\n"


class ConvexScene(Scene):
    def __init__(self, name, geom1, geom2, margins, flags="", assets=""):
        self.name = name
        self.plane = False
        self.xml = mjcf(name, geom1, geom2, margins, flags, assets)
        live = self.xml.replace("MESHDIR", str(MESHDIR))
        self.m = mujoco.MjModel.from_xml_string(live)
        self.d = mujoco.MjData(self.m)
        self.margin = 2 * margins[0]
        self.reach = 2 * (margins[0] + margins[1])
        self.od = mujoco.MjData(self.m)

    def min_dist(self, qpos) -> float:
        """The smallest contact distance of the scene's own model, or (no contact) the geoms'
        distance (mj_geomDistance); a large margin makes MuJoCo's inflated-shape EPA unreliable
        for deep mesh overlaps, so the placing oracle is the scene itself."""
        self.od.qpos[:] = qpos
        mujoco.mj_forward(self.m, self.od)
        if self.od.ncon:
            return min(self.od.contact[i].dist for i in range(self.od.ncon))
        return mujoco.mj_geomDistance(self.m, self.od, 0, 1, 10.0, None)

    def record(self, name, kind, q1, q2):
        out = super().record(name, kind, q1, q2)
        # MuJoCo places a mesh geom at its mesh's inertial frame (lagrange: the file's frame).
        out["geom_mesh"] = [int(t == mujoco.mjtGeom.mjGEOM_MESH) for t in self.m.geom_type]
        return out


def resting(s, rng, count, name="resting", spread=(0.15, 0.15), tilt=0.06):
    return resting_cases(s, rng, count, lambda r: Q_I, lambda r: yaw_tilt(r, tilt), spread, name=name)


def flat_cases(s):
    """Faces parallel (both turned alike about z), an edge and a corner on a face."""
    corner_down = qmul(axis_angle((1, 0, 0), math.atan(math.sqrt(2))), axis_angle((0, 0, 1), math.pi / 4))
    return [
        placed(s, "flat", ORIGIN, Q_I, (0.02, 0.01, 1), -0.01),
        placed(s, "flat_turned_30", ORIGIN, axis_angle((0, 0, 1), math.pi / 6), (0.03, -0.02, 1), -0.005),
        placed(s, "flat_tilted_2deg", ORIGIN, axis_angle((1, 0.3, 0), 0.035), (0, 0, 1), -0.004),
        placed(s, "flat_tilted_8deg", ORIGIN, axis_angle((1, 0.3, 0), 0.14), (0, 0, 1), -0.004),
        placed(s, "edge_on_face", ORIGIN, axis_angle((1, 0, 0), math.pi / 4), (0, 0, 1), -0.01),
        placed(s, "edge_on_face_turned", ORIGIN, qmul(axis_angle((0, 0, 1), 0.4), axis_angle((1, 0, 0), 0.6)),
               (0.1, 0.05, 1), -0.008),
        placed(s, "corner_on_face", ORIGIN, corner_down, (0.05, -0.02, 1), -0.01),
        placed(s, "side_flat", ORIGIN, Q_I, (1, 0.05, 0.02), -0.006),
    ]


def box_mesh():
    out = []
    s = ConvexScene("box_cube", BOX, CUBE_MESH, NO_MARGIN)
    rng = np.random.default_rng([SEED, zlib.crc32(b"box_cube resting")])
    out.append((s, flat_cases(s) + resting(s, rng, 12), 16))
    s = ConvexScene("box_link5", BOX, LINK5, NO_MARGIN)
    rng = np.random.default_rng([SEED, zlib.crc32(b"box_link5 resting")])
    out.append((s, flat_cases(s) + resting(s, rng, 8, tilt=0.5), 16))
    s = ConvexScene("box_cube_margin", BOX, CUBE_MESH, MARGIN)
    rng = np.random.default_rng([SEED, zlib.crc32(b"box_cube_margin resting")])
    out.append((s, resting(s, rng, 6), 8))
    # A prism with a 9-gon face resting on the box (the clipped polygon is that face, more than
    # four points: MuJoCo 4.0's quadrilateral, its first point fixed; src/collision/multiccd.rs).
    rng = np.random.default_rng([SEED, zlib.crc32(b"box_prism9")])
    s = ConvexScene("box_prism9", BOX, 'type="mesh" mesh="prism9"', NO_MARGIN,
                    assets=f'<mesh name="prism9" vertex="{base.prism(9, rng)}"/>')
    out.append((s, [placed(s, f"flat{k}", ORIGIN, yaw_tilt(rng, 0.02), (0.02 * k, -0.01 * k, 1), -0.004)
                    for k in range(6)], 0))
    # A box edge across a cube face narrower than it, tilted along the edge: the edge clipped by
    # both sides of the face, the points above the face dropped; where one end rises above the
    # face MuJoCo 4.0 reports the remaining clipped point twice (the two coincident points the
    # clipping of a two-point polygon makes), as lagrange does.
    s = ConvexScene("box_cube_edge", BOX, CUBE_MESH, NO_MARGIN)
    edge_up = ((0.0, 0.0, 0.0), axis_angle((1, 0, 0), math.pi / 4))
    out.append((s, [placed(s, f"edge_across_tilted{k}", edge_up, axis_angle((0, 1, 0), tilt),
                           (dx, -0.125, 0.18), -0.002)
                    for k, (tilt, dx) in enumerate([(0.0, -0.1), (0.01, -0.2), (-0.02, -0.1), (0.02, 0.05)])], 0))
    s = ConvexScene("box_cube_single", BOX, CUBE_MESH, NO_MARGIN, flags=' multiccd="disable"')
    rng = np.random.default_rng([SEED, zlib.crc32(b"box_cube_single resting")])
    out.append((s, resting(s, rng, 6), 8))
    return out


def mesh_mesh():
    out = []
    s = ConvexScene("cube_cube", CUBE_MESH, CUBE_MESH, NO_MARGIN)
    rng = np.random.default_rng([SEED, zlib.crc32(b"cube_cube resting")])
    out.append((s, flat_cases(s) + resting(s, rng, 12), 16))
    s = ConvexScene("link5_cube", CUBE_MESH, LINK5, NO_MARGIN)
    rng = np.random.default_rng([SEED, zlib.crc32(b"link5_cube resting")])
    out.append((s, resting(s, rng, 8, tilt=0.5), 16))
    s = ConvexScene("link5_link5", LINK5, LINK5, NO_MARGIN)
    out.append((s, [], 16))
    return out


def simple(name, g1, g2, n=16, margin=True, extra=None):
    def make():
        out = []
        s = ConvexScene(name, g1, g2, NO_MARGIN)
        cases = []
        if extra:
            rng = np.random.default_rng([SEED, zlib.crc32((name + " resting").encode())])
            cases = extra(s, rng)
        out.append((s, cases, n))
        if margin:
            s = ConvexScene(name + "_margin", g1, g2, MARGIN)
            out.append((s, [], n // 2))
        return out
    return make


# A cylinder's cap against a cube's edge with no cube face opposite the cap, as met in a drop test
# (five objects falling on a table, step 164): MuJoCo clips the cube's edge by the cap's 16-gon
# (two contacts), choosing by the features of EPA's final face. Bodies (pos, quat): the
# cylinder, then the cube (the drop scene's own centred cube at scale 0.6).
DROP_CYLINDER = 'type="cylinder" size="0.0393 0.0235"'
DROP_CUBE = 'type="mesh" mesh="cube_drop"'
DROP_ASSET = '<mesh name="cube_drop" file="cube_centred.obj" scale="0.6 0.6 0.6"/>'
DROP_CASES = {
    "cap_on_edge": (((-0.09470551076524246, 0.018934415479995772, 0.28036984620245564),
                     (0.4594776752331524, 0.14626725362377335, 0.688224240914168, 0.5420641573631428)),
                    ((-0.05422868656163417, 0.04281432714488902, 0.22840014621754512),
                     (0.383822723536361, -0.021310260232116775, 0.024181686214831404, -0.9228441015457474))),
}


def cylinder_mesh():
    out = simple("cylinder_mesh", CYLINDER_B, CUBE_MESH)()
    s = ConvexScene("cylinder_cube_drop", DROP_CYLINDER, DROP_CUBE, NO_MARGIN, assets=DROP_ASSET)
    out.append((s, [s.record(name, "penetrating", q1, q2) for name, (q1, q2) in DROP_CASES.items()], 0))
    return out


PAIRS = {
    "box_mesh": box_mesh,
    "mesh_mesh": mesh_mesh,
    "capsule_mesh": simple("capsule_mesh", CAPSULE, LINK5,
                           extra=lambda s, r: resting_cases(s, r, 8, lambda q: yaw_tilt(q, 0.05, Q_ZX),
                                                            lambda q: Q_I, (0.1, 0.1))),
    "capsule_cylinder": simple("capsule_cylinder", CAPSULE, CYLINDER),
    "cylinder_box": simple("cylinder_box", CYLINDER, BOX,
                           extra=lambda s, r: resting_cases(s, r, 8, lambda q: Q_I, lambda q: yaw_tilt(q, 0.05),
                                                            (0.1, 0.1))),
    "cylinder_cylinder": simple("cylinder_cylinder", CYLINDER, CYLINDER_B),
    "cylinder_mesh": cylinder_mesh,
    "sphere_mesh": simple("sphere_mesh", SPHERE, LINK5),
    "sphere_ellipsoid": simple("sphere_ellipsoid", SPHERE, ELLIPSOID, n=8),
    "capsule_ellipsoid": simple("capsule_ellipsoid", CAPSULE, ELLIPSOID, n=8),
    "ellipsoid_ellipsoid": simple("ellipsoid_ellipsoid", ELLIPSOID, ELLIPSOID, n=8),
    "ellipsoid_cylinder": simple("ellipsoid_cylinder", ELLIPSOID, CYLINDER, n=8),
    "ellipsoid_box": simple("ellipsoid_box", ELLIPSOID, BOX, n=8),
    "ellipsoid_mesh": simple("ellipsoid_mesh", ELLIPSOID, LINK5, n=8),
}


def golden(pair: str) -> str:
    scenes = []
    for scene, cases, n_random in PAIRS[pair]():
        rng = np.random.default_rng([SEED, zlib.crc32(scene.name.encode())])
        cases = cases + random_cases(scene, rng, n_random)
        scenes.append({"name": scene.name, "mjcf": scene.xml, "margin": scene.margin, "reach": scene.reach,
                       "cases": cases})
    doc = {
        "generated": f"by {SCRIPT} with mujoco {mujoco.__version__}; do not edit (rerun the script)",
        "generator": f"mujoco {mujoco.__version__}",
        "script": SCRIPT,
        "pair": pair,
        "layout": "mjcf: MESHDIR stands for tests/data/meshes; qpos: both free joints (pos, quat wxyz); "
                  "geom_xpos, geom_xmat (row-major): MuJoCo's world poses of every geom (a mesh geom's at its "
                  "mesh's inertial frame, geom_mesh 1); contacts in MuJoCo's order, frame row-major (normal, "
                  "tangent1, tangent2), normal from geom[0] to geom[1]",
        "scenes": scenes,
    }
    text = dump(doc) + "\n"
    assert json.loads(text) == json.loads(json.dumps(doc)), "dump() lost information"
    return text


def main() -> int:
    return base.run_pair_files(__doc__.split("\n\n")[0], PAIRS, golden, OUT_DIR, "convex", 20)

if __name__ == "__main__":
    sys.exit(main())
