#!/usr/bin/env python3
"""MuJoCo 4.0's transition Jacobians (mjd_transitionFD) for lagrange's transition_jacobians tests
(tests/transition.rs).

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_transition_golden.py          # (re)write tests/data/mujoco/transition/*.json
    python validation/mujoco_transition_golden.py --check  # recompute in memory, exit 1 if a file differs beyond 1e-12

Scenes: the go1 on its floor standing (keyframe "home", its controls) and walking (random
controls about home, 5% of their ranges, for 150 steps), the humanoid falling onto its floor, the panda arm without a
floor (contact-free; implicitfast), a parallel gripper holding a box in the air by friction
(validation/scenes/gripper_box.xml: six sphere-box contacts, servos with random controls). Each model is the tight-solver copy of the soft-mode golden
data (Newton, tolerance 1e-15, 1000 iterations, line search 100 iterations to 1e-12, dense
Jacobians: lagrange's tests/common tight_model), so that the nudged steps' solutions are exact
to round-off. Per state: qpos, qvel, act, ctrl, qacc_warmstart, the number of contacts, and
A, B of mjd_transitionFD(eps = 1e-6, centred), rows the next state (dq tangent, dv, dact).
Plus, per state, whether every nudged step keeps the nominal contact count (contact_set_same):
the cases where finite differences are comparable at 1e-6.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

import mujoco as mj
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from mujoco_golden import check_status, dump  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parent.parent
OUT_DIR = REPO / "tests" / "data" / "mujoco" / "transition"
SCRIPT = "validation/mujoco_transition_golden.py"
SEED = 20261126
EPS = 1e-6
CHECK_REL = 1e-12

# name -> (model, keyframe or None, warm-up steps, control noise about the keyframe's controls)
SCENES = {
    "go1_standing": ("models/mjcf/unitree_go1/scene.xml", "home", 20, 0.0),
    "go1_walking": ("models/mjcf/unitree_go1/scene.xml", "home", 150, 0.05),
    "humanoid_floor": ("models/mjcf/humanoid/humanoid.xml", None, 60, 0.3),
    "panda_free": ("models/mjcf/franka_emika_panda/panda.xml", "home", 30, 0.3),
    "gripper_box": ("validation/scenes/gripper_box.xml", "hold", 200, 0.05),
}
N_STATES = 2


def tight(m):
    m.opt.solver = mj.mjtSolver.mjSOL_NEWTON
    m.opt.tolerance = 1e-15
    m.opt.iterations = 1000
    m.opt.ls_iterations = 100
    m.opt.ls_tolerance = 1e-12
    m.opt.jacobian = mj.mjtJacobian.mjJAC_DENSE


def contact_set_same(m, d):
    """Whether every nudged step of mjd_transitionFD keeps the nominal step's contact count."""
    spec = mj.mjtState.mjSTATE_FULLPHYSICS | mj.mjtState.mjSTATE_CTRL | mj.mjtState.mjSTATE_WARMSTART
    saved = np.zeros(mj.mj_stateSize(m, spec))
    mj.mj_getState(m, d, saved, spec)
    d2 = mj.MjData(m)

    def ncon_after(change):
        mj.mj_setState(m, d2, saved, spec)
        change(d2)
        mj.mj_step(m, d2)
        return d2.ncon

    nominal = ncon_after(lambda _: None)
    for s in (EPS, -EPS):
        for k in range(m.nv):
            def dq(x, k=k, s=s):
                e = np.zeros(m.nv)
                e[k] = 1.0
                mj.mj_integratePos(m, x.qpos, e, s)
            def dv(x, k=k, s=s):
                x.qvel[k] += s
            if ncon_after(dq) != nominal or ncon_after(dv) != nominal:
                return False
        for k in range(m.nu):
            def du(x, k=k, s=s):
                x.ctrl[k] += s
            if ncon_after(du) != nominal:
                return False
    return True


def scene_doc(name, rng):
    rel, key, warmup, noise = SCENES[name]
    m = mj.MjModel.from_xml_path(str(REPO / rel))
    tight(m)
    d = mj.MjData(m)
    ctrl0 = np.zeros(m.nu)
    if key is not None:
        mj.mj_resetDataKeyframe(m, d, mj.mj_name2id(m, mj.mjtObj.mjOBJ_KEY, key))
        ctrl0 = d.ctrl.copy()
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    limited = m.actuator_ctrllimited.astype(bool)
    states = []
    for _ in range(N_STATES):
        for _ in range(warmup):
            u = ctrl0 + noise * rng.standard_normal(m.nu) * np.where(limited, hi - lo, 1.0)
            d.ctrl[:] = np.where(limited, np.clip(u, lo, hi), u)
            mj.mj_step(m, d)
        ndx = 2 * m.nv + m.na
        A = np.zeros((ndx, ndx))
        B = np.zeros((ndx, m.nu))
        mj.mj_forward(m, d)
        ncon = int(d.ncon)
        same = contact_set_same(m, d)
        mj.mjd_transitionFD(m, d, EPS, True, A, B, None, None)
        states.append(
            {
                "qpos": d.qpos.tolist(),
                "qvel": d.qvel.tolist(),
                "act": d.act.tolist(),
                "ctrl": d.ctrl.tolist(),
                "qacc_warmstart": d.qacc_warmstart.tolist(),
                "ncon": ncon,
                "contact_set_same": same,
                "A": A.tolist(),
                "B": B.tolist(),
            }
        )
    return {
        "scene": name,
        "model": rel,
        "generator": "mujoco %s, %s" % (mj.__version__, SCRIPT),
        "seed": SEED,
        "eps": EPS,
        "centered": True,
        "solver": "Newton, tolerance 1e-15, iterations 1000, ls_iterations 100, ls_tolerance 1e-12, dense",
        "nv": m.nv,
        "na": m.na,
        "nu": m.nu,
        "states": states,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="recompute in memory; exit 1 if a file differs")
    args = ap.parse_args()
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    stale = []
    for i, name in enumerate(SCENES):
        doc = scene_doc(name, np.random.default_rng([SEED, i]))
        text = dump(doc) + "\n"
        assert json.loads(text) == json.loads(json.dumps(doc)), "dump() lost information"
        out = OUT_DIR / ("%s.json" % name)
        old = out.read_text() if out.exists() else None
        if args.check:
            status = check_status(old, text, json.loads(text), CHECK_REL)
            if not status.startswith("ok"):
                stale.append(out.relative_to(REPO).as_posix())
        else:
            status = "unchanged" if old == text else "written"
            if old != text:
                out.write_text(text)
        same = [s["contact_set_same"] for s in doc["states"]]
        ncon = [s["ncon"] for s in doc["states"]]
        print("%-15s nv=%-3d ncon=%s same-contact-set=%s  %-9s %s" % (
            name, doc["nv"], ncon, same, status, out.relative_to(REPO).as_posix()))
    if args.check and stale:
        print("transition golden data out of date: %s" % ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
