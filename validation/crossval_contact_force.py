"""lagrange's `contact_force` against MuJoCo's `mj_contactForce`, contact by contact.

Scenes: go1 on its floor (elliptic cones, condim 3 and friction loss) and pyramidal scenes (the
dm_control humanoid, the textbook drop, the soft test scene with condim 1/3/4/6 on pyramidal
cones). A copy of each with a Newton solve run to round-off (crossval_soft's `tight_copy`, with
tolerance 1e-30) is evaluated by
`lagrange eval --constraints soft` and by MuJoCo's `mj_forward` at the same states (keyframes,
snapshots of MuJoCo's own run, perturbations); contacts are matched by geom pair and position,
and each contact's 6-vector (normal, two tangents, torsion, two rolling; contact frame) is
compared relative to the state's largest contact force. Tolerance: 1e-9 relative (both solvers
converge to the unique optimum of the soft problem; the decoding of pyramid edges is exact).

Exit status 1 on a difference beyond tolerance. Usage:
  python validation/crossval_contact_force.py --lagrange target/release/lagrange
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import crossval_common  # noqa: E402
from crossval_soft import ROOT, lagrange_eval, match_contacts, random_states, tight_copy  # noqa: E402

# Both Newton solves run to round-off (tolerance 1e-30 never stops them early): at crossval_soft's
# 1e-15, sliding elliptic contacts on go1 stop up to 1.4e-9 apart (10 against 14 iterations), a
# difference of convergence, not of the contact force's definition.
crossval_common.TIGHT = crossval_common.TIGHT.replace('tolerance="1e-15"', 'tolerance="1e-30"').replace(
    'ls_tolerance="1e-12"', 'ls_tolerance="1e-15"')

REL_CONTACT_FORCE = 1e-9
SCENES = [
    ("go1 (elliptic, keyframe home)", ROOT / "models/mjcf/unitree_go1/scene.xml"),
    ("humanoid (dm_control, pyramidal)", ROOT / "models/mjcf/humanoid/humanoid.xml"),
    ("drop (pyramidal)", ROOT / "models/textbook/drop.xml"),
    ("soft/features_pyramidal (condim 1/3/4/6, pyramidal)", ROOT / "tests/data/mjcf/soft/features_pyramidal.xml"),
]


def main() -> int:
    import mujoco as mj

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lagrange", default=str(ROOT / "target/release/lagrange"))
    ap.add_argument("--states", type=int, default=12)
    args = ap.parse_args()
    failed = 0
    print(f"{'scene':<56} {'contacts':>8} {'cone':>10} {'worst rel':>10}")
    for name, path in SCENES:
        scene = tight_copy(path)
        try:
            m = mj.MjModel.from_xml_path(str(scene))
            d = mj.MjData(m)
            rng = np.random.default_rng(7)
            states = random_states(mj, m, rng, args.states)
            results = lagrange_eval(Path(args.lagrange), scene, states)
            worst, count = 0.0, 0
            for (q, v), res in zip(states, results):
                d.qpos[:], d.qvel[:] = q, v
                mj.mj_forward(m, d)
                ours = res["forward"]["efc"]["contacts"] if res["forward"].get("efc") else []
                matched, geometry = match_contacts(ours, d)
                theirs = np.zeros((d.ncon, 6))
                for i in range(d.ncon):
                    mj.mj_contactForce(m, d, i, theirs[i])
                scale = max(float(np.max(np.abs(theirs))) if d.ncon else 0.0, 1e-300)
                for i, k in enumerate(matched):
                    if k is None:
                        worst = math.inf
                        continue
                    f = np.array(ours[k]["contact_force"])
                    # A contact stored with its geoms the other way round has the opposite normal
                    # and first tangent (MuJoCo's frame is made from the normal).
                    if list(ours[k]["geom_ids"]) != [int(d.contact[i].geom[0]), int(d.contact[i].geom[1])]:
                        f = f * np.array([1, -1, 1, 1, 1, 1])
                    worst = max(worst, float(np.max(np.abs(f - theirs[i]))) / scale)
                    count += 1
                if geometry > 1e-9:
                    print(f"  note: contact geometry differs by {geometry:.1e}")
            cone = "pyramidal" if m.opt.cone == mj.mjtCone.mjCONE_PYRAMIDAL else "elliptic"
            ok = worst <= REL_CONTACT_FORCE and count > 0
            failed += not ok
            print(f"{name:<56} {count:>8} {cone:>10} {worst:>10.1e} {'ok' if ok else 'FAIL'}")
        finally:
            scene.unlink(missing_ok=True)
    total = len(SCENES)
    print(f"contact_force: {total - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
