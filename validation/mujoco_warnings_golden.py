#!/usr/bin/env python3
"""MuJoCo 4.0's corrected results for a singular mass matrix and for bad controls.

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_warnings_golden.py            # (re)write tests/data/mujoco/warnings.json
    python validation/mujoco_warnings_golden.py --check    # recompute, exit 1 if the file moved beyond 1e-12

tests/data/mjcf/warnings/dup_hinges.xml: duplicated hinges make M singular at every state; MuJoCo
raises the factor's pivot below mjMINVAL to mjMINVAL and warns mjWARN_INERTIA (lastinfo: a dof),
giving finite accelerations (zero along the lost direction when no force acts on it, ~1e14 when
one does). bad_ctrl.xml: MuJoCo clamps each control to its ctrlrange, then if any is NaN or beyond
mjMAXVAL = 1e10 zeroes all of them and warns mjWARN_BADCTRL (lastinfo: the first bad actuator).
Per case: qpos, qvel, ctrl, qfrc_applied in; qacc, actuator_force and the two warnings' number and
lastinfo out (after one mj_forward on fresh data).
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys

import mujoco

REPO = pathlib.Path(__file__).resolve().parent.parent
OUT = REPO / "tests/data/mujoco/warnings.json"
SCRIPT = "validation/mujoco_warnings_golden.py"
CHECK_REL = 1e-12
NAN = float("nan")

CASES = {
    "dup_hinges.xml": [
        dict(qpos=[0.3, -0.2, 0.1, 0.2, -0.4], qvel=[0.5, -0.1, 0.2, 0.0, 0.3], qfrc_applied=[0, 0, 0, 0, 0]),
        dict(qpos=[0.3, -0.2, 0.1, 0.2, -0.4], qvel=[0, 0, 0, 0, 0], qfrc_applied=[0.3, 0, 0, 0, 0]),
    ],
    "bad_ctrl.xml": [
        dict(ctrl=[0.5, 0.5]),
        dict(ctrl=[NAN, 0.5]),
        dict(ctrl=[0.5, NAN]),
        dict(ctrl=[1e300, 0.5]),
        dict(ctrl=[0.5, 1e300]),
        dict(ctrl=[-math.inf, 0.5]),
        dict(ctrl=[2e10, 0.5]),
        dict(ctrl=[9e9, 0.5]),
    ],
}


def finite(x):
    """JSON has no NaN/inf: inputs are written as strings."""
    return x if math.isfinite(x) else repr(x)


def golden() -> dict:
    files = []
    for name, cases in CASES.items():
        m = mujoco.MjModel.from_xml_path(str(REPO / "tests/data/mjcf/warnings" / name))
        out = []
        for c in cases:
            d = mujoco.MjData(m)
            if "qpos" in c:
                d.qpos[:] = c["qpos"]
                d.qvel[:] = c["qvel"]
                d.qfrc_applied[:] = c["qfrc_applied"]
            if "ctrl" in c:
                d.ctrl[:] = c["ctrl"]
            mujoco.mj_forward(m, d)
            w = d.warning
            out.append({
                "qpos": d.qpos.tolist(), "qvel": d.qvel.tolist(), "qfrc_applied": d.qfrc_applied.tolist(),
                "ctrl": [finite(x) for x in d.ctrl.tolist()],
                "qacc": d.qacc.tolist(), "actuator_force": d.actuator_force.tolist(),
                "inertia_warnings": int(w[mujoco.mjtWarning.mjWARN_INERTIA].number),
                "inertia_lastinfo": int(w[mujoco.mjtWarning.mjWARN_INERTIA].lastinfo),
                "badctrl_warnings": int(w[mujoco.mjtWarning.mjWARN_BADCTRL].number),
                "badctrl_lastinfo": int(w[mujoco.mjtWarning.mjWARN_BADCTRL].lastinfo),
            })
        files.append({"file": name, "cases": out})
    return {"generated": f"by {SCRIPT} with mujoco {mujoco.__version__}; do not edit (rerun the script)",
            "models": files}


def worst_difference(old, new) -> float:
    """Largest difference of the numbers, relative to each list's largest magnitude; inf on a
    structural change."""
    if isinstance(old, dict) and isinstance(new, dict):
        if old.keys() != new.keys():
            return math.inf
        return max([worst_difference(old[k], new[k]) for k in old] + [0.0])
    if isinstance(old, list) and isinstance(new, list):
        if len(old) != len(new):
            return math.inf
        if all(isinstance(x, (int, float)) for x in old + new):
            scale = max([abs(x) for x in old + new] + [1e-300])
            return max([abs(a - b) / scale for a, b in zip(old, new)] + [0.0])
        return max([worst_difference(a, b) for a, b in zip(old, new)] + [0.0])
    return 0.0 if old == new else math.inf


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="recompute in memory; exit 1 if the file differs")
    args = ap.parse_args()
    doc = golden()
    text = json.dumps(doc, indent=1, sort_keys=True) + "\n"
    if args.check:
        if not OUT.exists():
            print(f"{OUT.relative_to(REPO)} MISSING", file=sys.stderr)
            return 1
        worst = worst_difference(json.loads(OUT.read_text()), doc)
        print(f"{OUT.relative_to(REPO)}: worst relative difference {worst:.1e}")
        return 0 if worst <= CHECK_REL else 1
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(text)
    print(f"wrote {OUT.relative_to(REPO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
