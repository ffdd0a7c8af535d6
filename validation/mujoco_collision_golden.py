#!/usr/bin/env python3
"""MuJoCo's contacts for pairs of primitive geoms, for lagrange's collision tests.

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_collision_golden.py            # (re)write tests/data/mujoco/collision/*.json
    python validation/mujoco_collision_golden.py --check    # recompute in memory, exit 1 if a file differs beyond round-off

One file per pair type: the closed forms lagrange follows point for point (sphere-box,
capsule-box, box-box, sphere-cylinder: MuJoCo's mjc_SphereBox, mjc_CapsuleBox, mjc_BoxBox,
mjc_SphereCylinder), plane-mesh with one and with several vertices below the plane (corpus meshes under
tests/data/meshes/mujoco: MuJoCo's f32 vertices in the mesh's inertial frame) and, as regression,
sphere-sphere, sphere-capsule, capsule-capsule and plane against sphere, capsule, box and
cylinder. Each file holds a few scenes (an MJCF text: two free bodies with one geom each, or a
world plane and one free body; margins and gaps nonzero in some) and, per scene, cases: the
bodies' poses (qpos), MuJoCo's world poses of the two geoms and every contact of mj_forward
(geom ids, pos, frame, dist, includemargin) in MuJoCo's order.

The cases cover, per scene:
- random relative poses (seeded), placed by bisection along a random direction so that the
  smallest contact distance is a chosen value: penetrating (-0.03 to -0.002), separated within
  the margin (margin scenes), and separated beyond the margin (no contact expected);
- hand-made poses touching at exactly zero distance (sizes and positions are dyadic fractions and
  rotations exact, so every engine computes 0 exactly; MuJoCo reports contacts at dist <= margin);
- degenerate poses: parallel faces, box resting flat on a box (aligned, turned, and both turned
  alike), edge on face, corner on face, crossed edges, coincident centres, a segment end inside a
  box, a capsule along a box edge or lying on a face.

Deterministic: a fixed seed per scene, floats written with repr, keys sorted. --check compares
numbers relative to the largest magnitude of their quantity (MuJoCo's last bits may differ between
machines; 1e-12 passes) and structure (counts, ids) exactly.
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys
import zlib

import mujoco
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from mujoco_golden import check_status, dump  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parent.parent
OUT_DIR = REPO / "tests" / "data" / "mujoco" / "collision"
SCRIPT = "validation/mujoco_collision_golden.py"
SEED = 20270405
CHECK_REL = 1e-12

# Geoms (MJCF half-sizes); dyadic so that hand-made touching poses are exact in floating point.
SPHERE = 'type="sphere" size="0.125"'
SPHERE_SMALL = 'type="sphere" size="0.0625"'
CAPSULE = 'type="capsule" size="0.0625 0.25"'
CAPSULE_LONG = 'type="capsule" size="0.046875 0.375"'
BOX_A = 'type="box" size="0.25 0.1875 0.125"'
BOX_B = 'type="box" size="0.125 0.125 0.0625"'
CUBE = 'type="box" size="0.125 0.125 0.125"'
CYLINDER = 'type="cylinder" size="0.125 0.25"'
PLANE = 'type="plane" size="2 2 0.1"'

# Margins and gaps per geom (a pair's are the sums): 1/32 m margin, 1/64 m gap.
NO_MARGIN = (0.0, 0.0)
MARGIN = (0.015625, 0.0)
MARGIN_GAP = (0.0078125, 0.00390625)

# Exact rotations (w, x, y, z): every matrix entry MuJoCo computes from them is exact.
Q_I = (1.0, 0.0, 0.0, 0.0)
Q_X180 = (0.0, 1.0, 0.0, 0.0)
Q_Z180 = (0.0, 0.0, 0.0, 1.0)
Q_ZX = (0.5, 0.5, 0.5, 0.5)  # 120 degrees about (1,1,1): z -> x, x -> y, y -> z
Q_ZY = (0.5, -0.5, -0.5, -0.5)  # its inverse: z -> y, x -> z, y -> x


def axis_angle(axis, angle) -> tuple:
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    s = math.sin(angle / 2)
    return (math.cos(angle / 2), *(float(x) for x in a * s))


def qmul(p, q) -> tuple:
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def qmat(q) -> np.ndarray:
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, np.asarray(q, float))
    return m.reshape(3, 3)


def random_quat(rng) -> tuple:
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    return tuple(float(x) for x in q)


def unit(rng) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


# Mesh scenes name their files relative to this directory, written as MESHDIR_TOKEN in the MJCF
# text (the test substitutes its own checkout's path).
MESH_DIR = REPO / "tests" / "data" / "meshes" / "mujoco"
MESHDIR_TOKEN = "@MESHDIR@"


def mjcf(name: str, geom1: str | None, geom2: str, margins: tuple, offset: str = "", assets: str = "") -> str:
    """Two free bodies with one geom each (geom1 None: a world plane and one free body); `assets`
    the <asset> children (meshes, files under MESHDIR_TOKEN)."""
    margin, gap = margins
    extra = f' margin="{margin!r}" gap="{gap!r}"' if margin or gap else ""
    compiler = f'<compiler angle="radian" meshdir="{MESHDIR_TOKEN}"/>' if assets else '<compiler angle="radian"/>'
    parts = [f'<mujoco model="{name}">', compiler, '<option><flag contact="enable"/></option>']
    if assets:
        parts.append(f"<asset>{assets}</asset>")
    parts.append("<worldbody>")
    if geom1 is None:
        parts.append(f'<geom name="plane" {PLANE}{extra}/>')
    else:
        parts.append(f'<body name="b1"><freejoint/><geom name="g1" {geom1}{extra}{offset}/></body>')
    parts.append(f'<body name="b2"><freejoint/><geom name="g2" {geom2}{extra}{offset}/></body>')
    parts += ["</worldbody>", "</mujoco>"]
    return "\n".join(parts) + "\n"


class Scene:
    def __init__(self, name: str, geom1: str | None, geom2: str, margins: tuple, offset: str = "", assets: str = ""):
        self.name = name
        self.plane = geom1 is None
        self.xml = mjcf(name, geom1, geom2, margins, offset, assets)
        text = self.xml.replace(MESHDIR_TOKEN, str(MESH_DIR))
        self.m = mujoco.MjModel.from_xml_string(text)
        self.d = mujoco.MjData(self.m)
        self.margin = 2 * margins[0]
        self.reach = 2 * (margins[0] + margins[1])
        # The same scene with a large margin: its smallest contact distance places random poses.
        self.oracle = mujoco.MjModel.from_xml_string(text)
        self.oracle.geom_margin[:] = 2.0
        self.od = mujoco.MjData(self.oracle)

    def qpos(self, q1, q2) -> list:
        """q1, q2: (pos, quat) of body 1 and body 2 (q1 ignored for plane scenes)."""
        out = [] if self.plane else [*q1[0], *q1[1]]
        return [float(x) for x in out + [*q2[0], *q2[1]]]

    def min_dist(self, qpos) -> float:
        self.od.qpos[:] = qpos
        mujoco.mj_forward(self.oracle, self.od)
        return min((self.od.contact[i].dist for i in range(self.od.ncon)), default=math.inf)

    def place(self, q1, quat2, direction, target, start=None) -> tuple:
        """Body 2's pose at `start` (default: body 1's position) + s * direction with the smallest
        contact distance `target` (bisection on s)."""
        p1 = np.asarray(q1[0] if start is None else start, float)
        lo, hi = 0.0, 3.0
        at = lambda s: self.qpos(q1, (p1 + s * direction, quat2))  # noqa: E731
        assert self.min_dist(at(hi)) > target, "upper bracket too close"
        if self.min_dist(at(lo)) > target:
            return None  # cannot penetrate that deep along this direction
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if self.min_dist(at(mid)) > target:
                hi = mid
            else:
                lo = mid
        return (tuple(float(x) for x in p1 + lo * direction), quat2)

    def record(self, name: str, kind: str, q1, q2) -> dict:
        qpos = self.qpos(q1, q2)
        m, d = self.m, self.d
        mujoco.mj_resetData(m, d)
        d.qpos[:] = qpos
        mujoco.mj_forward(m, d)
        contacts = []
        for i in range(d.ncon):
            c = d.contact[i]
            contacts.append({"geom": [int(c.geom[0]), int(c.geom[1])], "pos": [float(x) for x in c.pos],
                             "frame": [float(x) for x in c.frame], "dist": float(c.dist),
                             "includemargin": float(c.includemargin)})
        if kind == "touching":
            assert contacts and min(c["dist"] for c in contacts) == 0.0, f"{self.name}/{name}: not touching exactly"
        if kind == "outside":
            assert not contacts, f"{self.name}/{name}: contacts beyond the margin"
        if kind in ("penetrating", "within_margin", "touching"):
            assert contacts, f"{self.name}/{name}: no contact"
        return {"name": name, "kind": kind, "qpos": qpos,
                "geom_xpos": [[float(x) for x in p] for p in d.geom_xpos],
                "geom_xmat": [[float(x) for x in r] for r in d.geom_xmat],
                "contacts": contacts}


def random_cases(scene: Scene, rng, count: int) -> list:
    """Random relative poses at chosen smallest contact distances."""
    cases = []
    kinds = ["penetrating", "outside"] + (["within_margin"] if scene.reach > 0 else [])
    k = 0
    while len(cases) < count:
        kind = kinds[k % len(kinds)]
        k += 1
        q1 = (tuple(float(x) for x in rng.uniform(-0.5, 0.5, 3)), random_quat(rng))
        quat2 = random_quat(rng)
        if scene.plane:
            q1 = ((0.0, 0.0, 0.0), Q_I)
            direction = np.array([0.0, 0.0, 1.0])
        else:
            direction = unit(rng)
        target = {"penetrating": -rng.uniform(0.002, 0.03),
                  "within_margin": rng.uniform(0.1, 0.9) * scene.reach,
                  "outside": scene.reach + rng.uniform(0.002, 0.01)}[kind]
        q2 = scene.place(q1, quat2, direction, target)
        if q2 is None:
            continue
        cases.append(scene.record(f"random{len(cases)}", kind, q1, q2))
    return cases


def resting_cases(scene: Scene, rng, count: int, body1_quat, body2_quat, spread, name="resting") -> list:
    """Random poses of body 2 resting on (or hanging under) body 1 with small tilts, near the
    edges and corners of the contact patch: body 1 at an offset (x, y, 0) from a vertical line
    along which body 2 is placed at a random depth. body1_quat(rng), body2_quat(rng) give the
    orientations; spread the (x, y) half-ranges."""
    cases = []
    while len(cases) < count:
        q1 = ((0.0, 0.0, 0.0), body1_quat(rng))
        start = (float(rng.uniform(-spread[0], spread[0])), float(rng.uniform(-spread[1], spread[1])), 0.0)
        up = 1.0 if len(cases) % 4 else -1.0  # one in four from below
        q2 = scene.place(q1, body2_quat(rng), np.array([0.0, 0.0, up]), -rng.uniform(0.0005, 0.02), start=start)
        if q2 is None:
            continue
        cases.append(scene.record(f"{name}{len(cases)}", "penetrating", q1, q2))
    return cases


def z_to(direction) -> tuple:
    """The rotation taking z to `direction` (about z x direction)."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    return axis_angle(np.cross([0.0, 0.0, 1.0], d), math.acos(d[2]))


def over_corner(scene: Scene, name: str, yaw: float, drop: float, along: float, depth: float, kind="degenerate"):
    """A capsule nearly level, its segment passing over the box's (+x, +y, +z) corner at yaw `yaw`,
    going down by `drop` per unit length, the corner under the segment's point `along` (from the
    centre); the box placed below at contact distance `depth`."""
    d = np.array([math.cos(yaw), math.sin(yaw), -drop])
    d /= np.linalg.norm(d)
    centre = np.array([0.25, 0.1875, 0.0]) - along * d * np.array([1.0, 1.0, 0.0])
    q1 = ((float(centre[0]), float(centre[1]), 0.0), z_to(d))
    q2 = scene.place(q1, Q_I, np.array([0.0, 0.0, -1.0]), depth, start=(0.0, 0.0, 0.0))
    assert q2 is not None, f"{scene.name}/{name}: cannot place"
    return scene.record(name, kind, q1, q2)


def yaw_tilt(rng, tilt, base=(1.0, 0.0, 0.0, 0.0)) -> tuple:
    """A random turn about z, then a random tilt of at most `tilt` rad, applied to `base`."""
    q = qmul(axis_angle((0, 0, 1), rng.uniform(0, 2 * math.pi)),
             qmul(axis_angle((*unit(rng)[:2], 0.0), rng.uniform(0, tilt)), base))
    return q


ORIGIN = ((0.0, 0.0, 0.0), Q_I)


def at(*pos, q=Q_I) -> tuple:
    return (tuple(float(x) for x in pos), q)


def rotated(q1, local_pos, q2_rel) -> tuple:
    """Body 2 at body 1's frame point `local_pos`, orientation q1 * q2_rel."""
    p = np.asarray(q1[0]) + qmat(q1[1]) @ np.asarray(local_pos, float)
    return (tuple(float(x) for x in p), qmul(q1[1], q2_rel))


def placed(scene: Scene, name: str, q1, quat2, direction, target, kind="degenerate") -> dict:
    q2 = scene.place(q1, quat2, np.asarray(direction, float) / np.linalg.norm(direction), target)
    assert q2 is not None, f"{scene.name}/{name}: cannot place"
    return scene.record(name, kind, q1, q2)


# ------------------------------------------------------------------------------------------------
# Pair types: scenes and their hand-made cases
# ------------------------------------------------------------------------------------------------

def sphere_box() -> list:
    out = []
    s = Scene("sphere_box", SPHERE, BOX_A, NO_MARGIN)
    # Body 1: the sphere; body 2: the box at the origin.
    cases = [
        s.record("touch_face_x", "touching", at(0.375, 0.0, 0.0), ORIGIN),
        s.record("touch_face_z_box_turned", "touching", at(0.0, 0.0, -0.25), at(0, 0, 0, q=Q_Z180)),
        s.record("face", "penetrating", at(0.3125, 0.0625, 0.03125), ORIGIN),
        s.record("edge", "penetrating", at(0.3125, 0.25, 0.0), ORIGIN),
        s.record("corner", "penetrating", at(0.3125, 0.25, 0.1875), ORIGIN),
        s.record("centre_inside_near_face", "degenerate", at(0.0, 0.0625, 0.0625), ORIGIN),
        s.record("centre_on_face", "degenerate", at(0.25, 0.0, 0.0), ORIGIN),
        s.record("coincident_centres", "degenerate", ORIGIN, ORIGIN),
        s.record("coincident_centres_turned", "degenerate", at(0.1, 0.2, 0.3, q=axis_angle((1, 2, 3), 0.7)),
                 at(0.1, 0.2, 0.3, q=axis_angle((-1, 0.5, 2), 1.1))),
    ]
    out.append((s, cases, 12))
    s = Scene("sphere_box_margin", SPHERE, BOX_A, MARGIN)
    out.append((s, [s.record("touch_face_y", "touching", at(0.0, 0.3125, 0.0), ORIGIN),
                    s.record("face_within_margin", "within_margin", at(0.0, 0.0, 0.265625), ORIGIN)], 12))
    # The box on body 1: MuJoCo's geom 1 is still the sphere (lower type), geom id 1.
    s = Scene("box_sphere_order", BOX_A, SPHERE, MARGIN_GAP)
    out.append((s, [s.record("touch_face_x", "touching", ORIGIN, at(-0.375, 0.0, 0.0))], 8))
    s = Scene("sphere_cube", SPHERE, CUBE, NO_MARGIN)
    out.append((s, [s.record("coincident_centres_tie", "degenerate", ORIGIN, ORIGIN),
                    s.record("inside_on_diagonal_tie", "degenerate", at(0.0625, 0.0625, 0.0625), ORIGIN)], 4))
    return out


def capsule_box() -> list:
    out = []
    s = Scene("capsule_box", CAPSULE, BOX_A, NO_MARGIN)
    slant = axis_angle((0.3, 1.0, 0.0), 1.2)
    cases = [
        s.record("lying_on_face_touch", "touching", at(0.0, 0.0, 0.1875, q=Q_ZX), ORIGIN),
        s.record("lying_on_face", "penetrating", at(0.0, 0.03125, 0.171875, q=Q_ZX), ORIGIN),
        s.record("lying_on_face_overhanging", "penetrating", at(0.1875, 0.0, 0.171875, q=Q_ZX), ORIGIN),
        s.record("lying_across_face", "penetrating", at(0.0625, 0.0, 0.171875, q=Q_ZY), ORIGIN),
        s.record("segment_on_face", "degenerate", at(0.0, 0.0, 0.125, q=Q_ZY), ORIGIN),
        s.record("pointing_at_face", "penetrating", at(0.0625, 0.03125, 0.421875), ORIGIN),
        s.record("pointing_at_face_touch", "touching", at(0.0625, 0.03125, 0.4375), ORIGIN),
        s.record("end_inside", "degenerate", at(0.0625, 0.0, 0.25), ORIGIN),
        s.record("along_edge", "degenerate", at(0.28125, 0.0, 0.15625, q=Q_ZY), ORIGIN),
        s.record("along_edge_x", "degenerate", at(0.0, 0.21875, 0.15625, q=Q_ZX), ORIGIN),
        s.record("coincident_centres", "degenerate", ORIGIN, ORIGIN),
        s.record("coincident_centres_along_x", "degenerate", at(0, 0, 0, q=Q_ZX), ORIGIN),
        s.record("coincident_centres_turned", "degenerate", at(0, 0, 0, q=axis_angle((1, 1, 0.2), 0.9)), ORIGIN),
        # placed() moves body 2 (the box) from the capsule's centre along -(the capsule's side).
        placed(s, "crossing_edge", at(0.25, 0.0, 0.125, q=axis_angle((0.0, 1.0, 0.2), 0.8)), Q_I, (-1, -0.1, -1), -0.01),
        placed(s, "crossing_edge_square", at(0.25, 0.0, 0.125, q=axis_angle((0.0, 1.0, 0.0), 0.8)), Q_I, (-1, 0, -1), -0.005),
        placed(s, "near_corner", at(0.25, 0.1875, 0.125, q=slant), Q_I, (-1, -1, -1), -0.01),
        placed(s, "near_corner_tilted", at(0.25, 0.1875, 0.125, q=axis_angle((1, -1, 0.3), 1.0)), Q_I, (-1, -1, -1), -0.005),
        placed(s, "over_face_tilted", at(0.0, 0.0, 0.125, q=axis_angle((0.2, 1.0, 0.0), 1.4)), Q_I, (0, 0, -1), -0.01),
    ]
    rng = np.random.default_rng([SEED, zlib.crc32(b"capsule_box resting")])
    cases += resting_cases(s, rng, 24, lambda r: yaw_tilt(r, 0.15, Q_ZX),
                           lambda r: axis_angle((0, 0, 1), r.uniform(0, 2 * math.pi)), (0.4, 0.35))
    # Over the corner, nearly level: the closest box point is the corner, the second point lies
    # back over the top face (or along an edge when the segment runs nearly along one).
    for k, (yaw, drop, along, depth) in enumerate([(0.8, 0.02, 0.1, -0.01), (0.6, 0.05, -0.05, -0.005),
                                                   (1.2, 0.01, 0.15, -0.015), (0.3, 0.03, 0.0, -0.01),
                                                   (0.1, 0.02, 0.05, -0.01), (1.5, 0.02, 0.1, -0.01)]):
        cases.append(over_corner(s, f"over_corner{k}", yaw, drop, along, depth))
    rng = np.random.default_rng([SEED, zlib.crc32(b"capsule_box corners")])
    cases += resting_cases(s, rng, 24, lambda r: yaw_tilt(r, 0.8, Q_ZX),
                           lambda r: Q_I, (0.45, 0.4), name="by_corner")
    out.append((s, cases, 16))
    s = Scene("capsule_box_margin", CAPSULE, BOX_A, MARGIN)
    cases = [s.record("lying_on_face_within_margin", "within_margin", at(0.0, 0.0, 0.203125, q=Q_ZX), ORIGIN),
             s.record("lying_on_face_touch", "touching", at(0.0, 0.0, 0.1875, q=Q_ZX), ORIGIN)]
    for k, (yaw, drop, along, depth) in enumerate([(0.8, 0.02, 0.1, 0.01), (0.5, 0.04, 0.0, -0.005)]):
        cases.append(over_corner(s, f"over_corner{k}", yaw, drop, along, depth,
                                 kind="within_margin" if depth > 0 else "degenerate"))
    rng = np.random.default_rng([SEED, zlib.crc32(b"capsule_box_margin corners")])
    cases += resting_cases(s, rng, 24, lambda r: yaw_tilt(r, 0.3, Q_ZX), lambda r: Q_I, (0.45, 0.4), name="by_corner")
    out.append((s, cases, 12))
    s = Scene("box_capsule_order", BOX_A, CAPSULE_LONG, MARGIN_GAP)
    out.append((s, [s.record("lying_on_face", "penetrating", ORIGIN, at(0.0, 0.0, 0.1640625, q=Q_ZX)),
                    s.record("lying_on_face_overhanging", "penetrating", ORIGIN, at(0.125, 0.0625, 0.1640625, q=Q_ZX))], 8))
    return out


def box_box() -> list:
    out = []
    s = Scene("box_box", BOX_A, BOX_B, NO_MARGIN)
    turned = axis_angle((0.3, -0.5, 0.8), 2.1)
    corner_down = qmul(axis_angle((1, 0, 0), math.atan(math.sqrt(2))), axis_angle((0, 0, 1), math.pi / 4))
    cases = [
        s.record("flat_touch", "touching", ORIGIN, at(0.0, 0.0, 0.1875)),
        s.record("flat_touch_turned_180", "touching", ORIGIN, at(0.0625, 0.0, 0.1875, q=Q_Z180)),
        s.record("flat_touch_side_x", "touching", ORIGIN, at(0.375, 0.0625, 0.0, q=Q_X180)),
        s.record("flat", "penetrating", ORIGIN, at(0.03125, -0.0625, 0.171875)),
        s.record("flat_overhanging_corner", "penetrating", ORIGIN, at(0.1875, 0.125, 0.171875)),
        s.record("flat_turned_45", "penetrating", ORIGIN, at(0.0, 0.0, 0.18, q=axis_angle((0, 0, 1), math.pi / 4))),
        s.record("flat_turned_30_overhanging", "penetrating", ORIGIN,
                 at(0.2, 0.1, 0.18, q=axis_angle((0, 0, 1), math.pi / 6))),
        s.record("flat_both_turned_alike", "degenerate", at(0.1, -0.2, 0.3, q=turned),
                 rotated(at(0.1, -0.2, 0.3, q=turned), (0.05, 0.03, 0.1825), Q_I)),
        s.record("flat_both_turned_alike_overhanging", "degenerate", at(0.1, -0.2, 0.3, q=turned),
                 rotated(at(0.1, -0.2, 0.3, q=turned), (0.2, 0.15, 0.18), axis_angle((0, 0, 1), 0.3))),
        placed(s, "edge_on_face", ORIGIN, axis_angle((1, 0, 0), math.pi / 4), (0, 0, 1), -0.01),
        placed(s, "edge_on_face_turned", ORIGIN, qmul(axis_angle((0, 0, 1), 0.4), axis_angle((1, 0, 0), 0.6)),
               (0.1, 0.05, 1), -0.008),
        placed(s, "corner_on_face", ORIGIN, corner_down, (0.05, -0.02, 1), -0.01),
        placed(s, "tilted_slightly", ORIGIN, axis_angle((1, 0.2, 0), 0.01), (0, 0, 1), -0.01),
        placed(s, "tilted_slightly_small_depth", ORIGIN, axis_angle((0.3, 1, 0), 0.002), (0.01, 0, 1), -0.0005),
        placed(s, "edge_edge_crossed", at(0, 0, 0, q=axis_angle((1, 0, 0), math.pi / 4)),
               qmul(axis_angle((0, 0, 1), math.pi / 2), axis_angle((1, 0, 0), math.pi / 4)), (0, 0, 1), -0.01),
        placed(s, "edge_edge_skew", at(0, 0, 0, q=axis_angle((1, 0.1, 0), 0.7)),
               qmul(axis_angle((0, 0.2, 1), 1.2), axis_angle((1, 0, 0), 0.9)), (0.1, 0.2, 1), -0.006),
        s.record("coincident_centres", "degenerate", ORIGIN, ORIGIN),
        s.record("coincident_centres_turned", "degenerate", ORIGIN, at(0, 0, 0, q=turned)),
        s.record("inside", "degenerate", ORIGIN, at(0.0625, 0.03125, 0.0)),
    ]
    # An incident edge through a corner of the reference face: clipping makes near-duplicates.
    for k, angle in enumerate(np.linspace(0.1, 3.0, 40)):
        corner = np.array([0.25, 0.1875, 0.0])
        turn = axis_angle((0, 0, 1), angle)
        start = corner - qmat(turn) @ np.array([0.125, 0.0, 0.0])
        q2 = s.place(ORIGIN, turn, np.array([0.0, 0.0, 1.0]), -0.01, start=start)
        cases.append(s.record(f"edge_through_corner{k}", "degenerate", ORIGIN, q2))
    rng = np.random.default_rng([SEED, zlib.crc32(b"box_box resting")])
    cases += resting_cases(s, rng, 24, lambda r: Q_I, lambda r: yaw_tilt(r, 0.06), (0.4, 0.35))
    out.append((s, cases, 16))
    s = Scene("box_box_same", BOX_A, BOX_A, NO_MARGIN)
    out.append((s, [
        s.record("flat_touch", "touching", ORIGIN, at(0.0, 0.0, 0.25)),
        s.record("flat_touch_shifted", "touching", ORIGIN, at(0.125, -0.0625, 0.25)),
        s.record("flat", "penetrating", ORIGIN, at(0.0, 0.0, 0.234375)),
        s.record("flat_turned_90", "penetrating", ORIGIN, at(0.0, 0.0, 0.234375, q=axis_angle((0, 0, 1), math.pi / 2))),
        s.record("coincident", "degenerate", ORIGIN, ORIGIN),
        s.record("coincident_turned_180", "degenerate", ORIGIN, at(0, 0, 0, q=Q_Z180)),
        s.record("side_by_side", "penetrating", ORIGIN, at(0.46875, 0.0625, 0.03125)),
    ], 8))
    s = Scene("box_box_margin", BOX_A, CUBE, MARGIN)
    out.append((s, [
        s.record("flat_touch", "touching", ORIGIN, at(0.0, 0.0625, 0.25)),
        s.record("flat_within_margin", "within_margin", ORIGIN, at(0.0, 0.0625, 0.265625)),
        s.record("flat_turned_within_margin", "within_margin", ORIGIN,
                 at(0.1, 0.0, 0.26, q=axis_angle((0, 0, 1), 0.5))),
        placed(s, "edge_edge_within_margin", at(0, 0, 0, q=axis_angle((1, 0, 0), math.pi / 4)),
               qmul(axis_angle((0, 0, 1), math.pi / 2), axis_angle((1, 0, 0), math.pi / 4)), (0, 0, 1), 0.02,
               kind="within_margin"),
    ], 16))
    # Geoms away from their body origins, turned: exercises the geom frames.
    s = Scene("box_box_offset", BOX_B, BOX_A, MARGIN_GAP, offset=' pos="0.1 -0.05 0.02" euler="0.3 -0.2 0.5"')
    out.append((s, [], 10))
    return out


def sphere_sphere() -> list:
    s = Scene("sphere_sphere", SPHERE, SPHERE_SMALL, MARGIN)
    return [(s, [s.record("touch", "touching", ORIGIN, at(0.1875, 0.0, 0.0)),
                 s.record("coincident_centres", "degenerate", ORIGIN, at(0, 0, 0, q=axis_angle((1, 3, 0), 0.6)))], 8)]


def sphere_capsule() -> list:
    s = Scene("sphere_capsule", SPHERE, CAPSULE, MARGIN)
    return [(s, [s.record("touch_side", "touching", ORIGIN, at(0.1875, 0.0, 0.125))], 8)]


def capsule_capsule() -> list:
    s = Scene("capsule_capsule", CAPSULE, CAPSULE_LONG, MARGIN)
    return [(s, [s.record("crossed", "penetrating", at(0, 0, 0, q=Q_ZX), at(0.0625, 0.0, 0.1, q=Q_ZY)),
                 s.record("parallel_overlapping", "degenerate", at(0, 0, 0, q=Q_ZX), at(0.1, 0.0, 0.1, q=Q_ZX)),
                 s.record("coincident_centres", "degenerate", ORIGIN, at(0, 0, 0, q=Q_ZX))], 10)]


def sphere_cylinder() -> list:
    """MuJoCo's mjc_SphereCylinder: side, cap (touching exactly at 0 included), rim, the centre
    inside nearer the cap or the side (a tie goes to the side), the centre on the axis (coincident
    centres of its sphere–sphere: the normal is z1 x z2, or x)."""
    out = []
    s = Scene("sphere_cylinder", SPHERE, CYLINDER, NO_MARGIN)
    tilted = axis_angle((1, 0, 0), 0.5)
    cases = [
        s.record("touch_cap", "touching", at(0.0625, 0.0, 0.375), ORIGIN),
        s.record("touch_cap_bottom", "touching", at(-0.0625, 0.03125, -0.375), ORIGIN),
        s.record("touch_side", "touching", at(0.25, 0.0, 0.0625), ORIGIN),
        s.record("cap", "penetrating", at(0.03125, 0.03125, 0.34375), ORIGIN),
        s.record("side", "penetrating", at(0.21875, 0.0, 0.1), ORIGIN),
        s.record("rim", "penetrating", at(0.1875, 0.0, 0.3125), ORIGIN),
        s.record("rim_bottom", "penetrating", at(0.0, -0.1875, -0.3125), ORIGIN),
        s.record("inside_near_cap", "degenerate", at(0.0, 0.03125, 0.1875), ORIGIN),
        s.record("inside_near_side", "degenerate", at(0.09375, 0.0, 0.0), ORIGIN),
        s.record("inside_tie", "degenerate", at(0.0625, 0.0, 0.1875), ORIGIN),
        s.record("centre_on_axis", "degenerate", ORIGIN, ORIGIN),
        s.record("centre_on_axis_turned", "degenerate", at(0.0, 0.0, 0.0625, q=tilted), ORIGIN),
        s.record("turned", "penetrating", at(0.1, 0.15, 0.2), at(0.0, 0.0, 0.0, q=axis_angle((1, 2, 0.5), 0.8))),
    ]
    out.append((s, cases, 16))
    s = Scene("sphere_cylinder_margin", SPHERE, CYLINDER, MARGIN)
    out.append((s, [s.record("touch_cap", "touching", at(0.0625, 0.0, 0.375), ORIGIN),
                    s.record("cap_within_margin", "within_margin", at(0.0, 0.0, 0.390625), ORIGIN),
                    s.record("side_within_margin", "within_margin", at(0.265625, 0.0, 0.0), ORIGIN)], 12))
    # The cylinder on body 1: MuJoCo's geom 1 is still the sphere (lower type).
    s = Scene("cylinder_sphere_order", CYLINDER, SPHERE, MARGIN_GAP)
    out.append((s, [s.record("cap", "penetrating", ORIGIN, at(0.03125, 0.0, -0.34375))], 6))
    return out


def plane_sphere() -> list:
    s = Scene("plane_sphere", None, SPHERE, MARGIN)
    return [(s, [s.record("touch", "touching", None, at(0.25, -0.5, 0.125))], 6)]


def plane_capsule() -> list:
    s = Scene("plane_capsule", None, CAPSULE, MARGIN)
    return [(s, [s.record("lying_touch", "touching", None, at(0.25, -0.5, 0.0625, q=Q_ZX)),
                 s.record("lying", "penetrating", None, at(0.25, -0.5, 0.046875, q=Q_ZY))], 8)]


def plane_box() -> list:
    s = Scene("plane_box", None, BOX_A, MARGIN)
    return [(s, [s.record("flat_touch", "touching", None, at(0.25, -0.5, 0.125)),
                 s.record("flat", "penetrating", None, at(0.0, 0.0, 0.109375, q=Q_Z180)),
                 s.record("on_edge", "penetrating", None,
                          at(0.0, 0.0, 0.1875 * math.sqrt(0.5) + 0.125 * math.sqrt(0.5) - 0.01,
                             q=axis_angle((1, 0, 0), math.pi / 4)))], 8)]


def plane_cylinder() -> list:
    s = Scene("plane_cylinder", None, CYLINDER, MARGIN)
    return [(s, [s.record("on_cap", "penetrating", None, at(0.0, 0.0, 0.234375)),
                 s.record("on_side", "penetrating", None, at(0.0, 0.0, 0.109375, q=Q_ZX))], 8)]


# Corpus meshes (tests/data/meshes/mujoco, with their licences): a Franka link (276 vertices, a hull
# of 46: MuJoCo's hill-climbing support), a Barkour leg part and a small bone (5.7 mm).
MESHES = [("link0", "franka_emika_panda/link0_11.obj"), ("abduction", "google_barkour_vb/abduction.stl"),
          ("femoris", "dm_control/BONEFemoris_fabellae_L_1.stl")]


def mesh_scene(kind: str, name: str, file: str, margins: tuple) -> Scene:
    assets = f'<mesh name="{name}" file="{file}"/>'
    geom = f'type="mesh" mesh="{name}"'
    return Scene(f"{kind}_{name}", None, geom, margins, assets=assets)


def world_vertices(s: Scene, mesh: int) -> np.ndarray:
    """World positions of mesh `mesh`'s vertices at the scene's current state (after record)."""
    g = int(np.flatnonzero(s.m.geom_dataid == mesh)[0])
    adr, num = s.m.mesh_vertadr[mesh], s.m.mesh_vertnum[mesh]
    v = s.m.mesh_vert[adr:adr + num].astype(float)
    return v @ s.d.geom_xmat[g].reshape(3, 3).T + s.d.geom_xpos[g]


def plane_mesh() -> list:
    """Meshes at random orientations just touching the plane: one vertex alone below it (MuJoCo's
    mesh vertices are f32 in its inertial frame: the contact is that vertex), and lifted beyond
    it; then deeper at random orientations, where MuJoCo 4.0 adds other vertices of the hull face
    polygon facing the plane; then prisms with a many-sided face resting on it."""
    out = []
    for name, file in MESHES:
        s = mesh_scene("plane_mesh", name, file, NO_MARGIN)
        rng = np.random.default_rng([SEED, zlib.crc32(s.name.encode())])
        cases = []
        while len(cases) < 16:
            kind = "outside" if len(cases) % 4 == 3 else "penetrating"
            target = rng.uniform(1e-6, 1e-4) * (1 if kind == "outside" else -1)
            q2 = s.place(None, random_quat(rng), np.array([0.0, 0.0, 1.0]), target, start=(0.0, 0.0, -1.0))
            if q2 is None:
                continue
            case = s.record(f"vertex{len(cases)}", kind, None, q2)
            below = {tuple(p) for p in world_vertices(s, 0) if p[2] <= 0.0}
            if len(case["contacts"]) <= 1 and len(below) <= 1:
                cases.append(case)
        # Several vertices below the plane (MuJoCo 4.0: the deepest vertex and the vertices of its
        # hull face polygon facing the plane, at most 4 contacts; src/collision/plane_mesh.rs).
        frng = np.random.default_rng([SEED, zlib.crc32((s.name + "/face").encode())])
        while len(cases) < 28:
            target = -frng.uniform(2e-4, 3e-3)
            q2 = s.place(None, random_quat(frng), np.array([0.0, 0.0, 1.0]), target, start=(0.0, 0.0, -1.0))
            if q2 is None:
                continue
            cases.append(s.record(f"face{len(cases)}", "penetrating", None, q2))
        out.append((s, cases, 0))
    out += prism_faces()
    return out


def prism(n: int, rng) -> str:
    """A prism 0.1 m in radius and height whose bottom face is a convex n-gon (vertices at seeded
    random angles on a circle) and whose top is a hexagon, as an inline MJCF mesh."""
    angles = np.sort(rng.uniform(0.0, 2 * math.pi, n))
    pts = [(0.1 * math.cos(a), 0.1 * math.sin(a), -0.05) for a in angles]
    pts += [(0.1 * math.cos(a), 0.1 * math.sin(a), 0.05) for a in np.arange(6) * math.pi / 3]
    return " ".join(repr(round(float(x), 9)) for p in pts for x in p)


def prism_faces() -> list:
    """Prisms resting tilted on the plane with their n-gon bottom face below it (n = 6, 9, 10,
    11): MuJoCo 4.0 keeps four vertices of that face polygon, the deepest first and three chosen
    by its quadrilateral search from it (src/collision/plane_mesh.rs). A 7-gon follows the same rule
    but its f32 vertices lie 3e-9 m from the ones lagrange rounds (the mesh rounding of
    src/io/geom_hull.rs), so it is not among them."""
    out = []
    for n in (6, 9, 10, 11):
        rng = np.random.default_rng([SEED, zlib.crc32(f"prism{n}".encode())])
        assets = f'<mesh name="prism{n}" vertex="{prism(n, rng)}"/>'
        s = Scene(f"plane_mesh_prism{n}", None, f'type="mesh" mesh="prism{n}"', NO_MARGIN, assets=assets)
        cases = []
        while len(cases) < 8:
            axis = (math.cos(rng.uniform(0, 2 * math.pi)), math.sin(rng.uniform(0, 2 * math.pi)), 0.0)
            q = axis_angle(axis, rng.uniform(0.002, 0.03))
            q2 = s.place(None, q, np.array([0.0, 0.0, 1.0]), -0.004, start=(0.0, 0.0, -1.0))
            if q2 is not None:
                cases.append(s.record(f"tilted{len(cases)}", "penetrating", None, q2))
        out.append((s, cases, 0))
    return out


PAIRS = {
    "sphere_box": sphere_box,
    "capsule_box": capsule_box,
    "box_box": box_box,
    "sphere_sphere": sphere_sphere,
    "sphere_capsule": sphere_capsule,
    "capsule_capsule": capsule_capsule,
    "plane_sphere": plane_sphere,
    "plane_capsule": plane_capsule,
    "plane_box": plane_box,
    "plane_cylinder": plane_cylinder,
    "plane_mesh": plane_mesh,
    "sphere_cylinder": sphere_cylinder,
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
        "layout": "qpos: both free joints (pos, quat wxyz), or one above a world plane; geom_xpos, geom_xmat "
                  "(row-major): MuJoCo's world poses of every geom; contacts in MuJoCo's order, frame row-major "
                  "(normal, tangent1, tangent2), normal from geom[0] to geom[1]",
        "scenes": scenes,
    }
    text = dump(doc) + "\n"
    assert json.loads(text) == json.loads(json.dumps(doc)), "dump() lost information"
    return text


def run_pair_files(description: str, pairs, golden, out_dir: pathlib.Path, label: str, width: int) -> int:
    """The command line of a per-pair-type reference-data script (this one and
    mujoco_convex_golden.py): writes `out_dir/PAIR.json` from `golden(pair)` for each pair type of
    `pairs`, or with --check recomputes them in memory and exits 1 if a file differs beyond
    CHECK_REL or a file no pair type produces is there; --only limits it to some pair types."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--check", action="store_true", help="recompute in memory; exit 1 if a file differs")
    ap.add_argument("--only", action="append", default=[], help="only this pair type (repeatable)")
    args = ap.parse_args()
    unknown = set(args.only) - set(pairs)
    if unknown:
        print("unknown pair type(s): %s" % ", ".join(sorted(unknown)), file=sys.stderr)
        return 2
    out_dir.mkdir(parents=True, exist_ok=True)
    stale = []
    for pair in pairs:
        if args.only and pair not in args.only:
            continue
        text = golden(pair)
        out = out_dir / (pair + ".json")
        old = out.read_text() if out.exists() else None
        doc = json.loads(text)
        n_cases = sum(len(s["cases"]) for s in doc["scenes"])
        n_contacts = sum(len(c["contacts"]) for s in doc["scenes"] for c in s["cases"])
        if args.check:
            status = check_status(old, text, doc, CHECK_REL)
            if not status.startswith("ok"):
                stale.append(out.relative_to(REPO).as_posix())
        else:
            status = "unchanged" if old == text else "written"
            if old != text:
                out.write_text(text)
        print("%-*s %3d cases %4d contacts  %-9s %s" % (width, pair, n_cases, n_contacts, status,
                                                        out.relative_to(REPO).as_posix()))
    if not args.only:
        extra = sorted(p.name for p in out_dir.glob("*.json") if p.stem not in pairs)
        for e in extra:
            print("%-*s EXTRA: no pair type produces it" % (width, e))
        if args.check:
            stale += extra
    if args.check and stale:
        print("%s golden data out of date: %s" % (label, ", ".join(stale)), file=sys.stderr)
        return 1
    return 0


def main() -> int:
    return run_pair_files(__doc__.split("\n\n")[0], PAIRS, golden, OUT_DIR, "collision", 16)

if __name__ == "__main__":
    sys.exit(main())
