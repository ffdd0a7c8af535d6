#!/usr/bin/env python3
"""Exact (rigid) equality constraints: lagrange's `eval --constraints exact` against references.

For every model of the constraints set (our one-feature models in tests/data/mjcf/constraints/
and tests/data/urdf/constraints/, and a few corpus robots that carry <equality> or <mimic>) it
draws random states and compares lagrange's `forward.qacc` with

1. **MuJoCo-KKT**: the solution of the rigid KKT system built from MuJoCo's OWN quantities —
   M = mj_fullM (armature included), qfrc_bias, qfrc_passive (joint damping and springs), the
   equality rows of efc_J (dense Jacobian; efc_type == mjCNSTR_EQUALITY), and J̇v by central
   differences of J(q ⊕ εv)·v along v (mj_integratePos). Nothing of MuJoCo's soft constraint
   solver is used. URDF <mimic> rows come from the formula J = e_joint − multiplier·e_leader,
   J̇v = 0 (and are checked against the joint equalities MuJoCo's URDF import makes of them).

       M qacc = tau + qfrc_passive − qfrc_bias + Jᵀλ,      J qacc + J̇v = 0

   with v projected onto Jv = 0 first. Redundant rows (a planar loop closed by a 3-row connect)
   give a rank-deficient J: qacc is still unique (null-space method), λ is the minimum-norm one.

2. **Pinocchio** (4.1), where it has the constraint: `RigidConstraintModel` CONTACT_3D (connect)
   and CONTACT_6D (weld) between the two joints' frames at MuJoCo's anchor placements, solved by
   `constraintDynamics` with tight `ProximalSettings`; URDF mimics by Pinocchio's mimic joints
   (`buildModelFromUrdf(..., mimic=True)`: reduced crba/rnea, mapped to full coordinates).
   Anything Pinocchio cannot do is reported as skipped with the reason.

Each model is evaluated at N random states (joint ranges, random unit quaternions; v projected
onto Jv = 0) and at the same states with q projected onto the constraint manifold φ(q) = 0
(Gauss–Newton on MuJoCo's efc_pos, or the mimic formula). Pass criteria per state:

- qacc: max|Δ| / max(1, max|ref|) ≤ 1e-8 against MuJoCo-KKT (and against Pinocchio where compared);
- forward.qfrc_constraint = M qacc − (tau + qfrc_passive − bias) with lagrange's own M, bias and
  passive (1e-8, same relative measure), and equal to the reference's Jᵀλ;
- forward.qfrc_passive equals MuJoCo's qfrc_passive (1e-9);
- the number of constraint rows equals MuJoCo's equality rows (an inactive equality has none);
- at the manifold states every `violation` is ≤ 1e-8 (lagrange agrees where φ = 0).

Run through the wrapper (builds the venv and the release binary):

    validation/crossval_constraints               # table, appends "Constraints" to validation/report.md
    validation/crossval_constraints --filter weld # a subset (regex on the model name), no report
    validation/crossval_constraints --reference-only   # the references' self-checks only, no lagrange

Exit status 1 on any failure. See validation/README.md, "Exact equality constraints".
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time
import traceback
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from crossval_common import Layout, Slot, State, layout_from_slots, model_rng, quat_wxyz_to_mat, random_states  # noqa: E402
from crossval_corpus import REPO, Entry, corpus  # noqa: E402
from crossval_engines import GRAVITY_URDF, Lagrange, UrdfInfo, first_line, index_maps, match_slots, urdf_for_mujoco  # noqa: E402

SEED = 20261123
N_STATES = 5

#: qacc against a reference: max|Δ| / max(1, max|ref|) (the issue's measure).
QACC_TOL = 1e-8
#: qfrc_constraint (consistency with lagrange's own M, bias, passive; and against the reference).
QFRC_TOL = 1e-8
#: qfrc_passive against MuJoCo's.
PASSIVE_TOL = 1e-9
#: |violation| at states on the constraint manifold.
VIOLATION_TOL = 1e-8
#: The references' own checks: |J qacc + J̇v|, Pinocchio against MuJoCo-KKT.
REF_SELF_TOL = 1e-9

#: Central-difference step for J̇v = d/dt (J v) along v.
FD_STEP = 1e-6

#: Relative singular-value cut-off for the rank of J (redundant rows).
RANK_RTOL = 1e-10

#: Corpus models with <equality> or <mimic> (ids of crossval_corpus.corpus()).
CORPUS = [
    "menagerie/franka_emika_panda/panda.xml",          # joint equality (fingers)
    "menagerie/robotiq_2f85_v4/2f85.xml",              # two connects closing the linkages + joint
    "menagerie/aloha/aloha.xml",                       # joint equalities with polycoef, two arms
    "dm_control/suite/quadruped.xml",                  # four fixed-tendon equalities, free joint
    "dm_control/suite/manipulator.xml",                # fixed-tendon equality
    "erd/panda_description/urdf/panda.urdf@fixed",     # prismatic mimic
    "erd/baxter_description/urdf/baxter.urdf@fixed",   # two gripper mimics, multiplier −1, no offset attribute
    "erd/tiago_pro_description/robots/tiago_pro.urdf@fixed",  # ten revolute mimics (±1)
]

EQ_KINDS = {0: "connect", 1: "weld", 2: "joint", 3: "tendon", 4: "flex"}


# ---------------------------------------------------------------------------------------------
# The model set
# ---------------------------------------------------------------------------------------------


def model_set() -> list[Entry]:
    entries = []
    for p in sorted((REPO / "tests" / "data" / "mjcf" / "constraints").glob("*.xml")):
        rel = p.relative_to(REPO).as_posix()
        entries.append(Entry(rel, rel, "tests", p, "mjcf"))
    for p in sorted((REPO / "tests" / "data" / "urdf" / "constraints").glob("*.urdf")):
        rel = p.relative_to(REPO).as_posix()
        entries.append(Entry(rel, rel, "tests", p, "urdf", package_dirs=[p.parent]))
    by_id = {e.id: e for e in corpus()}
    for cid in CORPUS:
        if cid not in by_id:
            raise SystemExit("crossval_constraints: corpus model %s is not in the installed packages" % cid)
        entries.append(by_id[cid])
    return entries


# ---------------------------------------------------------------------------------------------
# Linear algebra
# ---------------------------------------------------------------------------------------------


def floats(x) -> np.ndarray:
    """A JSON list of numbers as a float array; null (lagrange's NaN) becomes NaN."""
    return np.array([math.nan if e is None else e for e in np.ravel(np.asarray(x, dtype=object))], dtype=float)


def rel_to_ref(a, ref) -> float:
    """max|a − ref| / max(1, max|ref|); NaN or a shape mismatch gives NaN."""
    a = np.asarray(a, dtype=float).ravel()
    ref = np.asarray(ref, dtype=float).ravel()
    if a.shape != ref.shape:
        return math.nan
    if a.size == 0:
        return 0.0
    d = np.abs(a - ref)
    if np.isnan(d).any():
        return math.nan
    return float(d.max()) / max(1.0, float(np.abs(ref).max()))


def row_space(J: np.ndarray):
    """(rank, V_r, U_r, S_r, N): the SVD pieces of J with the relative cut-off RANK_RTOL."""
    nv = J.shape[1]
    if J.shape[0] == 0:
        return 0, np.zeros((nv, 0)), np.zeros((0, 0)), np.zeros(0), np.eye(nv)
    U, S, Vt = np.linalg.svd(J)
    r = int(np.sum(S > RANK_RTOL * S[0])) if S.size and S[0] > 0 else 0
    return r, Vt[:r].T, U[:, :r], S[:r], Vt[r:].T


def project_velocity(J: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v minus its component in the row space of J (least squares: v ∈ null(J) afterwards)."""
    r, Vr, _, _, _ = row_space(J)
    return v - Vr @ (Vr.T @ v) if r else v.copy()


def kkt_solve(M, f, J, jdotv):
    """The rigid KKT system M a = f + Jᵀλ, J a = −J̇v by the null-space method (J may be rank
    deficient): a = V_r x + N z with S_r x = −U_rᵀ J̇v and (NᵀMN) z = Nᵀ(f − M V_r x).
    Returns (qacc, qfrc_constraint = M a − f, λ (minimum norm), the part of J̇v outside
    range(J), which must vanish for consistent rows)."""
    nv = M.shape[0]
    r, Vr, Ur, Sr, N = row_space(J)
    if r == 0:
        a = np.linalg.solve(M, f)
        return a, np.zeros(nv), np.zeros(J.shape[0]), float(np.abs(jdotv).max()) if jdotv.size else 0.0
    x = -(Ur.T @ jdotv) / Sr
    inconsistent = float(np.abs(jdotv - Ur @ (Ur.T @ jdotv)).max())
    a = Vr @ x
    if N.shape[1]:
        MN = M @ N
        z = np.linalg.solve(N.T @ MN, N.T @ (f - M @ a))
        a = a + N @ z
    qfrc = M @ a - f
    lam = np.linalg.lstsq(J.T, qfrc, rcond=None)[0]
    return a, qfrc, lam, inconsistent


# ---------------------------------------------------------------------------------------------
# MuJoCo: M, bias, passive, equality rows
# ---------------------------------------------------------------------------------------------


@dataclass
class Mimic:
    joint: str
    leader: str
    multiplier: float
    offset: float


def urdf_mimics(path: Path) -> tuple[list[Mimic], list[str]]:
    """The URDF's <mimic> elements between movable joints, and notes on the ones left out."""
    root = ET.parse(path).getroot()
    joints = {j.get("name"): j.get("type") for j in root.findall("joint")}
    out, notes = [], []
    for j in root.findall("joint"):
        m = j.find("mimic")
        if m is None:
            continue
        leader = m.get("joint")
        mult = float(m.get("multiplier", "1"))
        off = float(m.get("offset", "0"))
        if leader not in joints:
            notes.append("mimic on '%s' names the undefined joint '%s': no row" % (j.get("name"), leader))
        elif j.get("type") == "fixed" or joints[leader] == "fixed":
            notes.append("mimic on '%s' (leader '%s') involves a fixed joint: no row" % (j.get("name"), leader))
        else:
            out.append(Mimic(j.get("name"), leader, mult, off))
    return out, notes


class MjRef:
    """MuJoCo model with only equality rows (contacts, limits, friction loss and actuation
    disabled; springs and dampers kept), dense Jacobians."""

    def __init__(self, entry: Entry):
        import mujoco as mj

        self.mj = mj
        if entry.fmt == "urdf":
            spec = mj.MjSpec.from_string(urdf_for_mujoco(entry.path, entry.package_dirs))
            m = spec.compile()
        else:
            m = mj.MjModel.from_xml_path(str(entry.path))
        D = mj.mjtDisableBit
        for bit in ("mjDSBL_FRICTIONLOSS", "mjDSBL_LIMIT", "mjDSBL_CONTACT", "mjDSBL_ACTUATION"):
            m.opt.disableflags |= int(getattr(D, bit))
        m.opt.jacobian = mj.mjtJacobian.mjJAC_DENSE
        self.m = m
        self.d = mj.MjData(m)
        self.dfd = mj.MjData(m)
        self.fmt = entry.fmt
        slots = []
        kinds = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}
        for j in range(m.njnt):
            kind = kinds[int(m.jnt_type[j])]
            rng = None
            if kind in ("hinge", "slide") and m.jnt_limited[j]:
                rng = (float(m.jnt_range[j][0]), float(m.jnt_range[j][1]))
            nq, nv = {"free": (7, 6), "ball": (4, 3)}.get(kind, (1, 1))
            slots.append(Slot(m.joint(j).name or "joint%d" % j, kind, m.body(int(m.jnt_bodyid[j])).name,
                              int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j]), nq, nv, rng))
        self.layout = layout_from_slots(slots, "mujoco")
        self.mimics: list[Mimic] = []
        self.notes: list[str] = []
        if entry.fmt == "urdf":
            self.mimics, self.notes = urdf_mimics(entry.path)
            by = self.layout.by_name()
            for mm in self.mimics:
                if mm.joint not in by or mm.leader not in by:
                    raise ValueError("mimic joint '%s' or '%s' is not a MuJoCo joint" % (mm.joint, mm.leader))

    # -- counts ---------------------------------------------------------------------------------

    def equality_summary(self) -> dict[str, int]:
        """Active equality constraints by kind (URDF: the mimics)."""
        if self.fmt == "urdf":
            return {"mimic": len(self.mimics)} if self.mimics else {}
        out: dict[str, int] = {}
        for i in range(self.m.neq):
            if self.m.eq_active0[i]:
                k = EQ_KINDS.get(int(self.m.eq_type[i]), "?")
                out[k] = out.get(k, 0) + 1
        inactive = int(self.m.neq - np.sum(self.m.eq_active0))
        if inactive:
            out["inactive"] = inactive
        return out

    # -- evaluation -----------------------------------------------------------------------------

    def _rows(self, d) -> tuple[np.ndarray, np.ndarray]:
        """(J, φ) of the equality rows at d's current state (after mj_forward)."""
        mj, m = self.mj, self.m
        if self.fmt == "urdf":
            by = self.layout.by_name()
            J = np.zeros((len(self.mimics), m.nv))
            phi = np.zeros(len(self.mimics))
            for k, mm in enumerate(self.mimics):
                f, l = by[mm.joint], by[mm.leader]
                J[k, f.vadr] += 1.0
                J[k, l.vadr] -= mm.multiplier
                phi[k] = d.qpos[f.qadr] - mm.multiplier * d.qpos[l.qadr] - mm.offset
            return J, phi
        eq = np.asarray(d.efc_type[: d.nefc]) == int(mj.mjtConstraint.mjCNSTR_EQUALITY)
        J = np.asarray(d.efc_J).reshape(-1)[: d.nefc * m.nv].reshape(d.nefc, m.nv)[eq].copy()
        phi = np.asarray(d.efc_pos[: d.nefc])[eq].copy()
        return J, phi

    def mj_rows_urdf(self) -> np.ndarray:
        """MuJoCo's own equality rows (its URDF import turns <mimic> into joint equalities)."""
        d, mj = self.d, self.mj
        eq = np.asarray(d.efc_type[: d.nefc]) == int(mj.mjtConstraint.mjCNSTR_EQUALITY)
        return np.asarray(d.efc_J).reshape(-1)[: d.nefc * self.m.nv].reshape(d.nefc, self.m.nv)[eq].copy()

    def forward(self, q, v) -> None:
        d = self.d
        d.qpos[:] = q
        d.qvel[:] = v
        d.ctrl[:] = 0.0
        d.qfrc_applied[:] = 0.0
        d.xfrc_applied[:] = 0.0
        self.mj.mj_forward(self.m, d)

    def rows_at(self, q) -> tuple[np.ndarray, np.ndarray]:
        d = self.dfd
        d.qpos[:] = q
        d.qvel[:] = 0.0
        self.mj.mj_forward(self.m, d)
        return self._rows(d)

    def jdotv(self, q, v, h) -> np.ndarray:
        """d/dt (J v) along v, central differences of J(q ⊕ ±h v)·v."""
        mj, m = self.mj, self.m
        qp = np.array(q, dtype=float)
        qm = np.array(q, dtype=float)
        mj.mj_integratePos(m, qp, v, h)
        mj.mj_integratePos(m, qm, v, -h)
        Jp, _ = self.rows_at(qp)
        Jm, _ = self.rows_at(qm)
        return (Jp @ v - Jm @ v) / (2 * h)

    def project_q(self, q, iters: int = 60) -> tuple[np.ndarray | None, float]:
        """q moved onto φ(q) = 0 (Gauss–Newton with minimum-norm steps); None if it does not
        converge to 1e-13."""
        mj, m = self.mj, self.m
        q = np.array(q, dtype=float)
        if self.fmt == "urdf":
            by = self.layout.by_name()
            for _ in range(len(self.mimics) + 1):  # chains: leaders first, repeat until settled
                for mm in self.mimics:
                    q[by[mm.joint].qadr] = mm.multiplier * q[by[mm.leader].qadr] + mm.offset
            _, phi = self.rows_at(q)
            err = float(np.abs(phi).max()) if phi.size else 0.0
            return (q if err <= 1e-13 else None), err
        err = math.inf
        for _ in range(iters):
            J, phi = self.rows_at(q)
            err = float(np.abs(phi).max()) if phi.size else 0.0
            if err <= 1e-13:
                return q, err
            dq = -np.linalg.lstsq(J, phi, rcond=None)[0]
            step = 1.0
            # damped: halve the step while the residual grows (far from the manifold)
            for _ in range(30):
                qn = q.copy()
                mj.mj_integratePos(m, qn, dq, step)
                _, phin = self.rows_at(qn)
                if np.abs(phin).max() < err or step < 1e-6:
                    break
                step *= 0.5
            q = qn
        return None, err


@dataclass
class RefState:
    """One state and what MuJoCo-KKT makes of it, in MuJoCo's coordinates."""

    q: np.ndarray
    v: np.ndarray
    tau: np.ndarray
    manifold: bool
    M: np.ndarray = None
    bias: np.ndarray = None
    passive: np.ndarray = None
    J: np.ndarray = None
    phi: np.ndarray = None
    jdotv: np.ndarray = None
    qacc: np.ndarray = None
    qfrc: np.ndarray = None
    rank: int = 0
    residual: float = 0.0  # |J qacc + J̇v|
    fd_effect: float = 0.0  # change of qacc between FD steps h and 2h (relative measure)
    inconsistent: float = 0.0
    mj_rows_diff: float = math.nan  # URDF: formula rows against MuJoCo's own rows


def reference(mjr: MjRef, q, v, tau, manifold: bool) -> RefState:
    mj, m, d = mjr.mj, mjr.m, mjr.d
    mjr.forward(q, np.zeros(m.nv))
    J0, _ = mjr._rows(d)
    v = project_velocity(J0, np.asarray(v, dtype=float))
    mjr.forward(q, v)
    s = RefState(np.array(q, dtype=float), v, np.asarray(tau, dtype=float), manifold)
    M = np.zeros((m.nv, m.nv))
    mj.mj_fullM(m, d, M)
    s.M = M
    s.bias = d.qfrc_bias.copy()
    s.passive = d.qfrc_passive.copy()
    s.J, s.phi = mjr._rows(d)
    if mjr.fmt == "urdf":
        mine = s.J
        theirs = mjr.mj_rows_urdf()
        if theirs.shape == mine.shape:
            s.mj_rows_diff = float(np.abs(theirs - mine).max()) if mine.size else 0.0
        s.jdotv = np.zeros(s.J.shape[0])  # constant rows
        jd2 = s.jdotv
    else:
        s.jdotv = mjr.jdotv(q, v, FD_STEP)
        jd2 = mjr.jdotv(q, v, 2 * FD_STEP)
    f = s.tau + s.passive - s.bias
    s.rank = row_space(s.J)[0]
    s.qacc, s.qfrc, _, s.inconsistent = kkt_solve(M, f, s.J, s.jdotv)
    a2 = kkt_solve(M, f, s.J, jd2)[0]
    s.fd_effect = rel_to_ref(a2, s.qacc)
    s.residual = float(np.abs(s.J @ s.qacc + s.jdotv).max()) if s.J.size else 0.0
    return s


# ---------------------------------------------------------------------------------------------
# Pinocchio
# ---------------------------------------------------------------------------------------------


def pin_model_from_mujoco(pin, m):
    """A Pinocchio model of MuJoCo's compiled kinematic tree (Pinocchio's own MJCF reader keeps
    only the first tree under <worldbody> and merges multi-joint bodies): every body with its
    MuJoCo inertia, every joint at its anchor (hinge → RevoluteUnaligned, slide →
    PrismaticUnaligned, ball → Spherical, free → FreeFlyer), armature. Joints of one body chain
    about their anchors as in mj_kinematics. A hinge/slide coordinate is q − qpos0 (MuJoCo turns
    by q − qpos0). Returns (model, {body: (joint id, body frame in joint frame)},
    {MuJoCo joint: Pinocchio joint id})."""
    model = pin.Model()
    model.gravity = pin.Motion(np.asarray(m.opt.gravity, dtype=float), np.zeros(3))
    place = {0: (0, pin.SE3.Identity())}
    jids = {}
    for b in range(1, m.nbody):
        pj, X = place[int(m.body_parentid[b])]
        js = [j for j in range(m.njnt) if int(m.jnt_bodyid[j]) == b]
        if js and int(m.jnt_type[js[0]]) == 0:  # free: the body's pose is q itself
            if int(m.body_parentid[b]) != 0 or len(js) != 1:
                raise ValueError("free joint not on a child of the world")
            jids[js[0]] = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(),
                                         m.joint(js[0]).name or "joint%d" % js[0])
            pj, X = jids[js[0]], pin.SE3.Identity()
        else:
            X = X * pin.SE3(quat_wxyz_to_mat(m.body_quat[b]), np.asarray(m.body_pos[b], dtype=float).copy())
            for j in js:
                t = int(m.jnt_type[j])
                anchor = np.asarray(m.jnt_pos[j], dtype=float).copy()
                axis = np.asarray(m.jnt_axis[j], dtype=float).copy()
                if t == 1:
                    jm = pin.JointModelSpherical()
                elif t == 2:
                    jm = pin.JointModelPrismaticUnaligned(axis)
                elif t == 3:
                    jm = pin.JointModelRevoluteUnaligned(axis)
                else:
                    raise ValueError("free joint inside a body chain")
                jids[j] = model.addJoint(pj, jm, X * pin.SE3(np.eye(3), anchor), m.joint(j).name or "joint%d" % j)
                pj, X = jids[j], pin.SE3(np.eye(3), -anchor)
        R = quat_wxyz_to_mat(m.body_iquat[b])
        inertia = pin.Inertia(float(m.body_mass[b]), np.asarray(m.body_ipos[b], dtype=float).copy(),
                              R @ np.diag(m.body_inertia[b]) @ R.T)
        model.appendBodyToJoint(pj, inertia, X)
        place[b] = (pj, X)
    arm = np.zeros(model.nv)
    for j, jid in jids.items():
        jm = model.joints[jid]
        da = int(m.jnt_dofadr[j])
        arm[jm.idx_v : jm.idx_v + jm.nv] = m.dof_armature[da : da + jm.nv]
    model.armature = arm
    return model, place, jids


class PinRef:
    """Pinocchio's constrained dynamics for one model, in the canonical (lagrange) layout.

    Two modes: ``anchors`` (MJCF connect/weld → RigidConstraintModel CONTACT_3D/6D and
    constraintDynamics) and ``mimic`` (URDF <mimic> read by Pinocchio's URDF parser with
    mimic=True, or MJCF joint equalities with a linear polycoef turned into mimic joints by
    transformJointIntoMimic; reduced crba/rnea, qacc = G a_red)."""

    def __init__(self, entry: Entry, mjr: MjRef, canon: Layout):
        import pinocchio as pin

        self.pin = pin
        self.entry = entry
        self.mjr = mjr
        self.canon = canon
        self.skip = ""  # the reason Pinocchio is not compared, if it is not
        self.states_note = ""
        self.kind = ""
        self.m_check = 0.0  # largest |M_pin − M_MuJoCo| (relative) seen: the conversion's own check
        try:
            if entry.fmt == "urdf":
                self._init_urdf_mimic()
            else:
                self._init_mjcf()
        except Exception as e:  # Pinocchio's own errors become the skip reason
            self.skip = "Pinocchio: " + first_line(e, 300)

    # -- URDF mimic ----------------------------------------------------------------------------

    def _init_urdf_mimic(self):
        pin = self.pin
        mimics = [(mm.joint, mm.leader, mm.multiplier) for mm in self.mjr.mimics]
        if not mimics:
            self.skip = "no mimic between movable joints"
            return
        if self._chained(mimics):
            return
        if self.entry.floating:
            self.skip = "floating URDF with mimics: not set up"
            return
        model = pin.buildModelFromUrdf(str(self.entry.path), mimic=True)
        model.gravity = pin.Motion(GRAVITY_URDF, np.zeros(3))
        self._setup_mimic(model, mimics, offsets={})
        self.states_note = "manifold states only (a mimic model has no coordinates off the manifold)"

    def _chained(self, mimics) -> bool:
        followers = {f for f, _, _ in mimics}
        chained = [(f, l) for f, l, _ in mimics if l in followers]
        if chained:
            self.skip = ("Pinocchio 4.1's mimic joints cannot mimic a mimic joint (joint '%s' mimics '%s'; "
                         "JointModelMimic: 'Mimicking and mimicked configuration spaces have different sizes')"
                         % chained[0])
            return True
        if len(followers) != len(mimics):
            self.skip = "a joint mimics two joints: not expressible as Pinocchio mimic joints"
            return True
        return False

    def _setup_mimic(self, model, mimics, offsets):
        """G (canonical v = G v_red) and the coordinates of the independent joints."""
        if any(s.kind == "free" for s in self.canon.slots):
            raise ValueError("mimic mode with a free joint: not set up")
        self.model, self.data = model, model.createData()
        cby = self.canon.by_name()
        G = np.zeros((self.canon.nv, model.nv))
        self.qinfo = []  # (canonical slot, pin idx_q, pin nq, kind, offset)
        seen = set()
        mimic_of = {f: (l, k) for f, l, k in mimics}
        for j in range(1, model.njoints):
            name, jm = model.names[j], model.joints[j]
            c = cby.get(name)
            if c is None:
                raise ValueError("Pinocchio joint '%s' is not lagrange's" % name)
            seen.add(name)
            if jm.shortname() == "JointModelMimic":
                if name not in mimic_of:
                    raise ValueError("Pinocchio mimic joint '%s' is not a mimic of the file" % name)
                continue
            for k in range(c.nv):
                G[c.vadr + k, jm.idx_v + k] = 1.0
            self.qinfo.append((c, jm.idx_q, jm.nq, c.kind, offsets.get(name, 0.0)))
        for f, (l, k) in mimic_of.items():
            col = np.nonzero(G[cby[l].vadr])[0]
            G[cby[f].vadr, col] = k
        missing = [c.name for c in self.canon.slots if c.name not in seen]
        if missing:
            raise ValueError("no Pinocchio joint %s" % ", ".join(missing[:4]))
        self.G = G
        self.kind = "mimic"

    def _mimic_qacc(self, q, v, tau_total, M_ref):
        pin, model, data = self.pin, self.model, self.data
        qp = pin.neutral(model)
        for c, iq, nq, kind, off in self.qinfo:
            if kind == "ball":
                w, x, y, z = q[c.qadr : c.qadr + 4]
                qp[iq : iq + 4] = [x, y, z, w]
            elif nq == 2:
                qp[iq], qp[iq + 1] = math.cos(q[c.qadr]), math.sin(q[c.qadr])
            else:
                qp[iq] = q[c.qadr] - off
        G = self.G
        v_red = np.linalg.lstsq(G, v, rcond=None)[0]
        M = np.asarray(pin.crba(model, data, qp)).copy()
        M = np.triu(M) + np.triu(M, 1).T
        self.m_check = max(self.m_check, rel_to_ref(M, G.T @ M_ref @ G))
        b = np.asarray(pin.rnea(model, data, qp, v_red, np.zeros(model.nv))).copy()
        a_red = np.linalg.solve(M, G.T @ tau_total - b)
        return G @ a_red

    # -- MJCF ----------------------------------------------------------------------------------

    def _init_mjcf(self):
        pin = self.pin
        m = self.mjr.m
        active = [i for i in range(m.neq) if m.eq_active0[i]]
        if not active:
            self.skip = "no active equality"
            return
        anchors = [i for i in active if int(m.eq_type[i]) in (0, 1)]
        linear = [i for i in active if int(m.eq_type[i]) == 2 and int(m.eq_obj2id[i]) >= 0
                  and not np.any(m.eq_data[i][2:5])]
        rest = [i for i in active if i not in anchors and i not in linear]
        if rest:
            why = sorted({"tendon equality" if int(m.eq_type[i]) == 3 else
                          "joint equality without joint2 (a locked joint)" if int(m.eq_type[i]) == 2 and int(m.eq_obj2id[i]) < 0
                          else "joint equality with a nonlinear polycoef" if int(m.eq_type[i]) == 2
                          else EQ_KINDS.get(int(m.eq_type[i]), "?") for i in rest})
            self.skip = ("Pinocchio 4.1 has no constraint for a %s (its constraint models are point/frame "
                         "anchors, contacts, joint limits and friction; linear joint couplings map to mimic "
                         "joints)" % ", ".join(why))
            return
        if anchors and linear:
            self.skip = ("connect/weld together with joint couplings: Pinocchio's constraintDynamics does not "
                         "take mimic joints")
            return
        model, self.place, jids = pin_model_from_mujoco(pin, m)
        self.jids = jids
        offsets = {m.joint(j).name: float(m.qpos0[m.jnt_qposadr[j]]) for j in jids if int(m.jnt_type[j]) in (2, 3)}
        if linear:
            mimics = []
            for i in linear:
                f, l = int(m.eq_obj1id[i]), int(m.eq_obj2id[i])
                if int(m.jnt_type[f]) not in (2, 3) or int(m.jnt_type[l]) not in (2, 3):
                    self.skip = "joint equality on a ball or free joint"
                    return
                k, a0 = float(m.eq_data[i][1]), float(m.eq_data[i][0])
                if jids[l] > jids[f]:
                    # Pinocchio's mimicked joint must come first in the tree: invert the relation
                    if k == 0:
                        self.skip = "joint equality with polycoef a1 = 0 on a later joint2"
                        return
                    f, l, k, a0 = l, f, 1.0 / k, -a0 / k
                mimics.append((m.joint(f).name, m.joint(l).name, k, a0))
            if self._chained([(f, l, k) for f, l, k, _ in mimics]):
                return
            for f, l, k, a0 in mimics:
                # q_f − q_f0 = a0 + k (q_l − q_l0): in Pinocchio's coordinates (q − q0), offset a0
                model = pin.transformJointIntoMimic(model, model.getJointId(l), model.getJointId(f), k, a0)
            self._setup_mimic(model, [(f, l, k) for f, l, k, _ in mimics], offsets)
            # A mimic joint has no velocity coordinate of its own, so Pinocchio cannot hold its
            # armature: the reduced rotor inertia is Gᵀ diag(armature) G (diagonal, as each row of
            # G has one entry), i.e. the leader's armature plus k² times each follower's.
            cby = self.canon.by_name()
            arm = np.zeros(self.canon.nv)
            for j in range(m.njnt):
                c = cby[m.joint(j).name]
                da = int(m.jnt_dofadr[j])
                arm[c.vadr : c.vadr + c.nv] = m.dof_armature[da : da + c.nv]
            self.model.armature = np.diag(self.G.T @ np.diag(arm) @ self.G).copy()
            self.states_note = "manifold states only (a mimic model has no coordinates off the manifold)"
            self.note = "tree rebuilt from MuJoCo's compiled model; joint couplings as mimic joints"
            return
        self.model, self.data = model, model.createData()
        self._map_joints(offsets)
        self.cmodels = []
        self.has_weld = False
        for i in anchors:
            t = int(m.eq_type[i])
            data = np.asarray(m.eq_data[i], dtype=float)
            site = int(m.eq_objtype[i]) == int(self.mjr.mj.mjtObj.mjOBJ_SITE)
            ids = [int(m.eq_obj1id[i]), int(m.eq_obj2id[i])]
            frames = []
            for k in range(2):
                if site:
                    body = int(m.site_bodyid[ids[k]])
                    local = pin.SE3(quat_wxyz_to_mat(m.site_quat[ids[k]]), np.asarray(m.site_pos[ids[k]], dtype=float).copy())
                else:
                    body = ids[k]
                    if t == 0:  # connect: anchor k in body k (MuJoCo computes body 2's at qpos0)
                        local = pin.SE3(np.eye(3), data[3 * k : 3 * k + 3].copy())
                    elif k == 0:  # weld: frame 1 = body1 ∘ relpose
                        local = pin.SE3(quat_wxyz_to_mat(data[6:10]), data[3:6].copy())
                    else:  # weld: frame 2 = body2 ∘ anchor
                        local = pin.SE3(np.eye(3), data[0:3].copy())
                jid, jMb = self.place[body]
                frames.append((jid, jMb * local))
            ctype = pin.ContactType.CONTACT_3D if t == 0 else pin.ContactType.CONTACT_6D
            self.has_weld |= t == 1
            self.cmodels.append(pin.RigidConstraintModel(ctype, model, frames[0][0], frames[0][1], frames[1][0],
                                                         frames[1][1], pin.ReferenceFrame.LOCAL))
        self.cdatas = [cm.createData() for cm in self.cmodels]
        pin.initConstraintDynamics(model, self.data, self.cmodels, self.cdatas)
        self.kind = "anchors"
        self.note = ("tree rebuilt from MuJoCo's compiled model (Pinocchio's MJCF reader keeps only the first "
                     "tree under <worldbody>); CONTACT_3D/6D at MuJoCo's anchors")
        if self.has_weld:
            self.states_note = ("manifold states only: Pinocchio's CONTACT_6D constrains the velocity of body 2's "
                                "point at frame 1's origin, MuJoCo's weld those of its two anchor points; they "
                                "coincide only where the weld holds")

    def _map_joints(self, offsets):
        model, m = self.model, self.mjr.m
        cby = self.canon.by_name()
        self.entries = []
        for j, jid in self.jids.items():
            name = m.joint(j).name or "joint%d" % j
            c = cby.get(name)
            if c is None:
                raise ValueError("MuJoCo joint '%s' is not lagrange's" % name)
            jm = model.joints[jid]
            self.entries.append((c, jid, jm.idx_q, jm.idx_v, jm.nq, c.kind, offsets.get(name, 0.0)))
        if model.nv != self.canon.nv:
            raise ValueError("nv %d, lagrange %d" % (model.nv, self.canon.nv))
        self.vmap = np.zeros(model.nv, dtype=int)
        for c, jid, iq, iv, nq, kind, off in self.entries:
            self.vmap[c.vadr : c.vadr + c.nv] = range(iv, iv + c.nv)

    def _to_pin(self, q, v, tau):
        """Canonical state → Pinocchio's (q, v, tau), T and c of the free-joint velocity maps."""
        pin, model = self.pin, self.model
        nv = model.nv
        qp = pin.neutral(model)
        T = np.eye(nv)
        for c, jid, iq, iv, nq, kind, off in self.entries:
            if kind == "free":
                R = quat_wxyz_to_mat(q[c.qadr + 3 : c.qadr + 7])
                qp[iq : iq + 3] = q[c.qadr : c.qadr + 3]
                qp[iq + 3 : iq + 7] = pin.Quaternion(R).coeffs()
                T[iv : iv + 3, iv : iv + 3] = R
            elif kind == "ball":
                w, x, y, z = q[c.qadr : c.qadr + 4]
                qp[iq : iq + 4] = [x, y, z, w]
            else:
                qp[iq] = q[c.qadr] - off
        v_o = np.zeros(nv)
        v_o[self.vmap] = v
        tau_o = np.zeros(nv)
        tau_o[self.vmap] = tau
        Tinv = np.linalg.inv(T)
        v_pin = Tinv @ v_o
        cvec = np.zeros(nv)
        for c, jid, iq, iv, nq, kind, off in self.entries:
            if kind == "free":
                cvec[iv : iv + 3] = T[iv : iv + 3, iv : iv + 3] @ np.cross(v_pin[iv + 3 : iv + 6], v_pin[iv : iv + 3])
        return qp, v_pin, T.T @ tau_o, T, cvec

    def qacc(self, q, v, tau_total, M_ref):
        """Constrained qacc in the canonical layout; tau_total = tau + MuJoCo's qfrc_passive
        (Pinocchio's dynamics have no damping or springs); M_ref is MuJoCo's M in the canonical
        layout, for the conversion's own check. Returns (qacc, note)."""
        pin = self.pin
        if self.kind == "mimic":
            return self._mimic_qacc(q, v, tau_total, M_ref), ""
        model, data = self.model, self.data
        qp, v_pin, tau_pin, T, cvec = self._to_pin(q, v, tau_total)
        Tinv = np.linalg.inv(T)
        M = np.asarray(pin.crba(model, data, qp)).copy()
        M = np.triu(M) + np.triu(M, 1).T
        self.m_check = max(self.m_check, rel_to_ref((Tinv.T @ M @ Tinv)[np.ix_(self.vmap, self.vmap)], M_ref))
        settings = pin.ProximalSettings(1e-14, 1e-12, 200)
        a_pin = np.asarray(pin.constraintDynamics(model, data, qp, v_pin, tau_pin, self.cmodels, self.cdatas,
                                                  settings)).copy()
        note = "" if settings.iter < 200 else "proximal iterations did not converge (%d)" % settings.iter
        qacc_o = T @ a_pin + cvec
        return qacc_o[self.vmap], note


# ---------------------------------------------------------------------------------------------
# lagrange
# ---------------------------------------------------------------------------------------------


def lagrange_eval(lag: Lagrange, entry: Entry, states: list[dict]) -> tuple[list[dict] | None, str]:
    doc = {"states": states}
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(doc, f)
        path = f.name
    try:
        # Equality rows only, as on the MuJoCo side (its limit, friction-loss and contact rows and
        # its actuation are disabled there too): the manifold states may lie outside the joint ranges.
        args = ["eval", str(entry.path), "--states", path, "--json", "--constraints", "exact",
                "--disable", "limit", "--disable", "frictionloss", "--disable", "contact", "--disable", "actuation",
                *lag._args(entry)]
        try:
            p = lag._run(args)
        except subprocess.TimeoutExpired:
            return None, "eval timed out"
    finally:
        os.unlink(path)
    if p.returncode != 0:
        return None, "eval --constraints exact failed: " + first_line(p.stderr or p.stdout, 300)
    try:
        results = json.loads(p.stdout)["results"]
    except (json.JSONDecodeError, KeyError) as e:
        return None, "eval printed invalid JSON: %s" % e
    if any("forward" not in r for r in results):
        return None, "eval output has no 'forward' object"
    return results, ""


# ---------------------------------------------------------------------------------------------
# One model
# ---------------------------------------------------------------------------------------------


def process(entry: Entry, cfg: dict) -> dict:
    t0 = time.perf_counter()
    row = {"name": entry.name, "group": "test" if entry.source == "tests" else "corpus", "fmt": entry.fmt,
           "kinds": {}, "rows": 0, "rank": 0, "nv": None, "states": 0, "manifold_states": 0,
           "err_mj": math.nan, "err_pin": math.nan, "pin_states": 0, "qfrc_self": math.nan, "qfrc_ref": math.nan,
           "passive": math.nan, "viol_manifold": math.nan, "ref_residual": math.nan, "fd_effect": math.nan,
           "pin_vs_mj": math.nan, "inconsistent": math.nan, "result": "", "fails": [], "notes": [],
           "pin_skip": "", "seconds": 0.0}
    try:
        _process(entry, cfg, row)
    except Exception as e:
        row["result"] = "FAIL"
        row["fails"].append("harness error: %s (%s)" % (first_line(e, 300),
                                                        traceback.format_exc().strip().splitlines()[-3].strip()))
    row["seconds"] = time.perf_counter() - t0
    if not row["result"]:
        row["result"] = "FAIL" if row["fails"] else "PASS"
    return row


def _process(entry: Entry, cfg: dict, row: dict) -> None:
    mjr = MjRef(entry)
    row["notes"] += mjr.notes
    row["kinds"] = mjr.equality_summary()
    m = mjr.m
    row["nv"] = m.nv

    # canonical layout: lagrange's when it loads (joints by name), else MuJoCo's
    lag = None
    canon = mjr.layout
    if not cfg["reference_only"]:
        lag = Lagrange(cfg["lagrange"], cfg["timeout"])
        run = lag.info(entry)
        if run.status != "ok":
            row["fails"].append("lagrange does not load it: %s" % run.detail)
            return
        canon = run.layout
    mapping, problem = match_slots(canon, mjr.layout.slots)
    if problem:
        row["fails"].append("joints differ between lagrange and MuJoCo: %s" % problem)
        return
    qmap, vmap = index_maps(canon, mapping)

    # states: random (v projected), then the same projected onto the manifold
    if entry.fmt == "urdf":
        ranges = UrdfInfo(entry.path, entry.floating).ranges
    else:
        ranges = {s.name: s.range for s in mjr.layout.slots if s.range}
    draws = random_states(model_rng(cfg["seed"], "constraints:" + entry.id), canon, ranges, cfg["n_states"])
    refs: list[RefState] = []
    dropped = 0
    for manifold in (False, True):
        for s in draws:
            q_mj = np.array(m.qpos0, dtype=float)
            q_mj[qmap] = s.q
            v_mj = np.zeros(m.nv)
            v_mj[vmap] = s.v
            tau_mj = np.zeros(m.nv)
            tau_mj[vmap] = s.tau
            if manifold:
                q_mj, _ = mjr.project_q(q_mj)
                if q_mj is None:
                    dropped += 1
                    continue
            refs.append(reference(mjr, q_mj, v_mj, tau_mj, manifold))
    if dropped:
        row["notes"].append("%d of %d states: Gauss–Newton did not reach the manifold (|φ| > 1e-13), left out"
                            % (dropped, len(draws)))
    row["states"] = sum(1 for r in refs if not r.manifold)
    row["manifold_states"] = sum(1 for r in refs if r.manifold)
    row["rows"] = int(refs[0].J.shape[0]) if refs else 0
    row["rank"] = max((r.rank for r in refs), default=0)
    row["ref_residual"] = max((r.residual / max(1.0, float(np.abs(r.qacc).max())) for r in refs), default=0.0)
    row["fd_effect"] = max((r.fd_effect for r in refs), default=0.0)
    row["inconsistent"] = max((r.inconsistent for r in refs), default=0.0)
    if row["ref_residual"] > REF_SELF_TOL:
        row["fails"].append("reference: |J qacc + J̇v| = %.1e relative" % row["ref_residual"])
    if row["inconsistent"] > 1e-7:
        row["fails"].append("reference: J̇v has a component %.1e outside range(J) (inconsistent rows)" % row["inconsistent"])
    if entry.fmt == "urdf":
        diffs = [r.mj_rows_diff for r in refs if not math.isnan(r.mj_rows_diff)]
        if diffs:
            row["notes"].append("MuJoCo's URDF import makes the mimics joint equalities; its rows equal the "
                                "formula rows to %.1e" % max(diffs))
            if max(diffs) > 1e-12:
                row["fails"].append("MuJoCo's mimic rows differ from the formula by %.1e" % max(diffs))
        else:
            row["notes"].append("MuJoCo's URDF import made a different number of rows than the mimic formula")

    def to_canon_vec(x):
        return np.asarray(x)[vmap]

    # Pinocchio
    pinref = PinRef(entry, mjr, canon)
    pin_qacc: dict[int, np.ndarray] = {}  # state index -> Pinocchio's qacc (canonical)
    if pinref.skip:
        row["pin_skip"] = pinref.skip
    else:
        if pinref.states_note:
            row["notes"].append("Pinocchio: " + pinref.states_note)
        errs, notes = [], set()
        for k, r in enumerate(refs):
            if pinref.states_note and not r.manifold:
                continue
            M_c = r.M[np.ix_(vmap, vmap)]
            a, note = pinref.qacc(r.q[qmap], to_canon_vec(r.v), to_canon_vec(r.tau + r.passive), M_c)
            if note:
                notes.add(note)
            pin_qacc[k] = a
            errs.append(rel_to_ref(a, to_canon_vec(r.qacc)))
        if pinref.m_check > 1e-9:
            row["pin_skip"] = ("Pinocchio's mass matrix differs from MuJoCo's by %.1e (relative): the model "
                               "conversion is wrong, not compared" % pinref.m_check)
            row["fails"].append(row["pin_skip"])
            pin_qacc = {}
        elif not errs:
            row["pin_skip"] = "no state on the manifold"
        else:
            row["pin_vs_mj"] = max(errs)
            row["pin_states"] = len(errs)
            for n in sorted(notes):
                row["notes"].append("Pinocchio: " + n)
            if getattr(pinref, "note", ""):
                row["notes"].append("Pinocchio: " + pinref.note)
            if row["pin_vs_mj"] > QACC_TOL:
                row["fails"].append("references disagree: Pinocchio against MuJoCo-KKT qacc %.1e > %.0e"
                                    % (row["pin_vs_mj"], QACC_TOL))
    if cfg["reference_only"]:
        return

    # lagrange
    states = []
    for r in refs:
        # no "ctrl": zero controls, whatever lagrange's actuator count (MuJoCo's actuation is
        # disabled in the reference; lagrange's qfrc_actuator enters its own consistency check)
        states.append({"q": r.q[qmap].tolist(), "v": to_canon_vec(r.v).tolist(), "tau": to_canon_vec(r.tau).tolist()})
    results, err = lagrange_eval(lag, entry, states)
    if results is None:
        row["fails"].append(err)
        return
    e_mj, e_pin, e_self, e_ref, e_pas, viol = [], [], [], [], [], []
    rows_bad = set()
    pin_err_states = []
    for k, (r, out) in enumerate(zip(refs, results)):
        fw = out["forward"]
        nv = canon.nv
        qacc = floats(fw["qacc"])
        e_mj.append(rel_to_ref(qacc, to_canon_vec(r.qacc)))
        M_l = floats(out["M"]).reshape(nv, nv)
        bias_l = floats(out["bias"])
        pas_l = floats(fw.get("qfrc_passive", [math.nan] * nv))
        act_l = floats(fw.get("qfrc_actuator", [0.0] * nv))
        qfrc_l = floats(fw.get("qfrc_constraint", [math.nan] * nv))
        tau_c = to_canon_vec(r.tau)
        e_self.append(rel_to_ref(qfrc_l, M_l @ qacc - (tau_c + pas_l + act_l - bias_l)))
        e_ref.append(rel_to_ref(qfrc_l, to_canon_vec(r.qfrc)))
        e_pas.append(rel_to_ref(pas_l, to_canon_vec(r.passive)))
        cons = fw.get("constraints", [])
        nrows = sum(len(c.get("force", [])) for c in cons)
        if nrows != r.J.shape[0]:
            rows_bad.add("%d rows (%s), MuJoCo %d" % (
                nrows, ", ".join("%s %s: %d" % (c.get("kind"), c.get("name") or "?", len(c.get("force", []))) for c in cons),
                r.J.shape[0]))
        if r.manifold:
            # JSON null (a NaN in lagrange) counts as NaN, i.e. a failure
            vals = [math.nan if x is None else abs(x) for c in cons for x in c.get("violation", [])]
            if vals:
                viol.append(math.nan if any(math.isnan(x) for x in vals) else max(vals))
        if k in pin_qacc:
            e_pin.append(rel_to_ref(qacc, pin_qacc[k]))
    row["err_mj"] = max(e_mj)
    row["qfrc_self"] = max(e_self)
    row["qfrc_ref"] = max(e_ref)
    row["passive"] = max(e_pas)
    row["viol_manifold"] = (math.nan if any(math.isnan(x) for x in viol) else max(viol)) if viol else math.nan
    if viol and math.isnan(row["viol_manifold"]):
        row["fails"].append("|violation| on the manifold: NaN (null in the JSON) at %d of %d manifold states"
                            % (sum(math.isnan(x) for x in viol), len(viol)))
    if e_pin:
        row["err_pin"] = max(e_pin)
    checks = [("qacc vs MuJoCo-KKT", row["err_mj"], QACC_TOL), ("qacc vs Pinocchio", row["err_pin"], QACC_TOL),
              ("qfrc_constraint vs M qacc − (tau + passive − bias)", row["qfrc_self"], QFRC_TOL),
              ("qfrc_constraint vs reference Jᵀλ", row["qfrc_ref"], QFRC_TOL),
              ("qfrc_passive vs MuJoCo", row["passive"], PASSIVE_TOL),
              ("|violation| on the manifold", row["viol_manifold"], VIOLATION_TOL)]
    for what, e, tol in checks:
        if what == "qacc vs Pinocchio" and not e_pin:
            continue
        if what == "|violation| on the manifold" and (not viol or math.isnan(e)):
            continue  # (NaN reported above)
        if not (e <= tol):
            row["fails"].append("%s: %.2e > %.0e" % (what, e, tol))
    for b in sorted(rows_bad):
        row["fails"].append("constraint rows: " + b)


# ---------------------------------------------------------------------------------------------
# Report
# ---------------------------------------------------------------------------------------------


def fmt_err(e: float) -> str:
    return "—" if e is None or (isinstance(e, float) and math.isnan(e)) else "%.1e" % e


def kinds_text(k: dict) -> str:
    return ", ".join("%s %d" % (n, c) for n, c in k.items()) or "—"


COLUMNS = ["model", "equalities", "nv", "rows (rank)", "states", "vs MuJoCo-KKT", "vs Pinocchio", "Pin vs MJ-KKT",
           "qfrc_constraint", "passive", "|φ| manifold", "ref: FD, J a+J̇v", "result"]


def table_rows(rows: list[dict]) -> list[list[str]]:
    out = []
    for r in rows:
        pin = fmt_err(r["err_pin"]) if r["pin_states"] else ("skipped" if r["pin_skip"] else "—")
        out.append([r["name"], kinds_text(r["kinds"]), str(r["nv"] if r["nv"] is not None else "?"),
                    "%d (%d)" % (r["rows"], r["rank"]), "%d+%d" % (r["states"], r["manifold_states"]),
                    fmt_err(r["err_mj"]), pin, fmt_err(r["pin_vs_mj"]),
                    fmt_err(max(r["qfrc_self"], r["qfrc_ref"]) if not (math.isnan(r["qfrc_self"]) or math.isnan(r["qfrc_ref"])) else math.nan),
                    fmt_err(r["passive"]), fmt_err(r["viol_manifold"]),
                    "%s, %s" % (fmt_err(r["fd_effect"]), fmt_err(r["ref_residual"])), r["result"]])
    return out


def render_text(rows: list[dict], meta: dict) -> str:
    body = table_rows(rows)
    widths = [max(len(COLUMNS[i]), *(len(b[i]) for b in body)) for i in range(len(COLUMNS))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(COLUMNS, widths)), "  ".join("-" * w for w in widths)]
    for b in body:
        lines.append("  ".join(c.ljust(w) for c, w in zip(b, widths)))
    lines.append("")
    for r in rows:
        for f in r["fails"]:
            lines.append("FAIL %s: %s" % (r["name"], f))
    for r in rows:
        if r["pin_skip"]:
            lines.append("Pinocchio skipped on %s: %s" % (r["name"], r["pin_skip"]))
    for r in rows:
        for n in r["notes"]:
            lines.append("note %s: %s" % (r["name"], n))
    return "\n".join(lines)


SECTION = "## Constraints"


def render_markdown(rows: list[dict], meta: dict) -> str:
    n_pass = sum(r["result"] == "PASS" for r in rows)
    out = [SECTION, "",
           "Exact (rigid) equality constraints, `validation/crossval_constraints` (lagrange %s, MuJoCo %s, "
           "Pinocchio %s, %d random states per model plus the same states projected onto the constraint "
           "manifold, %.1f s). **%d of %d models pass.**" % (
               meta["commit"], meta["mujoco"], meta["pinocchio"], meta["states"], meta["seconds"], n_pass, len(rows)),
           "",
           "lagrange's `eval --constraints exact` `forward.qacc` against the rigid KKT solution built from "
           "MuJoCo's own M, qfrc_bias, qfrc_passive and equality rows (efc_J; J̇v by central differences, "
           "h = %g; URDF mimics from the formula) and against Pinocchio's `constraintDynamics` "
           "(CONTACT_3D/6D) or mimic joints. Errors are max|Δ| / max(1, max|ref|) over the states; "
           "tolerance %.0e for qacc and qfrc_constraint, %.0e for qfrc_passive, %.0e for |φ| on the manifold. "
           "`ref: FD, J a+J̇v` is the reference's own uncertainty: how much its qacc moves when the "
           "difference step doubles, and its KKT residual." % (FD_STEP, QACC_TOL, PASSIVE_TOL, VIOLATION_TOL),
           "",
           "| " + " | ".join(c.replace("|", "\\|") for c in COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    for b in table_rows(rows):
        out.append("| " + " | ".join(c.replace("|", "\\|") for c in b) + " |")
    out.append("")
    fails = [(r["name"], f) for r in rows for f in r["fails"]]
    if fails:
        out += ["Failures:", ""] + ["- `%s`: %s" % (n, f) for n, f in fails] + [""]
    skips = [(r["name"], r["pin_skip"]) for r in rows if r["pin_skip"]]
    if skips:
        out += ["Pinocchio not compared:", ""] + ["- `%s`: %s" % s for s in skips] + [""]
    notes = [(r["name"], n) for r in rows for n in r["notes"]]
    if notes:
        out += ["Notes:", ""] + ["- `%s`: %s" % s for s in notes] + [""]
    return "\n".join(out)


def write_section(report: Path, text: str) -> None:
    """Replaces the report's Constraints section (from its heading to the next '## ' heading or
    the end), or appends it."""
    old = report.read_text() if report.exists() else ""
    lines = old.splitlines()
    start = next((i for i, l in enumerate(lines) if l.strip() == SECTION), None)
    if start is None:
        new = old.rstrip("\n") + ("\n\n" if old else "") + text.rstrip("\n") + "\n"
    else:
        end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
        new_lines = lines[:start] + text.rstrip("\n").splitlines() + ([""] + lines[end:] if end < len(lines) else [])
        new = "\n".join(new_lines).rstrip("\n") + "\n"
    report.write_text(new)


# ---------------------------------------------------------------------------------------------


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--states", type=int, default=N_STATES, help="random states per model (default %(default)s)")
    ap.add_argument("--filter", help="only models whose name matches this regex (no report is written)")
    ap.add_argument("--lagrange", type=Path, default=REPO / "target" / "release" / "lagrange")
    ap.add_argument("--report", type=Path, help="Markdown report to add the section to (default validation/report.md "
                                                 "on a full run)")
    ap.add_argument("--no-report", action="store_true", help="write no report")
    ap.add_argument("--reference-only", action="store_true",
                    help="only the references and their self-checks (no lagrange); writes no report")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per lagrange process")
    ap.add_argument("--seed", type=int, default=SEED)
    ap.add_argument("--list", action="store_true", help="print the model set and exit")
    args = ap.parse_args()

    entries = model_set()
    if args.filter:
        entries = [e for e in entries if re.search(args.filter, e.name)]
    if args.list:
        for e in entries:
            print("%-6s %-5s %s" % ("test" if e.source == "tests" else "corpus", e.fmt, e.name))
        return 0
    if not args.reference_only and not args.lagrange.exists():
        print("crossval_constraints: %s does not exist (cargo build --release)" % args.lagrange, file=sys.stderr)
        return 2

    import mujoco
    import pinocchio

    meta = {
        "mujoco": mujoco.__version__, "pinocchio": pinocchio.__version__, "states": args.states,
        "commit": subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True,
                                 text=True).stdout.strip(),
    }
    print("exact equality constraints: %d models, %d random states each (+ manifold), lagrange %s, MuJoCo %s, "
          "Pinocchio %s%s" % (len(entries), args.states, meta["commit"], meta["mujoco"], meta["pinocchio"],
                              ", references only" if args.reference_only else ""), flush=True)
    cfg = {"lagrange": args.lagrange.resolve(), "timeout": args.timeout, "seed": args.seed, "n_states": args.states,
           "reference_only": args.reference_only}
    t0 = time.perf_counter()
    rows = []
    for i, e in enumerate(entries, 1):
        row = process(e, cfg)
        rows.append(row)
        print("[%2d/%d] %-4s %5.1fs  %s%s" % (i, len(entries), row["result"], row["seconds"], row["name"],
                                            ("  — " + row["fails"][0]) if row["fails"] else ""), flush=True)
    meta["seconds"] = time.perf_counter() - t0
    print()
    print(render_text(rows, meta))
    full = not args.filter and not args.reference_only and not args.no_report
    report = args.report or (REPO / "validation" / "report.md" if full else None)
    if report and not args.no_report and not args.reference_only:
        write_section(report, render_markdown(rows, meta))
        print("wrote the Constraints section of %s" % (report.relative_to(REPO) if report.is_relative_to(REPO) else report))
    failed = sum(r["result"] == "FAIL" for r in rows)
    passed = sum(r["result"] == "PASS" for r in rows)
    print("constraints: %d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
