#!/usr/bin/env python3
"""Exact-mode frictional point contacts: lagrange's `eval --constraints exact` against Pinocchio's
constrained dynamics and a rigid KKT solve on MuJoCo's own quantities.

Scenes (MJCF, floors and inclines): the Menagerie go1 on its floor (a copy with the feet at
condim 3, point contacts with sliding friction, since Pinocchio's point contacts have no
torsional or rolling friction), the textbook box resting on a 20° incline (four corners), and the
textbook cylinder on a 30° incline (docs/physics.md §2.5). Each is evaluated at rest (v = 0) at states where
its contacts touch exactly: the go1 at its home keyframe with random joint perturbations, the base
height and tilt and one knee solved so that all four feet touch the floor.

For the contacts lagrange reports (`forward.constraints` entries of kind "contact": geoms, pos,
frame, force) the references build their own rows at the same points:

1. **Pinocchio** (4.1): `RigidConstraintModel` CONTACT_3D between the two bodies at each contact
   point (LOCAL_WORLD_ALIGNED), solved by `constraintDynamics` — the rigid, sticking contact. The
   tree is rebuilt from MuJoCo's compiled model (Pinocchio's MJCF reader keeps one tree).
2. **MuJoCo-KKT**: M = mj_fullM, qfrc_bias, and J = the difference of the two bodies' point
   Jacobians (mj_jac) at each contact, J̇v = 0 at rest; [M Jᵀ; J 0] solved by least squares
   (minimum-norm forces when rows are redundant).

lagrange's solution is Coulomb's: it equals the sticking one when every contact force lies inside
its friction cone, which is checked (and reported) first. Pass criteria per state: qacc within
1e-8 (max|Δ| / max(1, max|ref|)) of both references; where the contact rows are independent
(rank of J = number of rows), every contact force (world frame, on the second geom's body) within
1e-8 of both references' (relative to the largest force); else the summed contact force; contact
positions within 1e-9 m of MuJoCo's own contacts for the pairs MuJoCo reports.

    validation/crossval_contacts                  # table + "Contacts" section of validation/report.md
    validation/crossval_contacts --no-report

Exit status 1 on any failure.
"""

from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from crossval_common import lagrange_eval_json, quat_wxyz_to_mat  # noqa: E402
from crossval_constraints import pin_model_from_mujoco, rel_to_ref  # noqa: E402
from crossval_corpus import REPO  # noqa: E402

SEED = 20261124
N_STATES = 4
QACC_TOL = 1e-8
FORCE_TOL = 1e-8
POS_TOL = 1e-9
SECTION = "## Contacts"


def go1_condim3(tmp: Path) -> Path:
    """A copy of the shipped go1 scene whose foot class has condim 3 (next to the original, so
    its mesh paths resolve)."""
    src = REPO / "models" / "mjcf" / "unitree_go1"
    dst = tmp / "unitree_go1"
    shutil.copytree(src, dst)
    go1 = (dst / "go1.xml").read_text()
    go1, n = re.subn(r'(<default class="foot">\s*<geom[^>]*?)condim="6"', r'\1condim="3"', go1)
    if n != 1:
        raise RuntimeError("go1.xml: the foot class's condim was not found")
    (dst / "go1.xml").write_text(go1)
    return dst / "scene.xml"


def touching_go1_state(mj, m, rng) -> np.ndarray:
    """The home keyframe with joint perturbations, then Newton on (base z, roll, pitch, RR knee)
    until the four foot spheres touch the floor z = 0 to 1e-14 m."""
    key = m.key("home").id
    q = m.key_qpos[key].copy()
    q[7:] += rng.uniform(-0.08, 0.08, m.nq - 7)
    feet = [m.geom(n).id for n in ("FR", "FL", "RR", "RL")]
    knee = m.jnt_qposadr[m.joint("RR_calf_joint").id]
    d = mj.MjData(m)

    def heights(x):
        qq = q.copy()
        qq[2] = x[0]
        roll, pitch = x[1], x[2]
        cr, sr, cp, sp = np.cos(roll / 2), np.sin(roll / 2), np.cos(pitch / 2), np.sin(pitch / 2)
        qq[3:7] = [cr * cp, sr * cp, cr * sp, -sr * sp]
        qq[knee] = x[3]
        d.qpos[:] = qq
        mj.mj_kinematics(m, d)
        return np.array([d.geom_xpos[g][2] - m.geom_size[g][0] for g in feet]), qq

    x = np.array([q[2], 0.0, 0.0, q[knee]])
    for _ in range(50):
        h, qq = heights(x)
        if np.max(np.abs(h)) < 1e-14:
            return qq
        J = np.zeros((4, 4))
        for k in range(4):
            dx = np.zeros(4)
            dx[k] = 1e-7
            J[:, k] = (heights(x + dx)[0] - heights(x - dx)[0]) / 2e-7
        x = x - np.linalg.solve(J, h)
    raise RuntimeError("go1: the feet could not be put on the floor (max height %.2e)" % np.max(np.abs(h)))


def lagrange_eval(binary: Path, scene: Path, states: list[dict]) -> list[dict]:
    # Contacts only: limits, friction loss and actuators are off on every side.
    return lagrange_eval_json(binary, scene, states, ["--constraints", "exact", "--disable", "limit", "--disable",
                                                      "frictionloss", "--disable", "actuation", "--disable",
                                                      "equality"])["results"]


class References:
    """MuJoCo's M, bias and point Jacobians, and Pinocchio's tree, for one scene."""

    def __init__(self, mj, pin, scene: Path):
        self.mj, self.pin = mj, pin
        m = mj.MjModel.from_xml_path(str(scene))
        D = mj.mjtDisableBit
        for bit in ("mjDSBL_FRICTIONLOSS", "mjDSBL_LIMIT", "mjDSBL_ACTUATION", "mjDSBL_EQUALITY"):
            m.opt.disableflags |= int(getattr(D, bit))
        self.m, self.d = m, mj.MjData(m)
        self.pmodel, self.place, self.jids = pin_model_from_mujoco(pin, m)
        self.pdata = self.pmodel.createData()
        # MuJoCo's dofs and Pinocchio's: the same tree order, joint by joint.
        self.vmap = np.zeros(m.nv, dtype=int)
        for j, jid in self.jids.items():
            jm = self.pmodel.joints[jid]
            da = int(m.jnt_dofadr[j])
            self.vmap[da : da + jm.nv] = range(jm.idx_v, jm.idx_v + jm.nv)

    def geom_body(self, name: str) -> int:
        return int(self.m.geom_bodyid[self.m.geom(name).id])

    def at(self, q):
        mj, m, d = self.mj, self.m, self.d
        d.qpos[:] = q
        d.qvel[:] = 0
        mj.mj_forward(m, d)
        M = np.zeros((m.nv, m.nv))
        mj.mj_fullM(m, d, M)
        return M, d.qfrc_bias.copy()

    def point_rows(self, body1: int, body2: int, p) -> np.ndarray:
        """3 × nv: the velocity of body2's material point at p minus body1's, world axes."""
        mj, m, d = self.mj, self.m, self.d
        rows = np.zeros((3, m.nv))
        for body, sign in ((body1, -1.0), (body2, 1.0)):
            if body == 0:
                continue
            jacp = np.zeros((3, m.nv))
            mj.mj_jac(m, d, jacp, None, np.asarray(p, dtype=float), body)
            rows += sign * jacp
        return rows

    def kkt(self, M, f, J):
        """[M Jᵀ; J 0] [a; λ] = [f; 0] by least squares: (a, λ)."""
        n, k = M.shape[0], J.shape[0]
        K = np.block([[M, -J.T], [J, np.zeros((k, k))]])
        x = np.linalg.lstsq(K, np.concatenate([f, np.zeros(k)]), rcond=1e-13)[0]
        return x[:n], x[n:]

    def pinocchio(self, q, contacts):
        """Pinocchio's constrained qacc (MuJoCo layout) and forces (world, on body2) at rest."""
        pin, m, model, data = self.pin, self.m, self.pmodel, self.pdata
        qp = pin.neutral(model)
        T = np.eye(model.nv)
        for j, jid in self.jids.items():
            jm = model.joints[jid]
            qa, t = int(m.jnt_qposadr[j]), int(m.jnt_type[j])
            if t == 0:
                R = quat_wxyz_to_mat(q[qa + 3 : qa + 7])
                qp[jm.idx_q : jm.idx_q + 3] = q[qa : qa + 3]
                qp[jm.idx_q + 3 : jm.idx_q + 7] = pin.Quaternion(R).coeffs()
                T[jm.idx_v : jm.idx_v + 3, jm.idx_v : jm.idx_v + 3] = R
            elif t == 1:
                w, x, y, z = q[qa : qa + 4]
                qp[jm.idx_q : jm.idx_q + 4] = [x, y, z, w]
            else:
                qp[jm.idx_q] = q[qa] - m.qpos0[qa]
        pin.forwardKinematics(model, data, qp)
        cmodels = []
        for c in contacts:
            placements = []
            for body in (c["body2"], c["body1"]):
                jid, jMb = self.place[body]
                oMj = data.oMi[jid] if jid > 0 else pin.SE3.Identity()
                placements.append((jid, oMj.inverse() * pin.SE3(np.eye(3), np.asarray(c["pos"], dtype=float))))
            (j1, p1), (j2, p2) = placements
            cmodels.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, j1, p1, j2, p2,
                                                    pin.ReferenceFrame.LOCAL_WORLD_ALIGNED))
        cdatas = [cm.createData() for cm in cmodels]
        pin.initConstraintDynamics(model, data, cmodels, cdatas)
        settings = pin.ProximalSettings(1e-14, 1e-12, 200)
        a = np.asarray(pin.constraintDynamics(model, data, qp, np.zeros(model.nv), np.zeros(model.nv), cmodels,
                                              cdatas, settings)).copy()
        qacc = (T @ a)[self.vmap]
        forces = np.asarray(data.lambda_c).reshape(-1, 3)
        return qacc, forces, settings.iter


def contacts_of(result: dict, refs: References) -> list[dict]:
    out = []
    for c in result["forward"]["constraints"]:
        if c["kind"] != "contact":
            continue
        frame = np.asarray(c["frame"], dtype=float)
        force = np.asarray(c["force"], dtype=float)
        world = frame[: len(force)].T @ force  # force on geom2's body, world axes
        out.append({"geoms": c["geoms"], "pos": np.asarray(c["pos"], dtype=float), "frame": frame,
                    "force": force, "world": world, "dist": c["dist"],
                    "body1": refs.geom_body(c["geoms"][0]), "body2": refs.geom_body(c["geoms"][1])})
    return out


def in_cone(c, mu: float) -> bool:
    f = c["force"]
    return len(f) < 3 or np.hypot(f[1], f[2]) <= mu * f[0] * (1 + 1e-12)


def mujoco_contact_error(refs: References, contacts) -> float:
    """Largest distance from each of MuJoCo's contacts (at the state of the last `at`) to
    lagrange's nearest contact of the same geom pair; NaN if MuJoCo reports none. (MuJoCo keeps
    a contact only while dist ≤ margin, so of a line contact at exactly zero distance it may keep
    one end: every contact it reports must be one of lagrange's.)"""
    m, d = refs.m, refs.d
    worst, seen = 0.0, False
    for i in range(d.ncon):
        g = sorted(int(x) for x in d.contact[i].geom)
        ours = [c["pos"] for c in contacts if sorted(m.geom(n).id for n in c["geoms"]) == g]
        if ours:
            seen = True
            worst = max(worst, min(np.linalg.norm(np.asarray(d.contact[i].pos) - p) for p in ours))
    return worst if seen else float("nan")


def scenes(tmp: Path, mj, rng):
    """(name, scene path, states) for each scene."""
    go1 = go1_condim3(tmp)
    m = mj.MjModel.from_xml_path(str(go1))
    yield "go1 (feet condim 3)", go1, [touching_go1_state(mj, m, rng) for _ in range(N_STATES)]
    for name in ("incline_box", "incline_cylinder"):
        path = REPO / "models" / "textbook" / f"{name}.xml"
        m = mj.MjModel.from_xml_path(str(path))
        yield f"textbook {name}", path, [m.qpos0.copy()]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lagrange", type=Path, default=REPO / "target" / "release" / "lagrange")
    ap.add_argument("--no-report", action="store_true", help="write no report")
    args = ap.parse_args()
    import mujoco as mj
    import pinocchio as pin

    rng = np.random.default_rng(SEED)
    rows, failed, t0 = [], 0, time.perf_counter()
    with tempfile.TemporaryDirectory() as tmpdir:
        for name, scene, states in scenes(Path(tmpdir), mj, rng):
            refs = References(mj, pin, scene)
            results = lagrange_eval(args.lagrange, scene, [{"q": list(map(float, q))} for q in states])
            worst = {"pin": 0.0, "kkt": 0.0, "force_pin": 0.0, "force_kkt": 0.0, "pos": 0.0}
            fails, ncon, notes = [], 0, set()
            for q, res in zip(states, results):
                contacts = contacts_of(res, refs)
                ncon = max(ncon, len(contacts))
                if not contacts:
                    fails.append("no contacts at a touching state")
                    continue
                qacc = np.asarray(res["forward"]["qacc"], dtype=float)
                M, bias = refs.at(q)
                worst["pos"] = max(worst["pos"], np.nan_to_num(mujoco_contact_error(refs, contacts)))
                J = np.vstack([refs.point_rows(c["body1"], c["body2"], c["pos"]) for c in contacts])
                a_kkt, lam = refs.kkt(M, -bias, J)
                a_pin, f_pin, iters = refs.pinocchio(q, contacts)
                if iters >= 200:
                    # Redundant rows (a box's four corners) slow the proximal iterations: the
                    # comparison below still holds Pinocchio's answer to the tolerance.
                    notes.add("Pinocchio's proximal solver at its iteration limit")
                mu = [refs.m.geom_friction[refs.m.geom(c["geoms"][1]).id][0] for c in contacts]
                if not all(in_cone(c, max(mu[i], refs.m.geom_friction[refs.m.geom(c["geoms"][0]).id][0]))
                           for i, c in enumerate(contacts)):
                    fails.append("a contact slips: the sticking references do not apply")
                worst["pin"] = max(worst["pin"], rel_to_ref(qacc, a_pin))
                worst["kkt"] = max(worst["kkt"], rel_to_ref(qacc, a_kkt))
                ours = np.array([c["world"] for c in contacts])
                f_kkt = lam.reshape(-1, 3)
                scale = max(1.0, np.abs(f_kkt).max())
                if np.linalg.matrix_rank(J, tol=1e-10 * np.abs(J).max()) == J.shape[0]:
                    worst["force_pin"] = max(worst["force_pin"], np.abs(ours - f_pin).max() / scale)
                    worst["force_kkt"] = max(worst["force_kkt"], np.abs(ours - f_kkt).max() / scale)
                else:
                    notes.add("redundant rows: summed force compared")
                    worst["force_pin"] = max(worst["force_pin"], np.abs(ours.sum(0) - f_pin.sum(0)).max() / scale)
                    worst["force_kkt"] = max(worst["force_kkt"], np.abs(ours.sum(0) - f_kkt.sum(0)).max() / scale)
            for key, tol in (("pin", QACC_TOL), ("kkt", QACC_TOL), ("force_pin", FORCE_TOL),
                             ("force_kkt", FORCE_TOL), ("pos", POS_TOL)):
                if not worst[key] <= tol:
                    fails.append("%s %.1e > %.0e" % (key, worst[key], tol))
            result = "FAIL" if fails else "PASS"
            failed += bool(fails)
            rank_note = "; ".join(sorted(notes))
            rows.append((name, len(states), ncon, worst, rank_note, result, fails))
            print("%-4s %-28s states %d, contacts %2d: qacc vs Pinocchio %.1e, vs MuJoCo-KKT %.1e; forces %.1e / %.1e; "
                  "contact pos vs MuJoCo %.1e m%s%s" % (result, name, len(states), ncon, worst["pin"], worst["kkt"],
                                                       worst["force_pin"], worst["force_kkt"], worst["pos"],
                                                       ("; " + rank_note) if rank_note else "",
                                                       ("  — " + "; ".join(fails)) if fails else ""), flush=True)
    seconds = time.perf_counter() - t0
    if not args.no_report:
        write_section(rows, seconds, mj.__version__, pin.__version__)
    print("contacts: %d passed, %d failed" % (len(rows) - failed, failed))
    return 1 if failed else 0


def write_section(rows, seconds, mj_version, pin_version) -> None:
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True,
                            text=True).stdout.strip()
    lines = [SECTION, "",
             "Exact-mode frictional point contacts, `validation/crossval_contacts` (lagrange %s, MuJoCo %s, Pinocchio "
             "%s, %.1f s): lagrange's `forward.qacc` and contact forces at rest against Pinocchio's "
             "`constraintDynamics` (CONTACT_3D at lagrange's contact points) and the rigid KKT solve on MuJoCo's M, "
             "bias and point Jacobians; every contact sticks (checked). Errors: qacc max|Δ|/max(1, max|ref|), forces "
             "relative to the largest force, contact positions against MuJoCo's own contacts (m)." %
             (commit, mj_version, pin_version, seconds), "",
             "| scene | states | contacts | qacc vs Pinocchio | qacc vs MuJoCo-KKT | forces vs Pinocchio | forces vs "
             "MuJoCo-KKT | contact pos vs MuJoCo | result |", "|---|---|---|---|---|---|---|---|---|"]
    for name, n, ncon, w, note, result, fails in rows:
        lines.append("| %s | %d | %d | %.1e | %.1e | %.1e%s | %.1e | %.1e | %s |" % (
            name, n, ncon, w["pin"], w["kkt"], w["force_pin"], " (sum)" if "summed" in note else "", w["force_kkt"], w["pos"],
            result + ((": " + "; ".join(fails)) if fails else "")))
    report = REPO / "validation" / "report.md"
    old = report.read_text() if report.exists() else ""
    text = "\n".join(lines) + "\n"
    ls = old.splitlines()
    start = next((i for i, l in enumerate(ls) if l.strip() == SECTION), None)
    if start is None:
        new = old.rstrip("\n") + "\n\n" + text
    else:
        end = next((i for i in range(start + 1, len(ls)) if ls[i].startswith("## ")), len(ls))
        new = "\n".join(ls[:start] + text.rstrip("\n").splitlines() + ([""] + ls[end:] if end < len(ls) else [])) + "\n"
    report.write_text(new)
    print("wrote the Contacts section of validation/report.md")


if __name__ == "__main__":
    sys.exit(main())
