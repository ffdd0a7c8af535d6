#!/usr/bin/env python3
"""Generate MuJoCo golden data for lagrange's MJCF loader and dynamics.

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_golden.py            # (re)write tests/data/mujoco/*.json
    python validation/mujoco_golden.py --check    # exit 1 if any value moved beyond round-off (1e-12 of its quantity)
    python validation/mujoco_golden.py --only fromto --only defaults   # a subset

Models: every hand-written feature file tests/data/mjcf/*.xml (one MJCF feature each; the
files under tests/data/mjcf/include/ are parts of include_nested.xml and the ones under
tests/data/mjcf/errors/ do not load on purpose) and the shipped robots in models/mjcf/
(their robot file, not scene.xml: the scenes only add a floor, lights and textures).

For each model this compiles the file with the `mujoco` package, records the compiled
model (bodies with mass, centre of mass and inertia; joints; sites; keyframes; qpos0;
gravity; timestep) and, at 6 states (qpos0 and 5 random configurations, random velocities
and generalized forces), the joint-space inertia M (mj_fullM, armature included), the bias
forces qfrc_bias (Coriolis + centrifugal + gravity), the forward dynamics
qacc = M^-1 (tau - bias) and the world poses of every body and site. It writes
tests/data/mujoco/<name>.json. Everything is in MuJoCo's conventions, which are lagrange's:
qpos/qvel layout, joint order, quaternions w-first. See validation/README.md.

Deterministic: a fixed seed per model (independent of the other models), floats written
with repr (shortest round trip), keys sorted. Rerunning with the pinned versions
reproduces the committed files byte for byte; --check verifies that.
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

REPO = pathlib.Path(__file__).resolve().parent.parent
FEATURE_DIR = REPO / "tests" / "data" / "mjcf"
OUT_DIR = REPO / "tests" / "data" / "mujoco"

SEED = 20261122
N_RANDOM_STATES = 5  # plus the qpos0 state: 6 states per model

# Shipped robots: golden name -> robot file (relative to the repo root).
ROBOTS = {
    "humanoid": "models/mjcf/humanoid/humanoid.xml",
    "franka_emika_panda": "models/mjcf/franka_emika_panda/panda.xml",
    "unitree_go1": "models/mjcf/unitree_go1/go1.xml",
}

# Pairs of feature files that must compile to the same MuJoCo model (same model written
# with different conventions).
TWINS = [("angle_degree", "angle_radian")]

# Ranges of the random draws for joints without limits.
HINGE_RANGE = (-math.pi, math.pi)
SLIDE_RANGE = (-0.5, 0.5)
FREE_POS_RANGE = (-1.0, 1.0)

# Internal consistency tolerances of the asserts below (MuJoCo against itself / numpy).
SELF_REL = 1e-10

JOINT_TYPES = {
    int(mujoco.mjtJoint.mjJNT_FREE): "free",
    int(mujoco.mjtJoint.mjJNT_BALL): "ball",
    int(mujoco.mjtJoint.mjJNT_SLIDE): "slide",
    int(mujoco.mjtJoint.mjJNT_HINGE): "hinge",
}
JOINT_NQ = {"free": 7, "ball": 4, "slide": 1, "hinge": 1}
JOINT_NV = {"free": 6, "ball": 3, "slide": 1, "hinge": 1}

# Everything except the smooth dynamics off, for the qacc_smooth cross-check: constraints
# (limits, contacts, equality, friction loss), springs, dampers, actuators.
DISABLE_FOR_CHECK = (
    mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    | mujoco.mjtDisableBit.mjDSBL_SPRING
    | mujoco.mjtDisableBit.mjDSBL_DAMPER
    | mujoco.mjtDisableBit.mjDSBL_ACTUATION
    | mujoco.mjtDisableBit.mjDSBL_CONTACT
)

NOTES = [
    "M = mj_fullM (joint-space inertia with dof_armature on the diagonal); bias = qfrc_bias "
    "(RNE with zero acceleration: Coriolis + centrifugal + gravity, no springs/dampers); "
    "qacc = M^-1 (tau - bias) via mj_solveM (not mj_forward's qacc, which adds passive and "
    "constraint forces)",
    "q/v in MuJoCo's qpos/qvel layout: free = [x y z qw qx qy qz] / [world linear velocity "
    "of the body origin, body-frame angular velocity]; ball = [qw qx qy qz] / body-frame "
    "angular velocity",
    "bodies[i].com = body_ipos (body frame); bodies[i].inertia = R(body_iquat) "
    "diag(body_inertia) R^T about the centre of mass in body axes; for a massless body "
    "MuJoCo's body_ipos is meaningless (it equals body_pos)",
    "quaternions are w-first, canonicalized to w >= 0 (compare rotations up to sign)",
    "unnamed bodies/joints/sites are named body{id}/joint{id}/site{id} with MuJoCo's ids "
    "(field 'mujoco_name' is the name in the file, empty if none)",
    "state 0 is q = qpos0 (every body in the pose written in the file); states 1.. are random",
    "keyframes: qpos/qvel are MuJoCo's compiled key_qpos/key_qvel (always nq/nv long: "
    "missing values come from qpos0 / zeros; quaternions normalized); qpos_file/qvel_file "
    "are the values written in the file (null if the attribute is absent)",
]


# --------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------


def floats(a) -> list:
    """A numpy array (any shape) as nested lists of Python floats."""
    return np.asarray(a, dtype=float).tolist()


def canonical_quat(q) -> list[float]:
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q)
    if q[0] < 0:
        q = -q
    return [float(x) for x in q]


def quat_to_mat(q) -> np.ndarray:
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, np.asarray(q, dtype=float))
    return m.reshape(3, 3)


def mat_to_quat(mat) -> list[float]:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.asarray(mat, dtype=float).reshape(9))
    return canonical_quat(q)


def random_unit_quat(rng) -> np.ndarray:
    """Uniformly random rotation: a normalized 4-D Gaussian, sign w >= 0."""
    while True:
        q = rng.standard_normal(4)
        n = np.linalg.norm(q)
        if n > 1e-6:
            q = q / n
            return -q if q[0] < 0 else q


def rel_err(a, b) -> float:
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    scale = max(np.abs(a).max(initial=0.0), np.abs(b).max(initial=0.0), 1e-300)
    return float(np.abs(a - b).max(initial=0.0) / scale)


def name_or(kind: int, m: mujoco.MjModel, i: int, prefix: str) -> tuple[str, str]:
    """(lagrange name, MuJoCo name) of object i: unnamed objects are '<prefix><id>'."""
    raw = mujoco.mj_id2name(m, kind, i) or ""
    return (raw if raw else "%s%d" % (prefix, i)), raw


def dump(obj, indent: int = 0) -> str:
    """Deterministic JSON: sorted keys, one dict entry per line, lists of numbers on one
    line, lists of lists one row per line, floats with repr (json's default)."""
    pad, inner = "  " * indent, "  " * (indent + 1)

    def flat(x) -> bool:
        return not isinstance(x, (list, dict))

    if isinstance(obj, dict):
        if not obj:
            return "{}"
        items = [inner + json.dumps(k) + ": " + dump(obj[k], indent + 1) for k in sorted(obj)]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, list):
        if all(flat(x) for x in obj):
            return json.dumps(obj)
        if all(isinstance(x, list) and all(flat(y) for y in x) for x in obj):
            rows = [inner + json.dumps(x) for x in obj]
        else:
            rows = [inner + dump(x, indent + 1) for x in obj]
        return "[\n" + ",\n".join(rows) + "\n" + pad + "]"
    if isinstance(obj, float):
        assert math.isfinite(obj), "non-finite float"
    return json.dumps(obj)


# --------------------------------------------------------------------------------------
# One model
# --------------------------------------------------------------------------------------


def load(path: pathlib.Path) -> tuple[mujoco.MjModel, list[str]]:
    """Compiles `path`, collecting MuJoCo's warnings (instead of MUJOCO_LOG.TXT)."""
    warnings: list[str] = []
    mujoco.set_mju_user_warning(lambda msg: warnings.append(str(msg)))
    try:
        m = mujoco.MjModel.from_xml_path(str(path))
    finally:
        mujoco.set_mju_user_warning(None)
    return m, warnings


def model_doc(m: mujoco.MjModel, path: pathlib.Path) -> dict:
    """Static description of the compiled model."""
    obj = mujoco.mjtObj
    body_names = [name_or(obj.mjOBJ_BODY, m, i, "body") for i in range(m.nbody)]

    bodies = []
    for i in range(m.nbody):
        name, raw = body_names[i]
        r = quat_to_mat(m.body_iquat[i])
        inertia = r @ np.diag(m.body_inertia[i]) @ r.T
        inertia = 0.5 * (inertia + inertia.T)
        bodies.append(
            {
                "id": i,
                "name": name,
                "mujoco_name": raw,
                "parent": body_names[m.body_parentid[i]][0],
                "mass": float(m.body_mass[i]),
                "com": floats(m.body_ipos[i]),
                "inertia": floats(inertia),
                "principal_inertia": floats(m.body_inertia[i]),
                "iquat": canonical_quat(m.body_iquat[i]),
                "pos": floats(m.body_pos[i]),
                "quat": canonical_quat(m.body_quat[i]),
                "njnt": int(m.body_jntnum[i]),
            }
        )

    joints = []
    for j in range(m.njnt):
        name, raw = name_or(obj.mjOBJ_JOINT, m, j, "joint")
        jtype = JOINT_TYPES[int(m.jnt_type[j])]
        qa, da = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
        limited = bool(m.jnt_limited[j]) and jtype in ("hinge", "slide", "ball")
        joints.append(
            {
                "id": j,
                "name": name,
                "mujoco_name": raw,
                "type": jtype,
                "body": body_names[m.jnt_bodyid[j]][0],
                "qposadr": qa,
                "dofadr": da,
                "nq": JOINT_NQ[jtype],
                "nv": JOINT_NV[jtype],
                "axis": floats(m.jnt_axis[j]),
                "pos": floats(m.jnt_pos[j]),
                "limited": limited,
                "range": floats(m.jnt_range[j]) if limited else None,
                "armature": floats(m.dof_armature[da : da + JOINT_NV[jtype]]),
                "qpos0": floats(m.qpos0[qa : qa + JOINT_NQ[jtype]]),
            }
        )
    assert [j["qposadr"] for j in joints] == sorted(j["qposadr"] for j in joints)

    sites = []
    for s in range(m.nsite):
        name, raw = name_or(obj.mjOBJ_SITE, m, s, "site")
        sites.append(
            {
                "id": s,
                "name": name,
                "mujoco_name": raw,
                "body": body_names[m.site_bodyid[s]][0],
                "pos": floats(m.site_pos[s]),
                "quat": canonical_quat(m.site_quat[s]),
            }
        )

    # Keyframes as compiled, and as written in the file (from the spec, before compiling).
    spec = mujoco.MjSpec.from_file(str(path))
    assert len(spec.keys) == m.nkey
    keyframes = []
    for k in range(m.nkey):
        sk = spec.keys[k]
        qpos_file = [float(x) for x in sk.qpos]
        qvel_file = [float(x) for x in sk.qvel]
        keyframes.append(
            {
                "name": mujoco.mj_id2name(m, obj.mjOBJ_KEY, k) or "",
                "time": float(m.key_time[k]),
                "qpos": floats(m.key_qpos[k]),
                "qvel": floats(m.key_qvel[k]),
                "qpos_file": qpos_file if qpos_file else None,
                "qvel_file": qvel_file if qvel_file else None,
            }
        )

    return {
        "nq": int(m.nq),
        "nv": int(m.nv),
        "nbody": int(m.nbody),
        "njnt": int(m.njnt),
        "gravity": floats(m.opt.gravity),
        "timestep": float(m.opt.timestep),
        "qpos0": floats(m.qpos0),
        "dof_armature": floats(m.dof_armature),
        "total_mass": float(m.body_mass[1:].sum()),
        "joint_names": [j["name"] for j in joints],
        "bodies": bodies,
        "joints": joints,
        "sites": sites,
        "keyframes": keyframes,
    }


def random_state(m: mujoco.MjModel, rng, at_qpos0: bool):
    """(q, v, tau): q inside the joint ranges (see module docstring), v and tau N(0, 1)."""
    q = m.qpos0.copy()
    if not at_qpos0:
        for j in range(m.njnt):
            jtype = JOINT_TYPES[int(m.jnt_type[j])]
            a = m.jnt_qposadr[j]
            if jtype == "free":
                q[a : a + 3] = rng.uniform(*FREE_POS_RANGE, size=3)
                q[a + 3 : a + 7] = random_unit_quat(rng)
            elif jtype == "ball":
                q[a : a + 4] = random_unit_quat(rng)
            else:
                if m.jnt_limited[j]:
                    lo, hi = m.jnt_range[j]
                else:
                    lo, hi = HINGE_RANGE if jtype == "hinge" else SLIDE_RANGE
                q[a] = rng.uniform(lo, hi)
    v = rng.standard_normal(m.nv)
    tau = rng.standard_normal(m.nv)
    return q, v, tau


def state_doc(m: mujoco.MjModel, d: mujoco.MjData, q, v, tau) -> dict:
    nv = m.nv
    d.qpos[:] = q
    d.qvel[:] = v
    d.qfrc_applied[:] = tau
    d.ctrl[:] = 0
    mujoco.mj_forward(m, d)

    big_m = np.zeros((nv, nv))
    mujoco.mj_fullM(m, d, big_m)
    bias = d.qfrc_bias.copy()
    qacc = np.zeros(nv)
    if nv:
        mujoco.mj_solveM(m, d, qacc.reshape(1, nv), (tau - bias).reshape(1, nv))

    # Consistency of what is written (MuJoCo against numpy and against itself).
    if nv:
        assert rel_err(big_m, big_m.T) <= SELF_REL, "M not symmetric"
        assert np.linalg.eigvalsh(big_m).min() > 0, "M not positive definite"
        assert rel_err(np.linalg.solve(big_m, tau - bias), qacc) <= SELF_REL, "mj_solveM vs numpy"
        assert rel_err(big_m @ qacc + bias, tau) <= SELF_REL, "M qacc + bias != tau"
        # With passive forces, actuation and constraints disabled (see DISABLE_FOR_CHECK),
        # mj_forward's smooth acceleration is the same forward dynamics.
        assert rel_err(d.qacc_smooth, qacc) <= SELF_REL, "qacc_smooth vs mj_solveM"

    xquat = [canonical_quat(x) for x in d.xquat]
    for i in range(m.nbody):
        assert rel_err(quat_to_mat(d.xquat[i]), d.xmat[i].reshape(3, 3)) <= SELF_REL
    return {
        "q": floats(q),
        "v": floats(v),
        "tau": floats(tau),
        "M": floats(big_m),
        "bias": floats(bias),
        "qacc": floats(qacc),
        "xpos": floats(d.xpos),
        "xquat": xquat,
        "site_xpos": floats(d.site_xpos),
        "site_xquat": [mat_to_quat(x) for x in d.site_xmat],
    }


def golden(name: str, rel_path: str, kind: str) -> str:
    path = REPO / rel_path
    m, warnings = load(path)
    m.opt.disableflags |= DISABLE_FOR_CHECK  # only affects the qacc_smooth cross-check
    d = mujoco.MjData(m)
    rng = np.random.default_rng([SEED, zlib.crc32(name.encode())])

    doc = {
        "name": name,
        "kind": kind,
        "model": rel_path,
        "generator": "mujoco %s" % mujoco.__version__,
        "seed": [SEED, zlib.crc32(name.encode())],
        "notes": NOTES,
        "warnings": warnings,
    }
    doc.update(model_doc(m, path))
    states = []
    for s in range(1 + N_RANDOM_STATES):
        q, v, tau = random_state(m, rng, at_qpos0=(s == 0))
        states.append(state_doc(m, d, q, v, tau))
    doc["states"] = states
    text = dump(doc) + "\n"
    assert json.loads(text) == json.loads(json.dumps(doc)), "dump() lost information"
    return text


# Relative difference below which a recomputed number counts as reproduced (the algorithms'
# cross-check level; the Rust tests compare lagrange with this data at 1e-9).
CHECK_REL = 1e-12


def _magnitude(x) -> float:
    """Largest |number| in a JSON value (0 for none)."""
    if isinstance(x, dict):
        return max((_magnitude(v) for v in x.values()), default=0.0)
    if isinstance(x, list):
        return max((_magnitude(v) for v in x), default=0.0)
    if isinstance(x, (int, float)) and not isinstance(x, bool):
        return abs(x)
    return 0.0


def check_status(old: str | None, text: str, doc, rel: float) -> str:
    """The --check verdict of a reference-data script on one file: "ok" when the committed text
    `old` equals the recomputed `text`, "ok (round-off …)" when they differ by at most `rel`
    (roundoff_difference), else "MISSING" or "DIFFERS"."""
    if old == text:
        return "ok"
    if old is None:
        return "MISSING"
    worst = roundoff_difference(json.loads(old), doc)
    return "DIFFERS" if worst is None or worst > rel else f"ok (round-off {worst:.1e})"


def roundoff_difference(a, b, scale: float = 0.0) -> float | None:
    """Largest relative difference between two JSON documents of the same structure, or None when
    keys, lengths, strings or types differ. Each number is measured against the largest magnitude
    of the quantity it belongs to (a dict entry: a matrix, a vector, a scalar), as the Rust tests
    measure errors, so that entries that are zero up to round-off do not count as relative 1."""
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            return None
        parts = [roundoff_difference(a[k], b[k], max(_magnitude(a[k]), _magnitude(b[k]))) for k in a]
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return None
        parts = [roundoff_difference(x, y, scale) for x, y in zip(a, b)]
    elif isinstance(a, bool) or isinstance(b, bool) or not isinstance(a, (int, float)) or not isinstance(b, (int, float)):
        return 0.0 if a == b else None
    else:
        return abs(a - b) / max(scale, abs(a), abs(b), 1e-300) if a != b else 0.0
    if any(p is None for p in parts):
        return None
    return max(parts, default=0.0)


def check_twins() -> None:
    """Twin feature files compile to the same MuJoCo model."""
    fields = [
        "body_pos", "body_quat", "body_mass", "body_ipos", "body_iquat", "body_inertia",
        "jnt_pos", "jnt_axis", "jnt_range", "qpos0", "qpos_spring", "dof_armature",
        "geom_pos", "geom_quat", "geom_size", "key_qpos", "key_qvel",
    ]
    for a, b in TWINS:
        ma, _ = load(FEATURE_DIR / (a + ".xml"))
        mb, _ = load(FEATURE_DIR / (b + ".xml"))
        for f in fields:
            x, y = getattr(ma, f), getattr(mb, f)
            assert x.shape == y.shape, "%s/%s: %s shapes differ" % (a, b, f)
            assert np.abs(x - y).max(initial=0.0) <= 1e-12, "%s/%s: %s differ" % (a, b, f)


def models() -> list[tuple[str, str, str]]:
    """(name, path relative to the repo, kind) of every model, features first."""
    out = []
    for p in sorted(FEATURE_DIR.glob("*.xml")):
        out.append((p.stem, p.relative_to(REPO).as_posix(), "feature"))
    for name, rel in ROBOTS.items():
        out.append((name, rel, "robot"))
    names = [n for n, _, _ in out]
    assert len(set(n.lower() for n in names)) == len(names), "duplicate (case-insensitive) names"
    return out


def ours(path: pathlib.Path) -> bool:
    """Whether a JSON file in OUT_DIR was written by this script (other scripts share the
    folder, e.g. validation/mujoco_mesh_golden.py writes meshes.json)."""
    try:
        doc = json.loads(path.read_text())
    except (OSError, ValueError):
        return False
    return isinstance(doc, dict) and doc.get("kind") in ("feature", "robot") and "states" in doc


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="exit 1 if any file would change")
    ap.add_argument("--only", action="append", default=[], help="only this model (repeatable)")
    args = ap.parse_args()

    check_twins()
    todo = [t for t in models() if not args.only or t[0] in args.only]
    unknown = set(args.only) - {t[0] for t in todo}
    if unknown:
        print("unknown model(s): %s" % ", ".join(sorted(unknown)), file=sys.stderr)
        return 2

    OUT_DIR.mkdir(parents=True, exist_ok=True)
    stale = []
    for name, rel, kind in todo:
        text = golden(name, rel, kind)
        out = OUT_DIR / (name + ".json")
        assert not out.exists() or ours(out), "%s was not written by this script" % out
        old = out.read_text() if out.exists() else None
        if args.check:
            if old == text:
                status = "ok"
            elif old is None:
                status = "missing"
            else:
                # MuJoCo's floating-point results differ in the last bits between machines (CPU
                # code paths); the data must agree in structure exactly and in value to round-off.
                worst = roundoff_difference(json.loads(old), json.loads(text))
                status = "DIFFERS" if worst is None or worst > CHECK_REL else "ok (round-off %.1e)" % worst
            if status not in ("ok",) and not status.startswith("ok ("):
                stale.append(out.relative_to(REPO).as_posix())
        else:
            status = "unchanged" if old == text else "written"
            if old != text:
                out.write_text(text)
        print("%-24s %-8s %-9s %s" % (name, kind, status, out.relative_to(REPO).as_posix()))

    if not args.only:
        expected = {t[0] + ".json" for t in todo}
        extra = sorted(p.name for p in OUT_DIR.glob("*.json") if p.name not in expected and ours(p))
        for e in extra:
            print("%-24s %-8s %-9s %s" % (e, "", "EXTRA", "no model produces it"))
        if args.check:
            stale += extra

    if args.check and stale:
        print("golden data out of date: %s" % ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
