#!/usr/bin/env python3
"""MuJoCo's tendon quantities on hand-made spatial-tendon scenes, for tests/tendon_mujoco.rs.

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_tendon_golden.py            # (re)write tests/data/mujoco/tendon/*.json
    python validation/mujoco_tendon_golden.py --check    # recompute in memory, exit 1 if a file differs beyond round-off

Per scene of tests/data/tendon (each wrap case: sphere and cylinder with and without side site,
the inside wrap, a pulley with divisor, site paths through several bodies; springs with a dead
band, damping, friction loss, a limit, actuators on spatial tendons, tendon sensors): at seeded
random states (qpos, qvel, ctrl), mj_forward's ten_length, ten_J (dense), ten_velocity,
ten_wrapnum, wrap_obj, wrap_xpos, actuator_length, actuator_moment (dense), qfrc_passive,
efc_type, efc_id, efc_force, qacc and sensordata; and a 200-step mj_step trajectory (qpos, qvel
every step) from the first state. Deterministic (fixed seed, floats written with repr, keys
sorted); --check compares numbers relative to the largest magnitude of their quantity.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

import mujoco
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from mujoco_golden import check_status, dump  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parent.parent
SCENES = REPO / "tests" / "data" / "tendon"
OUT_DIR = REPO / "tests" / "data" / "mujoco" / "tendon"
SEED = 20261126
CHECK_REL = 1e-12
NSTATES = 12
NSTEPS = 200


def dense(rownnz, rowadr, colind, values, nrow, ncol):
    out = np.zeros((nrow, ncol))
    for i in range(nrow):
        for k in range(rowadr[i], rowadr[i] + rownnz[i]):
            out[i, colind[k]] = values[k]
    return out


def rows(a) -> list:
    return [[float(x) for x in r] for r in np.atleast_2d(a)]


def flat(a) -> list:
    return [float(x) for x in np.ravel(a)]


def random_state(m, rng):
    q = m.qpos0.copy()
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        kind = int(m.jnt_type[j])
        if kind == int(mujoco.mjtJoint.mjJNT_BALL):
            v = rng.normal(size=4)
            v[0] = abs(v[0]) + 1.0
            q[a:a + 4] = v / np.linalg.norm(v)
        elif kind in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
            lo, hi = (m.jnt_range[j] if m.jnt_limited[j] else (-1.5, 1.5))
            q[a] = rng.uniform(lo, hi)
    v = rng.normal(scale=1.0, size=m.nv)
    ctrl = rng.uniform(-1, 1, size=m.nu)
    return q, v, ctrl


def state_doc(m, d) -> dict:
    ten_j = dense(m.ten_J_rownnz, m.ten_J_rowadr, m.ten_J_colind, d.ten_J, m.ntendon, m.nv)
    moment = dense(d.moment_rownnz, d.moment_rowadr, d.moment_colind, d.actuator_moment, m.nu, m.nv)
    nwrap = int(d.ten_wrapadr[-1] + d.ten_wrapnum[-1]) if m.ntendon else 0
    return {
        "qpos": flat(d.qpos),
        "qvel": flat(d.qvel),
        "ctrl": flat(d.ctrl),
        "ten_length": flat(d.ten_length),
        "ten_velocity": flat(d.ten_velocity),
        "ten_J": rows(ten_j),
        "ten_wrapadr": [int(x) for x in d.ten_wrapadr],
        "ten_wrapnum": [int(x) for x in d.ten_wrapnum],
        "wrap_obj": [int(x) for x in np.ravel(d.wrap_obj)[:nwrap]],
        "wrap_xpos": rows(np.reshape(d.wrap_xpos, (-1, 3))[:nwrap]) if nwrap else [],
        "actuator_length": flat(d.actuator_length),
        "actuator_velocity": flat(d.actuator_velocity),
        "actuator_moment": rows(moment) if m.nu else [],
        "qfrc_passive": flat(d.qfrc_passive),
        "qfrc_actuator": flat(d.qfrc_actuator),
        "efc_type": [int(x) for x in d.efc_type],
        "efc_id": [int(x) for x in d.efc_id],
        "efc_force": flat(d.efc_force),
        "qacc": flat(d.qacc),
        "sensordata": flat(d.sensordata),
    }


def golden(scene: pathlib.Path) -> str:
    m = mujoco.MjModel.from_xml_path(str(scene))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(SEED)
    states = []
    first = None
    for _ in range(NSTATES):
        q, v, ctrl = random_state(m, rng)
        mujoco.mj_resetData(m, d)
        d.qpos[:], d.qvel[:], d.ctrl[:] = q, v, ctrl
        mujoco.mj_forward(m, d)
        states.append(state_doc(m, d))
        first = first or (q, v * 0.2, ctrl)
    mujoco.mj_resetData(m, d)
    d.qpos[:], d.qvel[:], d.ctrl[:] = first
    traj = []
    for _ in range(NSTEPS):
        mujoco.mj_step(m, d)
        traj.append({"qpos": flat(d.qpos), "qvel": flat(d.qvel)})
    doc = {
        "script": "validation/mujoco_tendon_golden.py",
        "mujoco": mujoco.__version__,
        "scene": scene.relative_to(REPO).as_posix(),
        "tendon_lengthspring": rows(m.tendon_lengthspring),
        "tendon_invweight0": flat(m.tendon_invweight0),
        "states": states,
        "trajectory": {"qpos0": flat(first[0]), "qvel0": flat(first[1]), "ctrl": flat(first[2]), "steps": traj},
    }
    return dump(doc) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="recompute in memory; exit 1 if a file differs")
    args = ap.parse_args()
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    stale = []
    for scene in sorted(SCENES.glob("*.xml")):
        text = golden(scene)
        out = OUT_DIR / (scene.stem + ".json")
        old = out.read_text() if out.exists() else None
        if args.check:
            status = check_status(old, text, json.loads(text), CHECK_REL)
            if not status.startswith("ok"):
                stale.append(out.relative_to(REPO).as_posix())
        else:
            status = "unchanged" if old == text else "written"
            if old != text:
                out.write_text(text)
        print("%-20s %-9s %s" % (scene.stem, status, out.relative_to(REPO).as_posix()))
    if args.check and stale:
        print("tendon golden data out of date: %s" % ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
