#!/usr/bin/env python3
"""MuJoCo's geometric queries for lagrange's tests/geom_queries.rs: mj_ray (nearest geom along a
ray, with its geomgroup / flg_static / bodyexclude filters), mju_rayGeom on sites, mju_insideGeom
on sites (through the insidesite sensor: the Python bindings do not expose it) and
mj_geomDistance (signed distance and fromto segment between two geoms).

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_geomq_golden.py            # (re)write tests/data/mujoco_geomq/
    python validation/mujoco_geomq_golden.py --check    # recompute in memory; exit 1 if a file moved beyond 1e-12

Scenes (MJCF text in each JSON; mesh files written beside them in tests/data/mujoco_geomq/meshes/,
named in the MJCF through the placeholder @MESHDIR@ for <compiler meshdir>):

- primitives.json: a floor, a bounded tilted plane, a static box (a body welded to the world), a
  mocap cylinder with a welded child capsule, free bodies with a sphere, a visual capsule
  (contype 0, group 2), an ellipsoid, a cylinder, a box (group 9, clamped to 5 by the filter)
  with a welded lid body, a two-hinge arm, and a body with three alpha cases (rgba alpha 0,
  material alpha 0, material alpha 1 over rgba alpha 0); sites of every primitive type (default
  size and class sizes filled entry by entry, fromto). Per random state (qpos, mocap pose): rays
  (random, aimed at each geom, from inside each geom, parallel to and in the floor's plane, from
  below the floor, into the sky) under five filters, the last excluding the body the first hit;
  rays against every site (mju_rayGeom: aimed, from inside, missing); points around every site
  (insidesite; points within 1e-9 of the surface are left out, where the sign is round-off).
- meshes.json: a slab mesh whose inertial frame is its file frame (MuJoCo's float vertices are
  the file's exactly), a non-convex L-shaped prism (visual: contype 0) and a tetrahedron
  (MuJoCo moves both to their inertial frames and rounds the vertices to float32); rays at
  them (into the L's notch too: triangles, not the hull) and from inside the slab.
- distance.json: mj_geomDistance between every pair of a floor, a sphere, a capsule, an
  ellipsoid, a cylinder, a box and the slab mesh, both orders: body 2 placed from body 1 along a
  random direction at a chosen signed distance (bisection on MuJoCo's own distance): penetrating
  (-0.02 to -0.002 m) and separated (0.01 to 0.3 m), each with distmax 1 and a distmax below the
  distance (the cap, no fromto). The scene sets ccd_tolerance 1e-14 and ccd_iterations 1000 so
  that MuJoCo's GJK/EPA (ellipsoids, cylinders, boxes, meshes) converges close to the exact
  distance that lagrange's computes.

Deterministic: a fixed seed per scene, floats with repr, keys sorted (validation/mujoco_golden.py's
dump). --check compares numbers relative to the largest magnitude of their quantity and ids,
counts and mesh files exactly.
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
OUT_DIR = REPO / "tests" / "data" / "mujoco_geomq"
MESH_DIR = OUT_DIR / "meshes"
MESHDIR = "@MESHDIR@"
SCRIPT = "validation/mujoco_geomq_golden.py"
SEED = 20270611
CHECK_REL = 1e-12

# ------------------------------------------------------------------------------------------------
# Mesh files (OBJ text, written by this script)
# ------------------------------------------------------------------------------------------------


def prism(outline, z0, z1) -> tuple[list, list]:
    """A prism over a counter-clockwise polygon (fan-triangulated from its first vertex, which must
    see every other), triangles wound counter-clockwise seen from outside."""
    n = len(outline)
    verts = [(x, y, z0) for x, y in outline] + [(x, y, z1) for x, y in outline]
    faces = []
    for k in range(1, n - 1):
        faces.append((0, k + 1, k))  # bottom, facing -z
        faces.append((n, n + k, n + k + 1))  # top, facing +z
    for k in range(n):
        a, b = k, (k + 1) % n
        faces.append((a, b, n + b))
        faces.append((a, n + b, n + a))
    return verts, faces


def obj_text(verts, faces, comment) -> str:
    lines = [f"# {comment} (written by {SCRIPT})"]
    lines += ["v %r %r %r" % tuple(float(c) for c in v) for v in verts]
    lines += ["f %d %d %d" % tuple(i + 1 for i in f) for f in faces]
    return "\n".join(lines) + "\n"


def mesh_files() -> dict[str, str]:
    slab = prism([(-0.25, -0.125), (0.25, -0.125), (0.25, 0.125), (-0.25, 0.125)], -0.0625, 0.0625)
    # An L in the xy plane (the square [1,2]x[1,2] of the 2x2 block missing), 1/8 m cells, offset
    # from the origin; fan-triangulated from (0, 0), which sees every vertex.
    ell = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    notch = prism([(0.125 * x + 0.05, 0.125 * y - 0.1) for x, y in ell], 0.02, 0.145)
    tet_v = [(0.0, 0.0, 0.0), (0.3, 0.02, 0.01), (0.05, 0.22, -0.03), (0.07, 0.06, 0.25)]
    tet_f = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    return {
        "slab.obj": obj_text(*slab, "box 0.5 x 0.25 x 0.125 m centred on the origin"),
        "notch.obj": obj_text(*notch, "L-shaped prism, non-convex"),
        "tet.obj": obj_text(tet_v, tet_f, "irregular tetrahedron"),
    }


# ------------------------------------------------------------------------------------------------
# Helpers
# ------------------------------------------------------------------------------------------------


def floats(a) -> list:
    return [float(x) for x in np.asarray(a, float).ravel()]


def random_quat(rng) -> np.ndarray:
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def unit(rng) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def load(xml: str) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(xml.replace(MESHDIR, str(MESH_DIR)))


def free_joint_bodies(m) -> list[int]:
    return [int(m.jnt_bodyid[j]) for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]


def random_state(m, d, rng, box) -> dict:
    """Random free-body poses in `box` (lo, hi corners), other joints within ±1, random mocap poses."""
    mujoco.mj_resetData(m, d)
    lo, hi = np.asarray(box[0], float), np.asarray(box[1], float)
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        t = m.jnt_type[j]
        if t == mujoco.mjtJoint.mjJNT_FREE:
            d.qpos[a:a + 3] = rng.uniform(lo, hi)
            d.qpos[a + 3:a + 7] = random_quat(rng)
        elif t == mujoco.mjtJoint.mjJNT_BALL:
            d.qpos[a:a + 4] = random_quat(rng)
        else:
            d.qpos[a] = rng.uniform(-1.0, 1.0)
    for k in range(m.nmocap):
        d.mocap_pos[k] = rng.uniform(lo, hi)
        d.mocap_quat[k] = random_quat(rng)
    mujoco.mj_forward(m, d)
    return {"qpos": floats(d.qpos), "mocap_pos": floats(d.mocap_pos), "mocap_quat": floats(d.mocap_quat)}


def model_info(m) -> dict:
    """What the test checks lagrange's compiled model against: geom and site names in id order,
    their MuJoCo body ids, geom groups and visible alphas (the material's when it has one), site
    types (mjtGeom) and sizes."""
    alpha = [float(m.mat_rgba[m.geom_matid[g]][3] if m.geom_matid[g] >= 0 else m.geom_rgba[g][3]) for g in range(m.ngeom)]
    return {"geom_names": [m.geom(g).name for g in range(m.ngeom)],
            "geom_bodyid": [int(b) for b in m.geom_bodyid], "geom_group": [int(x) for x in m.geom_group],
            "geom_alpha": alpha, "body_weldid": [int(b) for b in m.body_weldid],
            "site_names": [m.site(s).name for s in range(m.nsite)], "site_bodyid": [int(b) for b in m.site_bodyid],
            "site_type": [int(t) for t in m.site_type], "site_size": [floats(x) for x in m.site_size]}


def ray(m, d, p, v, flt) -> dict:
    gid = np.array([-1], dtype=np.int32)
    normal = np.zeros(3)
    group = None if flt["geomgroup"] is None else np.array(flt["geomgroup"], dtype=np.uint8)
    dist = mujoco.mj_ray(m, d, np.asarray(p, float), np.asarray(v, float), group, flt["flg_static"],
                         flt["bodyexclude"], gid, normal)
    return {"dist": float(dist), "geom": int(gid[0]), "normal": floats(normal)}


FILTERS = [
    {"geomgroup": None, "flg_static": True, "bodyexclude": -1},
    {"geomgroup": None, "flg_static": False, "bodyexclude": -1},
    {"geomgroup": [1, 0, 1, 0, 1, 1], "flg_static": True, "bodyexclude": -1},
    {"geomgroup": [0, 1, 0, 1, 0, 0], "flg_static": False, "bodyexclude": -1},
    # bodyexclude: the body of the geom the first filter's ray hits (the world when none).
    {"geomgroup": None, "flg_static": True, "bodyexclude": "first hit"},
]


def ray_record(m, d, p, v, kind) -> dict:
    results = []
    for flt in FILTERS:
        flt = dict(flt)
        if flt["bodyexclude"] == "first hit":
            first = results[0]["geom"]
            flt["bodyexclude"] = int(m.geom_bodyid[first]) if first >= 0 else 0
        r = ray(m, d, p, v, flt)
        r["bodyexclude"] = flt["bodyexclude"]
        results.append(r)
    return {"kind": kind, "p": floats(p), "v": floats(v), "results": results}


def rays_at_geoms(m, d, rng, per_geom) -> list:
    """Random rays, rays aimed at each geom and from inside each, parallel-to-floor, below-floor
    and sky rays."""
    out = []
    for _ in range(8):
        p = rng.uniform([-2, -2, -0.5], [2, 2, 2.5])
        out.append(ray_record(m, d, p, unit(rng) * rng.uniform(0.5, 2.0), "random"))
    for g in range(m.ngeom):
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE:
            continue
        c = d.geom_xpos[g]
        r = m.geom_rbound[g]
        for _ in range(per_geom):
            p = c + unit(rng) * rng.uniform(1.5, 4.0) * max(r, 0.1)
            aim = c + unit(rng) * rng.uniform(0.0, 0.8) * r
            out.append(ray_record(m, d, p, (aim - p) * rng.uniform(0.3, 3.0), "aimed"))
        for _ in range(max(1, per_geom // 3)):
            out.append(ray_record(m, d, c + unit(rng) * 0.01 * r, unit(rng) * rng.uniform(0.5, 2.0), "inside"))
    for _ in range(3):
        h = rng.uniform(0.05, 1.0)
        out.append(ray_record(m, d, [*rng.uniform(-1, 1, 2), h], [*unit(rng)[:2], 0.0], "parallel_to_floor"))
    out.append(ray_record(m, d, [0.3, -0.2, 0.0], [1.0, 0.5, 0.0], "in_floor_plane"))
    out.append(ray_record(m, d, [0.1, 0.2, -0.5], [0.05, -0.02, 1.0], "from_below_floor"))
    out.append(ray_record(m, d, [0.0, 0.0, 5.0], [0.1, 0.2, 1.0], "into_sky"))
    return out


SITE_LEVEL_SKIP = 1e-9


def site_level(m, s, local) -> float:
    """A function < 0 inside site s, > 0 outside, 0 on its surface, ~relative (to skip points
    whose inside/outside is round-off)."""
    t = m.site_type[s]
    r = m.site_size[s]
    x, y, z = local
    if t == mujoco.mjtGeom.mjGEOM_SPHERE:
        return (x * x + y * y + z * z) / r[0] ** 2 - 1
    if t == mujoco.mjtGeom.mjGEOM_CAPSULE:
        dz = z - min(max(z, -r[1]), r[1])
        return (x * x + y * y + dz * dz) / r[0] ** 2 - 1
    if t == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        return (x / r[0]) ** 2 + (y / r[1]) ** 2 + (z / r[2]) ** 2 - 1
    if t == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return max(abs(z) / r[1], math.hypot(x, y) / r[0]) - 1
    if t == mujoco.mjtGeom.mjGEOM_BOX:
        return max(abs(x) / r[0], abs(y) / r[1], abs(z) / r[2]) - 1
    raise ValueError(t)


def site_cases(m, d, probe_m, probe_d, state, rng, per_site) -> tuple[list, list]:
    """mju_rayGeom rays against every site, and insidesite at points around every site (the probe
    model: the scene plus a mocap probe site and one insidesite sensor per site)."""
    rays, points = [], []
    for s in range(m.nsite):
        name = m.site(s).name
        pos, mat, size, stype = d.site_xpos[s].copy(), d.site_xmat[s].copy(), m.site_size[s].copy(), int(m.site_type[s])
        extent = float(np.max(size))
        for k in range(per_site):
            kind = "aimed" if k % 3 else "inside"
            if kind == "aimed":
                p = pos + unit(rng) * rng.uniform(2.0, 5.0) * extent
                aim = pos + unit(rng) * rng.uniform(0.0, 1.2) * extent
            else:
                p = pos + unit(rng) * 0.1 * extent
                aim = p + unit(rng)
            v = (aim - p) * rng.uniform(0.3, 3.0)
            normal = np.zeros(3)
            dist = mujoco.mju_rayGeom(pos, mat, size, p, v, stype, normal)
            rays.append({"site": name, "kind": kind, "p": floats(p), "v": floats(v), "dist": float(dist),
                         "normal": floats(normal)})
        # Points in the site frame within 1.3 times its extents (0.005 for unused entries).
        half = np.where(size > 0, size, 0.005)
        if stype in (mujoco.mjtGeom.mjGEOM_SPHERE,):
            half = np.array([size[0]] * 3)
        if stype in (mujoco.mjtGeom.mjGEOM_CAPSULE,):
            half = np.array([size[0], size[0], size[0] + size[1]])
        if stype in (mujoco.mjtGeom.mjGEOM_CYLINDER,):
            half = np.array([size[0], size[0], size[1]])
        sensor = probe_m.sensor(f"inside_{name}").id
        taken = 0
        while taken < per_site:
            local = rng.uniform(-1.3, 1.3, 3) * half
            if abs(site_level(m, s, local)) < SITE_LEVEL_SKIP:
                continue
            point = pos + mat.reshape(3, 3) @ local
            probe_d.qpos[:] = state["qpos"]
            probe_d.mocap_pos[:-1] = np.reshape(state["mocap_pos"], (-1, 3))
            probe_d.mocap_quat[:-1] = np.reshape(state["mocap_quat"], (-1, 4))
            probe_d.mocap_pos[-1] = point
            mujoco.mj_forward(probe_m, probe_d)
            inside = int(round(probe_d.sensordata[probe_m.sensor_adr[sensor]]))
            points.append({"site": name, "point": floats(point), "inside": inside})
            taken += 1
    return rays, points


def probe_model(xml: str, sites: list[str]) -> str:
    """The scene with a mocap probe site appended to the world and one insidesite sensor per site."""
    probe = '<body name="geomq_probe" mocap="true"><site name="geomq_probe"/></body>\n</worldbody>'
    sensors = "".join(f'<insidesite name="inside_{s}" site="{s}" objtype="site" objname="geomq_probe"/>' for s in sites)
    return xml.replace("</worldbody>", probe, 1).replace("</mujoco>", f"<sensor>{sensors}</sensor>\n</mujoco>")


# ------------------------------------------------------------------------------------------------
# Scenes
# ------------------------------------------------------------------------------------------------

PRIMITIVES = """<mujoco model="geomq_primitives">
  <compiler angle="radian"/>
  <asset>
    <material name="clear" rgba="0.2 0.3 0.4 0"/>
    <material name="solid" rgba="0.9 0.1 0.1 1"/>
  </asset>
  <default>
    <default class="visual"><geom contype="0" conaffinity="0" group="2"/></default>
    <default class="zone"><site type="box" size="0.12 0.08"/></default>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
    <geom name="panel" type="plane" size="0.6 0.4 0.05" pos="0.3 -0.2 2.2" euler="2.9 0.2 0.4" group="1"/>
    <site name="world_zone" type="ellipsoid" size="0.3 0.2 0.1" pos="-1 1 0.2" euler="0.3 0.1 0.2"/>
    <body name="post" pos="1.6 0.2 0.5">
      <geom name="post" type="box" size="0.1 0.12 0.5" group="1"/>
    </body>
    <body name="target" mocap="true" pos="-1.6 -0.3 0.8">
      <geom name="target" type="cylinder" size="0.12 0.1" group="3"/>
      <body name="target_child" pos="0 0 0.3">
        <geom name="target_cap" type="capsule" size="0.05 0.1"/>
      </body>
    </body>
    <body name="ball" pos="0 0 1">
      <freejoint/>
      <geom name="ball" size="0.2"/>
      <site name="ball_zone" type="sphere" size="0.25"/>
    </body>
    <body name="pill" pos="0.5 0 1">
      <freejoint/>
      <geom name="pill" type="capsule" size="0.1 0.25" class="visual"/>
      <site name="pill_zone" type="capsule" fromto="0 0 -0.3 0.05 0 0.3" size="0.12"/>
    </body>
    <body name="egg" pos="-0.5 0 1">
      <freejoint/>
      <geom name="egg" type="ellipsoid" size="0.3 0.2 0.12" group="4"/>
      <site name="egg_zone" type="ellipsoid" size="0.32 0.22 0.14" euler="0.2 0.3 0.1"/>
    </body>
    <body name="can" pos="0 0.5 1">
      <freejoint/>
      <geom name="can" type="cylinder" size="0.15 0.2" group="5"/>
      <site name="can_zone" type="cylinder" size="0.16 0.22" pos="0.01 0 0"/>
    </body>
    <body name="brick" pos="0 -0.5 1">
      <freejoint/>
      <geom name="brick" type="box" size="0.2 0.15 0.1" group="9"/>
      <site name="brick_zone" class="zone"/>
      <site name="brick_top" class="zone" size="0.15" pos="0 0 0.1"/>
      <site name="tiny" pos="0.05 0 0"/>
      <body name="brick_lid" pos="0 0 0.15">
        <geom name="lid" type="box" size="0.1 0.1 0.02"/>
      </body>
    </body>
    <body name="arm" pos="0.8 -0.8 0.6">
      <joint type="hinge" axis="0 1 0" pos="0 0 0.2"/>
      <joint type="hinge" axis="1 0 0" pos="0.1 0 0"/>
      <geom name="arm" type="capsule" fromto="0 0 0 0.4 0 0" size="0.05"/>
    </body>
    <body name="ghosts" pos="-0.5 0.8 0.6">
      <joint type="slide" axis="0 0 1"/>
      <geom name="invisible" size="0.15" rgba="1 1 1 0"/>
      <geom name="clear_material" type="box" size="0.1 0.1 0.1" pos="0.4 0 0" material="clear"/>
      <geom name="solid_material_alpha0" type="box" size="0.1 0.1 0.1" pos="-0.4 0 0" material="solid" rgba="1 1 1 0"/>
    </body>
  </worldbody>
</mujoco>
"""

MESHES = """<mujoco model="geomq_meshes">
  <compiler angle="radian" meshdir="@MESHDIR@"/>
  <asset>
    <mesh name="slab" file="slab.obj"/>
    <mesh name="notch" file="notch.obj"/>
    <mesh name="tet" file="tet.obj" scale="1 1.5 1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
    <body name="slab" pos="0 0 0.5">
      <freejoint/>
      <geom name="slab" type="mesh" mesh="slab"/>
    </body>
    <body name="notch" pos="0.6 0 0.5">
      <freejoint/>
      <geom name="notch" type="mesh" mesh="notch" contype="0" conaffinity="0" group="2"/>
    </body>
    <body name="tet" pos="-0.6 0 0.5">
      <freejoint/>
      <geom name="tet" type="mesh" mesh="tet"/>
    </body>
    <body name="ball" pos="0 0.6 0.5">
      <freejoint/>
      <geom name="ball" size="0.1"/>
    </body>
  </worldbody>
</mujoco>
"""

# One free body per geom type beside a floor; body i holds geom i + 1.
DISTANCE_GEOMS = [
    ("sphere", 'type="sphere" size="0.125"'),
    ("capsule", 'type="capsule" size="0.0625 0.2"'),
    ("ellipsoid", 'type="ellipsoid" size="0.2 0.125 0.09"'),
    ("cylinder", 'type="cylinder" size="0.11 0.15"'),
    ("box", 'type="box" size="0.2 0.13 0.08"'),
    ("slab", 'type="mesh" mesh="slab"'),
]


def distance_xml() -> str:
    bodies = "\n".join(f'    <body name="{n}" pos="{3 * k} 10 10">\n      <freejoint/>\n      <geom name="{n}" {g}/>\n    </body>'
                       for k, (n, g) in enumerate(DISTANCE_GEOMS))
    return f"""<mujoco model="geomq_distance">
  <compiler angle="radian" meshdir="@MESHDIR@"/>
  <option ccd_tolerance="1e-14" ccd_iterations="1000"/>
  <asset>
    <mesh name="slab" file="slab.obj"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
{bodies}
  </worldbody>
</mujoco>
"""


def primitives_cases(rng) -> dict:
    m = load(PRIMITIVES)
    d = mujoco.MjData(m)
    sites = [m.site(s).name for s in range(m.nsite)]
    pm = load(probe_model(PRIMITIVES, sites))
    pd = mujoco.MjData(pm)
    assert pm.nmocap == m.nmocap + 1
    states = []
    for k in range(4):
        state = random_state(m, d, rng, ([-1.2, -1.2, 0.2], [1.2, 1.2, 1.6]))
        state["name"] = f"random{k}"
        state["rays"] = rays_at_geoms(m, d, rng, 4)
        state["site_rays"], state["inside"] = site_cases(m, d, pm, pd, state, rng, 9)
        states.append(state)
    return {"name": "primitives", "mjcf": PRIMITIVES, "model": model_info(m), "filters": FILTERS, "states": states}


def meshes_cases(rng) -> dict:
    m = load(MESHES)
    d = mujoco.MjData(m)
    states = []
    notch = m.geom("notch").id
    notch_body = m.geom_bodyid[notch]
    for k in range(4):
        state = random_state(m, d, rng, ([-0.8, -0.8, 0.3], [0.8, 0.8, 1.2]))
        state["name"] = f"random{k}"
        rays = rays_at_geoms(m, d, rng, 8)
        # Into the L's notch (the missing cell's centre, in the mesh file frame = the body frame).
        corner = d.xpos[notch_body] + d.xmat[notch_body].reshape(3, 3) @ np.array([0.05 + 0.1875, -0.1 + 0.1875, 0.08])
        for _ in range(8):
            p = corner + unit(rng) * rng.uniform(0.3, 0.8)
            rays.append(ray_record(m, d, p, (corner - p) * rng.uniform(0.5, 2.0), "into_notch"))
        state["rays"] = rays
        states.append(state)
    return {"name": "meshes", "mjcf": MESHES, "model": model_info(m), "filters": FILTERS, "states": states}


def distance_cases(rng) -> dict:
    xml = distance_xml()
    m = load(xml)
    d = mujoco.MjData(m)
    far = lambda b: (np.array([3.0 * b, 10.0, 10.0]), np.array([1.0, 0, 0, 0]))  # noqa: E731
    ngeom = m.ngeom
    body_of = {g: int(m.geom_bodyid[g]) for g in range(ngeom)}
    joint_of = {b: int(m.body_jntadr[b]) for b in range(1, m.nbody)}

    def pose(b, pos, quat):
        a = m.jnt_qposadr[joint_of[b]]
        d.qpos[a:a + 3] = pos
        d.qpos[a + 3:a + 7] = quat

    def dist(g1, g2, qpos) -> float:
        d.qpos[:] = qpos
        mujoco.mj_kinematics(m, d)
        return mujoco.mj_geomDistance(m, d, g1, g2, 10.0, None)

    cases = []
    for g1 in range(ngeom):
        for g2 in range(g1 + 1, ngeom):
            for target_kind in ["penetrating", "separated", "penetrating", "separated"]:
                mujoco.mj_resetData(m, d)
                for b in range(1, m.nbody):
                    pose(b, *far(b))
                b1, b2 = body_of[g1], body_of[g2]
                if b1 == 0:  # the floor: body 2 above it, turned at random
                    start, direction = np.zeros(3), np.array([0.0, 0.0, 1.0])
                else:
                    start, direction = rng.uniform(-0.3, 0.3, 3), unit(rng)
                    pose(b1, start, random_quat(rng))
                quat2 = random_quat(rng)
                target = -rng.uniform(0.002, 0.02) if target_kind == "penetrating" else rng.uniform(0.01, 0.3)
                base = d.qpos.copy()

                def at(s):
                    q = base.copy()
                    a = m.jnt_qposadr[joint_of[b2]]
                    q[a:a + 3] = start + s * direction
                    q[a + 3:a + 7] = quat2
                    return q

                lo, hi = 0.0, 3.0
                assert dist(g1, g2, at(hi)) > target
                if dist(g1, g2, at(lo)) > target:
                    continue
                for _ in range(80):
                    mid = 0.5 * (lo + hi)
                    if dist(g1, g2, at(mid)) > target:
                        hi = mid
                    else:
                        lo = mid
                qpos = at(lo)
                d.qpos[:] = qpos
                mujoco.mj_forward(m, d)
                results = []
                for a, b in [(g1, g2), (g2, g1)]:
                    exact = mujoco.mj_geomDistance(m, d, a, b, 10.0, None)
                    for distmax in [1.0, exact - 0.5 * abs(exact) if exact > 0 else 1.0]:
                        fromto = np.zeros(6)
                        dd = mujoco.mj_geomDistance(m, d, a, b, distmax, fromto)
                        results.append({"geom1": a, "geom2": b, "distmax": float(distmax), "dist": float(dd),
                                        "fromto": floats(fromto)})
                cases.append({"name": f"{m.geom(g1).name}-{m.geom(g2).name}-{len(cases)}", "kind": target_kind,
                              "qpos": floats(qpos), "results": results})
    return {"name": "distance", "mjcf": xml, "model": model_info(m), "states": cases}


SCENES = {"primitives": primitives_cases, "meshes": meshes_cases, "distance": distance_cases}


def golden(scene: str) -> str:
    rng = np.random.default_rng([SEED, zlib.crc32(scene.encode())])
    doc = SCENES[scene](rng)
    doc["generated"] = f"by {SCRIPT} with mujoco {mujoco.__version__}; do not edit (rerun the script)"
    doc["layout"] = ("rays: p + x v, x >= 0; results per filter (geomgroup null = all groups, bodyexclude -1 = "
                     "none), dist -1 and geom -1 for no hit, normal world; site_rays: mju_rayGeom on the site's "
                     "type and size; inside: mju_insideGeom (insidesite sensor), 1 inside; distance results: "
                     "mj_geomDistance(geom1, geom2, distmax), fromto zero when dist = distmax; qpos, mocap_pos, "
                     "mocap_quat (w x y z) the state; MJCF meshdir @MESHDIR@ = tests/data/mujoco_geomq/meshes")
    text = dump(doc) + "\n"
    assert json.loads(text) == json.loads(json.dumps(doc)), "dump() lost information"
    return text


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="recompute in memory; exit 1 if a file differs")
    args = ap.parse_args()
    stale = []
    MESH_DIR.mkdir(parents=True, exist_ok=True)
    for name, text in mesh_files().items():
        path = MESH_DIR / name
        old = path.read_text() if path.exists() else None
        if args.check:
            if old != text:
                stale.append(path.relative_to(REPO).as_posix())
        elif old != text:
            path.write_text(text)
    for scene in SCENES:
        text = golden(scene)
        out = OUT_DIR / f"{scene}.json"
        old = out.read_text() if out.exists() else None
        doc = json.loads(text)
        if args.check:
            status = check_status(old, text, doc, CHECK_REL)
            if not status.startswith("ok"):
                stale.append(out.relative_to(REPO).as_posix())
        else:
            status = "unchanged" if old == text else "written"
            if old != text:
                out.write_text(text)
        print("%-10s %3d states  %-9s %s" % (scene, len(doc["states"]), status, out.relative_to(REPO).as_posix()))
    if args.check and stale:
        print("geometric-query golden data out of date: %s" % ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
