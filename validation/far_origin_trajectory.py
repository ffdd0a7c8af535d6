#!/usr/bin/env python3
"""How far MuJoCo 4.0's trajectory of a translated scene follows the original (report only).

Run from the repository root with the validation venv (see validation/README.md):

    python validation/far_origin_trajectory.py [--steps 1000]

The same test as tests/far_origin.rs (translated_trajectories_follow_the_original) runs in
lagrange: tests/data/mjcf/far_origin/scene.xml (a ball and a tilted box resting on a floor, a fixed-base
arm falling onto it) from qpos0 at rest, and the same scene moved by d·(0.6, −0.48, 0.64) for
d = 1e3, 1e5, 1e6 m (everything on the world body moved in the MjSpec, the free bodies' qpos
set by hand); both stepped with mj_step, the translated free bodies' positions
brought back by −offset. Prints the largest qpos/qvel difference over the steps, as the lagrange
test does; and, for the go1 scene after 200 settling steps from its "home" keyframe, the same.
"""

from __future__ import annotations

import argparse
import pathlib

import mujoco
import numpy as np

REPO = pathlib.Path(__file__).resolve().parent.parent
DIRECTION = np.array([0.6, -0.48, 0.64])


def translate(path: pathlib.Path, offset: np.ndarray) -> mujoco.MjModel:
    """The model of path with everything on the world body (geoms, sites, tree roots) moved by
    offset, through MjSpec (a compiled model's static geoms and bounding volumes are precomputed,
    so editing geom_pos would not move them consistently)."""
    spec = mujoco.MjSpec.from_file(str(path))
    for g in spec.worldbody.geoms:
        g.pos = np.asarray(g.pos) + offset
    for s in spec.worldbody.sites:
        s.pos = np.asarray(s.pos) + offset
    for b in spec.worldbody.bodies:
        b.pos = np.asarray(b.pos) + offset
    return spec.compile()


def free_adrs(m: mujoco.MjModel) -> list[int]:
    return [m.jnt_qposadr[j] for j in range(m.njnt)
            if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE and m.body_parentid[m.jnt_bodyid[j]] == 0]


def gap(path: pathlib.Path, m: mujoco.MjModel, qpos, qvel, d: float, steps: int) -> float:
    offset = DIRECTION * d
    moved = translate(path, offset)
    a, b = mujoco.MjData(m), mujoco.MjData(moved)
    a.qpos[:], a.qvel[:] = qpos, qvel
    b.qpos[:], b.qvel[:] = qpos, qvel
    for adr in free_adrs(m):
        b.qpos[adr:adr + 3] += offset
    worst = 0.0
    for _ in range(steps):
        mujoco.mj_step(m, a)
        mujoco.mj_step(moved, b)
        back = b.qpos.copy()
        for adr in free_adrs(m):
            back[adr:adr + 3] -= offset
        worst = max(worst, float(np.max(np.abs(back - a.qpos))), float(np.max(np.abs(b.qvel - a.qvel))))
    return worst


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=1000)
    args = ap.parse_args()
    path = REPO / "tests/data/mjcf/far_origin/scene.xml"
    m = mujoco.MjModel.from_xml_path(str(path))
    for d in (1e3, 1e5, 1e6):
        g = gap(path, m, m.qpos0.copy(), np.zeros(m.nv), d, args.steps)
        print(f"MuJoCo {mujoco.__version__} far_origin/scene.xml, {args.steps} steps at {d:.0e} m: "
              f"largest qpos/qvel gap {g:.1e}")
    path = REPO / "models/mjcf/unitree_go1/scene.xml"
    m = mujoco.MjModel.from_xml_path(str(path))
    d0 = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d0, m.key("home").id)
    for _ in range(200):
        mujoco.mj_step(m, d0)
    for d in (1e3, 1e5, 1e6):
        g = gap(path, m, d0.qpos.copy(), d0.qvel.copy(), d, args.steps)
        print(f"MuJoCo {mujoco.__version__} go1 scene.xml, {args.steps} steps at {d:.0e} m: "
              f"largest qpos/qvel gap {g:.1e}")


if __name__ == "__main__":
    main()
