"""Reference data for MuJoCo's mj_rnePostConstraint (tests/rne_post.rs): the per-body quantities
MuJoCo's acceleration-stage sensors read, at random states of scenes covering what enters them.

For each scene, the tight-solver copy of validation/crossval_soft.py (Newton, tolerance 1e-15) at
the states of crossval_soft.random_states (seeded), with fixed xfrc_applied on some bodies:
mj_forward, then mj_rnePostConstraint. Written per state: qpos, qvel, qacc, qacc_smooth, nefc,
and per MuJoCo body subtree_com, cacc, cfrc_int, cfrc_ext (MuJoCo's convention: world axes about
subtree_com[body_rootid], [angular; linear] and [torque; force]); per site its position,
mj_objectAcceleration (world axes, [angular; linear]) and cfrc_int of its body moved to it
(world axes, [torque; force]); per body mj_objectAcceleration of the body frame (mjOBJ_XBODY) at
xpos. Scenes:

- arm: fixed-base arm under gravity, a two-hinge body, a hand welded to the forearm and a tool
  welded to the hand, a massive static pedestal; xfrc on forearm, hand and pedestal; no contacts;
- space: <flag gravity="disable">, a free torso with a ball-joint limb, a welded tip and a
  hinge-plus-slide body; xfrc on torso and tip; no contacts;
- stack: pyramidal contacts (boxes on the floor and on a static pedestal, a ball on a box, a
  condim-6 capsule); xfrc on a box;
- go1: models/mjcf/unitree_go1/scene.xml, a floating base on its floor (elliptic cones, limits,
  friction loss); xfrc on the trunk;
- mocap: tests/data/mjcf/applied/mocap.xml, mocap bodies pushing (contact) and holding (weld,
  connect) free bodies;
- the equality scenes of tests/data/mjcf/constraints/: weld between moving bodies with
  torquescale 0.4, connect by sites between free bodies, weld by sites, connect closing a
  four-bar.

Writes tests/data/mujoco_rnepost/<scene>.json (generated: do not edit); with --check recomputes
with the live MuJoCo and exits 1 when a committed file differs beyond 1e-12 relative.

  python validation/mujoco_rnepost_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mujoco as mj
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import crossval_soft as cs  # noqa: E402
from crossval_common import TIGHT  # noqa: E402
from mujoco_golden import check_status, dump  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tests/data/mujoco_rnepost"
SCRIPT = "validation/mujoco_rnepost_golden.py"
CHECK_REL = 1e-12
SEED = 20280                                         # per scene: SEED + its index
STATES = 6
# scene: (model, {body: xfrc_applied [force; torque], world axes})
SCENES = {
    "arm": ("tests/data/mjcf/rnepost/arm.xml",
            {"forearm": [0.5, -1.0, 2.0, 0.05, 0.02, -0.03], "hand": [1.0, 0.3, -0.5, 0.0, 0.04, 0.01],
             "pedestal": [10.0, 0.0, 3.0, 1.0, -2.0, 0.5]}),
    "space": ("tests/data/mjcf/rnepost/space.xml",
              {"torso": [2.0, -1.0, 0.5, 0.1, 0.3, -0.2], "tip": [0.0, 0.4, -0.3, 0.01, 0.0, 0.02]}),
    "stack": ("tests/data/mjcf/rnepost/stack.xml", {"box": [3.0, -1.0, 5.0, 0.2, 0.1, -0.3]}),
    "go1": ("models/mjcf/unitree_go1/scene.xml", {"trunk": [5.0, 2.0, -10.0, 0.5, -0.3, 0.2]}),
    "mocap": ("tests/data/mjcf/applied/mocap.xml", {}),
    "weld_bodies_torquescale": ("tests/data/mjcf/constraints/weld_bodies_torquescale.xml", {}),
    "connect_free_sites": ("tests/data/mjcf/constraints/connect_free_sites.xml", {"a": [0.0, 1.0, 0.0, 0.1, 0.0, 0.0]}),
    "weld_sites": ("tests/data/mjcf/constraints/weld_sites.xml", {}),
    "fourbar_connect": ("tests/data/mjcf/constraints/fourbar_connect.xml", {}),
}


def tight_model(rel: str) -> mj.MjModel:
    copy = cs.tight_copy(ROOT / rel)
    try:
        return mj.MjModel.from_xml_path(str(copy))
    finally:
        copy.unlink()


def moved_force(m: mj.MjModel, d: mj.MjData, body: int, point: np.ndarray) -> list[float]:
    """cfrc_int of `body` about world point `point`, world axes, [torque; force]."""
    out = np.zeros(6)
    mj.mju_transformSpatial(out, d.cfrc_int[body], 1, point, d.subtree_com[m.body_rootid[body]], np.eye(3).ravel())  # identity: world axes
    return out.tolist()


def object_acceleration(m: mj.MjModel, d: mj.MjData, objtype, objid: int) -> list[float]:
    out = np.zeros(6)
    mj.mj_objectAcceleration(m, d, objtype, objid, out, 0)
    return out.tolist()


def scene_doc(index: int, name: str) -> dict:
    rel, xfrc = SCENES[name]
    m = tight_model(rel)
    rng = np.random.default_rng(SEED + index)
    states = []
    for q, v in cs.random_states(mj, m, rng, STATES):
        d = mj.MjData(m)
        d.qpos[:], d.qvel[:] = q, v
        for body, w in xfrc.items():
            d.xfrc_applied[m.body(body).id] = w
        mj.mj_forward(m, d)
        mj.mj_rnePostConstraint(m, d)
        states.append({
            "qpos": q.tolist(), "qvel": v.tolist(), "qacc": d.qacc.tolist(), "qacc_smooth": d.qacc_smooth.tolist(),
            "nefc": int(d.nefc),
            "subtree_com": d.subtree_com.tolist(), "cacc": d.cacc.tolist(),
            "cfrc_int": d.cfrc_int.tolist(), "cfrc_ext": d.cfrc_ext.tolist(),
            "site_xpos": d.site_xpos.tolist(),
            "site_acc": [object_acceleration(m, d, mj.mjtObj.mjOBJ_SITE, s) for s in range(m.nsite)],
            "site_int": [moved_force(m, d, m.site_bodyid[s], d.site_xpos[s]) for s in range(m.nsite)],
            "xpos": d.xpos.tolist(),
            "xbody_acc": [object_acceleration(m, d, mj.mjtObj.mjOBJ_XBODY, b) for b in range(m.nbody)],
        })
    return {
        "generated_by": SCRIPT + " (do not edit)",
        "mujoco": mj.__version__,
        "model": rel,
        "options": "tight copy of validation/crossval_common.py: " + TIGHT.removeprefix("<option "),
        "bodies": [m.body(b).name for b in range(m.nbody)],
        "body_parentid": m.body_parentid.tolist(),
        "body_rootid": m.body_rootid.tolist(),
        "sites": [m.site(s).name for s in range(m.nsite)],
        "site_bodyid": m.site_bodyid.tolist(),
        "xfrc_applied": xfrc,
        "states": states,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="recompute in memory; exit 1 if a file differs")
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    stale = []
    for index, name in enumerate(SCENES):
        doc = scene_doc(index, name)
        text = dump(doc) + "\n"
        out = OUT / f"{name}.json"
        old = out.read_text() if out.exists() else None
        if args.check:
            status = check_status(old, text, doc, CHECK_REL)
            if not status.startswith("ok"):
                stale.append(out.relative_to(ROOT).as_posix())
        else:
            status = "unchanged" if old == text else "written"
            if old != text:
                out.write_text(text)
        nefc = [s["nefc"] for s in doc["states"]]
        print(f"{name:24s} {len(doc['bodies']):3d} bodies {len(doc['sites']):3d} sites  nefc {nefc}  {status}")
    extra = sorted(p.name for p in OUT.glob("*.json") if p.stem not in SCENES)
    for e in extra:
        print(f"{e}: EXTRA, no scene produces it")
    if args.check and (stale or extra):
        print("mj_rnePostConstraint golden data out of date: " + ", ".join(stale + extra), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
