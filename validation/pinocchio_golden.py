#!/usr/bin/env python3
"""Generate Pinocchio golden data for lagrange, in lagrange's conventions.

Run from the repository root with the validation venv (see validation/README.md):

    python validation/pinocchio_golden.py

For each robot in models/ (the mesh-stripped copies written by strip_meshes.py) this
loads the URDF with Pinocchio's parser, draws 6 random states with a fixed seed and
writes tests/data/pinocchio/<robot>.json. Every quantity is converted from Pinocchio's
conventions (joint order, continuous-joint [cos, sin] coordinates, x-y-z-w quaternion,
body-frame free-flyer linear velocity) into lagrange's; see validation/README.md.
The conversion is checked with asserts before anything is written.
"""

from __future__ import annotations

import json
import math
import pathlib
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

REPO = pathlib.Path(__file__).resolve().parent.parent
OUT_DIR = REPO / "tests" / "data" / "pinocchio"

SEED = 20261121
N_STATES = 6
GRAVITY = np.array([0.0, 0.0, -9.81])
ROOT_JOINT = "root_joint"

# robot -> (URDF path relative to the repo root, floating base?)
ROBOTS = {
    "ur5": ("models/ur5/ur5.urdf", False),
    "panda": ("models/panda/panda.urdf", False),
    "solo12": ("models/solo12/solo12.urdf", True),
}

# Expected sizes (nq, nv) in lagrange's coordinates: a sanity check on the models.
EXPECTED = {
    "ur5": (6, 6),
    "panda": (9, 9),
    "solo12": (19, 18),
}


# --------------------------------------------------------------------------------------
# Our joint order, computed from the URDF text alone (independent of Pinocchio)
# --------------------------------------------------------------------------------------


class UrdfJoint:
    def __init__(self, elem: ET.Element):
        self.name = elem.get("name")
        self.type = elem.get("type")
        self.parent = elem.find("parent").get("link")
        self.child = elem.find("child").get("link")
        lim = elem.find("limit")
        self.lower = self.upper = None
        if lim is not None and lim.get("lower") is not None and lim.get("upper") is not None:
            self.lower = float(lim.get("lower"))
            self.upper = float(lim.get("upper"))
        self.mimic = elem.find("mimic") is not None


def parse_urdf(path: pathlib.Path):
    root = ET.parse(path).getroot()
    links = [l.get("name") for l in root.findall("link")]
    joints = [UrdfJoint(j) for j in root.findall("joint")]
    children = {}
    child_links = set()
    for j in joints:
        children.setdefault(j.parent, []).append(j)  # file order
        child_links.add(j.child)
    roots = [l for l in links if l not in child_links]
    assert len(roots) == 1, "expected exactly one root link, got %s" % roots
    order = []  # all joints (fixed included) in DFS pre-order, file order among siblings

    def visit(link):
        for j in children.get(link, []):
            order.append(j)
            visit(j.child)

    visit(roots[0])
    assert len(order) == len(joints), "URDF is not a tree"
    return links, roots[0], order


def our_joint_layout(order, floating):
    """List of (name, kind, nq, nv) in lagrange order, where kind is one of
    'free', 'revolute', 'prismatic', 'continuous'."""
    layout = []
    if floating:
        layout.append((ROOT_JOINT, "free", 7, 6))
    for j in order:
        if j.type == "fixed":
            continue
        if j.type in ("revolute", "prismatic", "continuous"):
            layout.append((j.name, j.type, 1, 1))
        else:
            raise NotImplementedError("joint type %r (%s)" % (j.type, j.name))
    return layout


# --------------------------------------------------------------------------------------
# Conversion helpers
# --------------------------------------------------------------------------------------


def quat_wxyz_from_rot(R: np.ndarray) -> list[float]:
    x, y, z, w = pin.Quaternion(R).coeffs()
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    return [float(w), float(x), float(y), float(z)]


class Converter:
    """Maps between lagrange coordinates and Pinocchio coordinates for one model."""

    def __init__(self, model: pin.Model, layout, floating: bool):
        self.model = model
        self.layout = layout
        self.floating = floating
        self.nq = sum(l[2] for l in layout)
        self.nv = sum(l[3] for l in layout)
        assert self.nv == model.nv, (self.nv, model.nv)
        # For each of our joints: (our q offset, our v offset, pinocchio joint id)
        self.entries = []
        iq = iv = 0
        vperm = []  # vperm[k] = Pinocchio velocity index of our velocity coordinate k
        for name, kind, nq, nv in layout:
            assert model.existJointName(name), "Pinocchio has no joint %r" % name
            jid = model.getJointId(name)
            jm = model.joints[jid]
            if kind == "free":
                assert jm.shortname() == "JointModelFreeFlyer", jm.shortname()
                assert jid == 1 and jm.idx_q == 0 and jm.idx_v == 0
            else:
                assert jm.nv == 1, (name, jm.shortname())
                # nq == 2: unbounded revolute, Pinocchio stores [cos, sin]
                assert jm.nq in (1, 2), (name, jm.shortname())
                if kind == "continuous":
                    assert jm.nq == 2, (name, jm.shortname())
            self.entries.append((name, kind, iq, iv, jid))
            vperm.extend(range(jm.idx_v, jm.idx_v + jm.nv))
            iq += nq
            iv += nv
        assert sorted(vperm) == list(range(model.nv)), "velocity map is not a permutation"
        self.vperm = np.array(vperm)
        # every Pinocchio joint (except the universe) must be one of ours
        pin_names = {model.names[i] for i in range(1, model.njoints)}
        assert pin_names == {e[0] for e in self.entries}, pin_names ^ {e[0] for e in self.entries}

    # --- q ---
    def q_to_pin(self, q: np.ndarray) -> np.ndarray:
        qp = np.zeros(self.model.nq)
        for name, kind, iq, iv, jid in self.entries:
            jm = self.model.joints[jid]
            if kind == "free":
                x, y, z, qw, qx, qy, qz = q[iq : iq + 7]
                qp[0:7] = [x, y, z, qx, qy, qz, qw]
            elif jm.nq == 2:
                qp[jm.idx_q] = math.cos(q[iq])
                qp[jm.idx_q + 1] = math.sin(q[iq])
            else:
                qp[jm.idx_q] = q[iq]
        return qp

    def q_from_pin(self, qp: np.ndarray) -> np.ndarray:
        q = np.zeros(self.nq)
        for name, kind, iq, iv, jid in self.entries:
            jm = self.model.joints[jid]
            if kind == "free":
                x, y, z, qx, qy, qz, qw = qp[0:7]
                q[iq : iq + 7] = [x, y, z, qw, qx, qy, qz]
            elif jm.nq == 2:
                q[iq] = math.atan2(qp[jm.idx_q + 1], qp[jm.idx_q])
            else:
                q[iq] = qp[jm.idx_q]
        return q

    # --- T = blockdiag(R, I3, I) in Pinocchio's velocity order; v_ours = P T v_pin ---
    def T(self, qp: np.ndarray) -> np.ndarray:
        T = np.eye(self.model.nv)
        if self.floating:
            T[0:3, 0:3] = pin.Quaternion(qp[3:7]).normalized().toRotationMatrix()
        return T

    def to_ours(self, x_pin_order: np.ndarray) -> np.ndarray:
        """Permute a vector (already frame-converted) from Pinocchio order to ours."""
        return x_pin_order[self.vperm]

    def to_pin_order(self, x_ours: np.ndarray) -> np.ndarray:
        x = np.zeros_like(x_ours)
        x[self.vperm] = x_ours
        return x

    def mat_to_ours(self, A: np.ndarray) -> np.ndarray:
        return A[np.ix_(self.vperm, self.vperm)]


# --------------------------------------------------------------------------------------
# Random states (drawn in our coordinates)
# --------------------------------------------------------------------------------------


def random_state(rng, layout, urdf_joints, nv):
    q = []
    for name, kind, nq, _ in layout:
        if kind == "free":
            pos = rng.uniform(-1.0, 1.0, 3)
            quat = rng.standard_normal(4)
            quat /= np.linalg.norm(quat)
            if quat[0] < 0:
                quat = -quat
            q.extend(pos.tolist() + quat.tolist())
        else:
            j = urdf_joints[name]
            if kind != "continuous" and j.lower is not None and j.lower < j.upper:
                q.append(rng.uniform(j.lower, j.upper))
            else:
                q.append(rng.uniform(-math.pi, math.pi))
    v = rng.uniform(-2.0, 2.0, nv)
    tau = rng.uniform(-5.0, 5.0, nv)
    return np.array(q), v, tau


# --------------------------------------------------------------------------------------
# Golden data for one state
# --------------------------------------------------------------------------------------


def rel_close(a, b, tol, scale=1.0):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    err = np.max(np.abs(a - b)) if a.size else 0.0
    ref = max(scale, np.max(np.abs(a)) if a.size else 0.0, np.max(np.abs(b)) if b.size else 0.0)
    return err <= tol * ref, err, ref


def check(cond_tuple, what):
    ok, err, ref = cond_tuple
    assert ok, "%s: max abs error %.3e (scale %.3e)" % (what, err, ref)


def compute_state(model, data, conv: Converter, links, q, v, tau):
    nv = model.nv
    qp = conv.q_to_pin(q)
    assert np.allclose(conv.q_from_pin(qp), q, rtol=0, atol=1e-12)
    T = conv.T(qp)
    Tinv = np.linalg.inv(T)

    # our v, tau in Pinocchio order (still our frames) -> Pinocchio frames
    v_o = conv.to_pin_order(v)  # = T v_pin
    tau_o = conv.to_pin_order(tau)
    v_pin = Tinv @ v_o
    tau_pin = T.T @ tau_o

    # Pinocchio quantities
    M_pin = pin.crba(model, data, qp).copy()
    M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
    b_pin = pin.rnea(model, data, qp, v_pin, np.zeros(nv)).copy()
    a_pin = pin.aba(model, data, qp, v_pin, tau_pin).copy()
    kinetic = pin.computeKineticEnergy(model, data, qp, v_pin)
    potential = pin.computePotentialEnergy(model, data, qp)
    com = pin.centerOfMass(model, data, qp).copy()
    total_mass = data.mass[0]

    # c = d/dt(T) v_pin = [R (omega x v_local_lin); 0]
    c = np.zeros(nv)
    if conv.floating:
        R = T[0:3, 0:3]
        v_lin, omega = v_pin[0:3], v_pin[3:6]
        c[0:3] = R @ np.cross(omega, v_lin)

    M_o = Tinv.T @ M_pin @ Tinv
    qacc_o = T @ a_pin + c
    bias_o = Tinv.T @ b_pin - M_o @ c

    M = conv.mat_to_ours(M_o)
    qacc = conv.to_ours(qacc_o)
    bias = conv.to_ours(bias_o)

    # ---- verification -------------------------------------------------------------
    # (a) equation of motion in our coordinates
    lhs = M @ qacc + bias
    scale = max(1.0, np.max(np.abs(tau)), np.max(np.abs(M @ qacc)), np.max(np.abs(bias)))
    check(rel_close(lhs, tau, 1e-9, scale), "M qacc + bias == tau")
    # symmetric positive definite mass matrix
    check(rel_close(M, M.T, 1e-12), "M symmetric")
    assert np.all(np.linalg.eigvalsh(M) > 0), "M not positive definite"
    # (b) kinetic energy = 1/2 v^T M v with our v and M
    check(rel_close(0.5 * v @ M @ v, kinetic, 1e-10, 1e-3), "kinetic == 1/2 v^T M v")
    # independent RNEA: generalized force giving zero *our* acceleration is our bias
    a_pin_zero = Tinv @ (np.zeros(nv) - c)
    tau_zero = conv.to_ours(Tinv.T @ pin.rnea(model, data, qp, v_pin, a_pin_zero))
    check(rel_close(tau_zero, bias, 1e-9), "bias == RNEA at zero our-acceleration")
    # ABA agrees with solving our M, bias
    check(rel_close(np.linalg.solve(M, tau - bias), qacc, 1e-8), "qacc == M^-1 (tau - bias)")
    # (c) finite differences along the true trajectory:
    #   qacc == d/dt of our v, and the root link's world position moves with v[0:3]
    h = 1e-5

    def v_ours_at(t):
        qt = pin.integrate(model, qp, v_pin * t + 0.5 * a_pin * t * t)
        return conv.to_ours(conv.T(qt) @ (v_pin + a_pin * t)), qt

    (vp, qph), (vm, qmh) = v_ours_at(h), v_ours_at(-h)
    check(rel_close((vp - vm) / (2 * h), qacc, 1e-6), "qacc == finite-difference d/dt v")
    if conv.floating:
        check(
            rel_close((qph[0:3] - qmh[0:3]) / (2 * h), v[0:3], 1e-6),
            "root linear velocity == finite-difference d/dt position (world frame)",
        )

    # ---- poses ----------------------------------------------------------------------
    pin.forwardKinematics(model, data, qp)
    pin.updateFramePlacements(model, data)
    poses = {}
    for name in links:
        assert model.existFrame(name, pin.FrameType.BODY), "no BODY frame for link %r" % name
        fid = model.getFrameId(name, pin.FrameType.BODY)
        oMf = data.oMf[fid]
        poses[name] = {
            "pos": [float(x) for x in oMf.translation],
            "quat": quat_wxyz_from_rot(oMf.rotation),
        }
    if conv.floating:
        # root pose must match q
        root_link = links_root(model)
        assert np.allclose(poses[root_link]["pos"], q[0:3], atol=1e-12)
        assert np.allclose(np.abs(np.dot(poses[root_link]["quat"], q[3:7])), 1.0, atol=1e-12)

    return {
        "q": q.tolist(),
        "v": v.tolist(),
        "tau": tau.tolist(),
        "M": M.tolist(),
        "bias": bias.tolist(),
        "qacc": qacc.tolist(),
        "poses": poses,
        "kinetic": float(kinetic),
        "potential": float(potential),
        "com": [float(x) for x in com],
        "total_mass": float(total_mass),
    }


def links_root(model):
    """Name of the BODY frame attached to the free-flyer joint with identity placement."""
    for f in model.frames:
        if f.type == pin.FrameType.BODY and f.parentJoint == 1 and f.placement.isIdentity():
            return f.name
    raise AssertionError("no root body frame")


# --------------------------------------------------------------------------------------
# JSON output (compact: numeric arrays on one line, full float precision)
# --------------------------------------------------------------------------------------


def dump(obj, indent=0):
    pad = " " * indent
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        items = [
            "%s %s: %s" % (pad, json.dumps(k), dump(v, indent + 1)) for k, v in obj.items()
        ]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, list):
        if all(not isinstance(x, (list, dict)) for x in obj):
            return json.dumps(obj)
        if all(isinstance(x, list) and all(not isinstance(y, (list, dict)) for y in x) for x in obj):
            return "[\n" + ",\n".join(pad + "  " + json.dumps(x) for x in obj) + "\n" + pad + "]"
        return "[\n" + ",\n".join(pad + "  " + dump(x, indent + 2) for x in obj) + "\n" + pad + "]"
    if isinstance(obj, float):
        assert math.isfinite(obj)
    return json.dumps(obj)


# --------------------------------------------------------------------------------------


def generate(robot: str, rng) -> dict:
    rel, floating = ROBOTS[robot]
    path = REPO / rel
    links, root_link, order = parse_urdf(path)
    urdf_joints = {j.name: j for j in order}
    layout = our_joint_layout(order, floating)

    if floating:
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    else:
        model = pin.buildModelFromUrdf(str(path))
    model.gravity = pin.Motion(GRAVITY, np.zeros(3))
    data = model.createData()
    conv = Converter(model, layout, floating)
    assert (conv.nq, conv.nv) == EXPECTED[robot], (robot, conv.nq, conv.nv)
    if floating:
        assert links_root(model) == root_link, (links_root(model), root_link)

    # Bodies welded to the world (fixed base only): Pinocchio lumps them into the
    # universe inertia and leaves them out of mass/com/potential energy.
    world_fixed_links = [
        f.name
        for f in model.frames
        if f.type == pin.FrameType.BODY and f.parentJoint == 0 and f.name in links
    ]
    I0 = model.inertias[0]

    notes = []
    mimic = [j.name for j in order if j.mimic and j.type != "fixed"]
    if mimic:
        notes.append(
            "URDF <mimic> ignored (Pinocchio default, mimic=False): joints %s are "
            "independent degrees of freedom" % ", ".join(mimic)
        )
    if world_fixed_links:
        notes.append(
            "total_mass, com and potential exclude the links welded to the world "
            "(see world_fixed); Pinocchio's convention"
        )
    notes.append("URDF <dynamics> damping/friction and <transmission> are not modelled")

    states = []
    for _ in range(N_STATES):
        q, v, tau = random_state(rng, layout, urdf_joints, conv.nv)
        states.append(compute_state(model, data, conv, links, q, v, tau))

    return {
        "robot": robot,
        "model": rel,
        "floating": floating,
        "gravity": GRAVITY.tolist(),
        "nq": conv.nq,
        "nv": conv.nv,
        "joint_names": [l[0] for l in layout],
        "generator": "pinocchio %s" % pin.__version__,
        "seed": SEED,
        "root_link": root_link,
        "world_fixed": {
            "links": world_fixed_links,
            "mass": float(I0.mass),
            "com": [float(x) for x in I0.lever],
        },
        "notes": notes,
        "states": states,
    }


def main() -> int:
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    for i, robot in enumerate(ROBOTS):
        # one independent, reproducible stream per robot
        rng = np.random.default_rng([SEED, i])
        doc = generate(robot, rng)
        out = OUT_DIR / ("%s.json" % robot)
        text = dump(doc) + "\n"
        assert json.loads(text) == json.loads(json.dumps(doc))
        out.write_text(text)
        print(
            "%-14s nq=%-3d nv=%-3d mass=%-10.6g -> %s (%d bytes)"
            % (robot, doc["nq"], doc["nv"], doc["states"][0]["total_mass"], out.relative_to(REPO), len(text))
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
