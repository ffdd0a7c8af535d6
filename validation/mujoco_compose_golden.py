#!/usr/bin/env python3
"""MuJoCo's names and counts of the composed models (<attach>, <replicate>), for tests/compose_mujoco.rs.

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_compose_golden.py            # (re)write tests/data/mujoco/compose/*.json
    python validation/mujoco_compose_golden.py --check    # recompute in memory, exit 1 if a file differs

For each tests/data/mjcf/compose_*.xml (the attached sub-models live in tests/data/mjcf/compose/):
MuJoCo 4.0's compiled names, in its order, of bodies (with parents), joints, geoms, sites,
tendons, actuators and sensors, the number of equality constraints and the excluded body pairs by
name. The bodies, masses, joints, qpos0 and the dynamics (M, qfrc_bias, qacc) of the same files
are in tests/data/mujoco/compose_*.json (validation/mujoco_golden.py, tests/mujoco.rs).
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

import mujoco

REPO = pathlib.Path(__file__).resolve().parent.parent
SRC_DIR = REPO / "tests" / "data" / "mjcf"
OUT_DIR = REPO / "tests" / "data" / "mujoco" / "compose"
SCRIPT = "validation/mujoco_compose_golden.py"


def names(m, obj, n) -> list[str]:
    return [mujoco.mj_id2name(m, obj, i) or "" for i in range(n)]


def golden(path: pathlib.Path) -> str:
    m = mujoco.MjModel.from_xml_path(str(path))
    o = mujoco.mjtObj
    bodies = names(m, o.mjOBJ_BODY, m.nbody)
    doc = {
        "generated": f"by {SCRIPT} with mujoco {mujoco.__version__}; do not edit (rerun the script)",
        "model": path.relative_to(REPO).as_posix(),
        "bodies": bodies,
        "body_parents": [bodies[int(p)] for p in m.body_parentid],
        "joints": names(m, o.mjOBJ_JOINT, m.njnt),
        "geoms": names(m, o.mjOBJ_GEOM, m.ngeom),
        "geom_bodies": [bodies[int(b)] for b in m.geom_bodyid],
        "sites": names(m, o.mjOBJ_SITE, m.nsite),
        "tendons": names(m, o.mjOBJ_TENDON, m.ntendon),
        "actuators": names(m, o.mjOBJ_ACTUATOR, m.nu),
        "sensors": names(m, o.mjOBJ_SENSOR, m.nsensor),
        "neq": int(m.neq),
        "excludes": [[bodies[s >> 16], bodies[s & 0xFFFF]] for s in (int(x) for x in m.exclude_signature)],
    }
    return json.dumps(doc, indent=1, sort_keys=True) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="recompute in memory; exit 1 if a file differs")
    args = ap.parse_args()
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    stale = []
    for src in sorted(SRC_DIR.glob("compose_*.xml")):
        text = golden(src)
        out = OUT_DIR / (src.stem + ".json")
        old = out.read_text() if out.exists() else None
        if args.check:
            status = "ok" if old == text else "DIFFERS"
            if old != text:
                stale.append(out.relative_to(REPO).as_posix())
        else:
            status = "unchanged" if old == text else "written"
            if old != text:
                out.write_text(text)
        print("%-22s %-9s %s" % (src.stem, status, out.relative_to(REPO).as_posix()))
    if args.check and stale:
        print("compose golden data out of date: %s" % ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
