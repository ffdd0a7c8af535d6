#!/usr/bin/env python3
"""Pinocchio's analytic derivatives of RNEA and ABA, in lagrange's conventions, for
lagrange's derivative tests (tests/pinocchio_derivatives.rs).

Run from the repository root with the validation venv (see validation/README.md):

    python validation/pinocchio_derivatives_golden.py          # (re)write tests/data/pinocchio_derivatives/*.json
    python validation/pinocchio_derivatives_golden.py --check  # recompute in memory, exit 1 if a file differs beyond 1e-12

For each URDF corpus robot (ur5, panda fixed; solo12 on a free flyer) and 4 random states drawn
in lagrange's coordinates: computeRNEADerivatives at (q, v, a) and computeABADerivatives at
(q, v, tau), converted to lagrange's coordinates with the exact change-of-variables Jacobians
(joint order and quaternion layout as validation/pinocchio_golden.py's Converter does).

Free flyer (docs/physics.md, "Derivatives of the dynamics", has the derivation). Pinocchio:
v_p = (body-frame linear velocity v_loc, body-frame ω), τ_p the body-frame wrench, a_p = v̇_p,
q-tangent δ_p = (δρ, δθ) with q ⊕ δ_p = M·exp6(δ_p). lagrange (MuJoCo): v = (world linear
velocity, body ω) = G v_p with G = diag(R, I), τ = G τ_p, a = G (a_p + h) with
h = (ω × v_loc, 0), q-tangent δ = (δp world, δθ body), so that δ_p = Gᵀ δ at first order. With
[x] the cross-product matrix and only the root block rows 0:3 of the correction terms non-zero:

  ∂τ/∂v = G (∂τ_p/∂v_p Gᵀ + M_p K),        K[:, lin] = −[ω] Rᵀ, K[:, ang] = [v_loc]
  ∂τ/∂q = G (∂τ_p/∂q_p Gᵀ + ∂τ_p/∂v_p P + M_p A) + E,
          P[:, ang] = [v_loc], A[:, ang] = [Rᵀ a_lin] − [ω][v_loc], E[:, ang] = −R [f_loc]
  ∂q̈/∂τ = G M_p⁻¹ Gᵀ,  ∂q̈/∂v = G (∂a_p/∂v_p Gᵀ + H),  H[:, lin] = [ω] Rᵀ, H[:, ang] = −[v_loc]
  ∂q̈/∂q = G (∂a_p/∂q_p Gᵀ + ∂a_p/∂v_p P + M_p⁻¹ T + Hq) + E',
          T[:, ang] = [τ_loc], Hq[:, ang] = [ω][v_loc], E'[:, ang] = −R [(a_p + h)_lin]

Before anything is written every converted matrix is checked against central differences of
the converted functions along lagrange's own tangent (1e-6 relative).
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from mujoco_golden import check_status, dump  # noqa: E402
from pinocchio_golden import (  # noqa: E402
    EXPECTED,
    GRAVITY,
    ROBOTS,
    Converter,
    our_joint_layout,
    parse_urdf,
    random_state,
)

REPO = pathlib.Path(__file__).resolve().parent.parent
OUT_DIR = REPO / "tests" / "data" / "pinocchio_derivatives"
SCRIPT = "validation/pinocchio_derivatives_golden.py"
SEED = 20261126
N_STATES = 4
CHECK_REL = 1e-12


def skew(x):
    return np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])


def sym_upper(A):
    return np.triu(A) + np.triu(A, 1).T


class Lagrange:
    """Pinocchio's dynamics seen in lagrange's coordinates (Pinocchio's velocity order; the
    Converter permutes at the end)."""

    def __init__(self, model, conv):
        self.model, self.conv, self.data = model, conv, model.createData()
        self.nv = model.nv

    def frames(self, q):
        qp = self.conv.q_to_pin(q)
        G = self.conv.T(qp)
        return qp, G

    def rnea(self, q, v, a):
        qp, G = self.frames(q)
        v_p = G.T @ v
        c = np.zeros(self.nv)
        if self.conv.floating:
            c[0:3] = G[0:3, 0:3] @ np.cross(v_p[3:6], v_p[0:3])
        a_p = G.T @ (a - c)
        return G @ pin.rnea(self.model, self.data, qp, v_p, a_p)

    def aba(self, q, v, tau):
        qp, G = self.frames(q)
        v_p, tau_p = G.T @ v, G.T @ tau
        a_p = pin.aba(self.model, self.data, qp, v_p, tau_p).copy()
        h = np.zeros(self.nv)
        if self.conv.floating:
            h[0:3] = np.cross(v_p[3:6], v_p[0:3])
        return G @ (a_p + h)

    def rnea_derivatives(self, q, v, a):
        qp, G = self.frames(q)
        nv = self.nv
        v_p = G.T @ v
        c = np.zeros(nv)
        fl = self.conv.floating
        if fl:
            c[0:3] = G[0:3, 0:3] @ np.cross(v_p[3:6], v_p[0:3])
        a_p = G.T @ (a - c)
        dq, dv, _ = pin.computeRNEADerivatives(self.model, self.data, qp, v_p, a_p)
        dq, dv = np.array(dq), np.array(dv)
        tau_p = np.array(self.data.tau)
        M = sym_upper(np.array(pin.crba(self.model, self.data, qp)))
        K, P, A, E = (np.zeros((nv, nv)) for _ in range(4))
        if fl:
            R = G[0:3, 0:3]
            v_loc, w = v_p[0:3], v_p[3:6]
            K[0:3, 0:3] = -skew(w) @ R.T
            K[0:3, 3:6] = skew(v_loc)
            P[0:3, 3:6] = skew(v_loc)
            A[0:3, 3:6] = skew(R.T @ a[0:3]) - skew(w) @ skew(v_loc)
            E[0:3, 3:6] = -R @ skew(tau_p[0:3])
        dtau_dv = G @ (dv @ G.T + M @ K)
        dtau_dq = G @ (dq @ G.T + dv @ P + M @ A) + E
        return dtau_dq, dtau_dv

    def aba_derivatives(self, q, v, tau):
        qp, G = self.frames(q)
        nv = self.nv
        v_p, tau_p = G.T @ v, G.T @ tau
        dq, dv, minv = pin.computeABADerivatives(self.model, self.data, qp, v_p, tau_p)
        dq, dv, minv = np.array(dq), np.array(dv), sym_upper(np.array(minv))
        a_p = np.array(self.data.ddq)
        P, T, Hq, H, E = (np.zeros((nv, nv)) for _ in range(5))
        if self.conv.floating:
            R = G[0:3, 0:3]
            v_loc, w = v_p[0:3], v_p[3:6]
            h = np.cross(w, v_loc)
            P[0:3, 3:6] = skew(v_loc)
            T[0:3, 3:6] = skew(tau_p[0:3])
            Hq[0:3, 3:6] = skew(w) @ skew(v_loc)
            H[0:3, 0:3] = skew(w) @ R.T
            H[0:3, 3:6] = -skew(v_loc)
            E[0:3, 3:6] = -R @ skew(a_p[0:3] + h)
        dqacc_dtau = G @ minv @ G.T
        dqacc_dv = G @ (dv @ G.T + H)
        dqacc_dq = G @ (dq @ G.T + dv @ P + minv @ T + Hq) + E
        return dqacc_dq, dqacc_dv, dqacc_dtau

    def integrate(self, q, k, eps):
        """lagrange's q ⊕ eps·e_k (Pinocchio velocity index k; MuJoCo's mj_integratePos)."""
        q = q.copy()
        for name, kind, iq, iv, jid in self.conv.entries:
            jm = self.model.joints[jid]
            if not (jm.idx_v <= k < jm.idx_v + jm.nv):
                continue
            if kind == "free":
                i = k - jm.idx_v
                if i < 3:
                    q[iq + i] += eps
                else:
                    w, x, y, z = q[iq + 3 : iq + 7]
                    quat = pin.Quaternion(w, x, y, z)
                    d = np.zeros(3)
                    d[i - 3] = eps
                    r = quat * pin.Quaternion(pin.exp3(d))
                    q[iq + 3 : iq + 7] = [r.w, r.x, r.y, r.z]
            else:
                q[iq] += eps
        return q


def central(f, x_of, nv, eps=1e-6):
    cols = [(f(x_of(k, eps)) - f(x_of(k, -eps))) / (2 * eps) for k in range(nv)]
    return np.array(cols).T


def assert_close(name, A, B, tol):
    scale = max(np.max(np.abs(A)), np.max(np.abs(B)), 1.0)
    err = np.max(np.abs(A - B)) / scale
    assert err <= tol, "%s: %.3e > %.0e" % (name, err, tol)
    return err


def generate(robot: str, rng) -> dict:
    rel, floating = ROBOTS[robot]
    path = REPO / rel
    _, _, order = parse_urdf(path)
    urdf_joints = {j.name: j for j in order}
    layout = our_joint_layout(order, floating)
    if floating:
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    else:
        model = pin.buildModelFromUrdf(str(path))
    model.gravity = pin.Motion(GRAVITY, np.zeros(3))
    conv = Converter(model, layout, floating)
    assert (conv.nq, conv.nv) == EXPECTED[robot]
    lg = Lagrange(model, conv)
    nv = model.nv
    states = []
    worst = 0.0
    for _ in range(N_STATES):
        q, v, tau = random_state(rng, layout, urdf_joints, nv)
        a = rng.uniform(-3.0, 3.0, nv)
        # lagrange order -> Pinocchio order for the computation
        vp, ap, tp = conv.to_pin_order(v), conv.to_pin_order(a), conv.to_pin_order(tau)
        dtau_dq, dtau_dv = lg.rnea_derivatives(q, vp, ap)
        dqacc_dq, dqacc_dv, dqacc_dtau = lg.aba_derivatives(q, vp, tp)
        # The conversion checked against central differences in lagrange's coordinates.
        e = lambda k: np.eye(nv)[k]  # noqa: E731
        fd = central(lambda x: lg.rnea(x, vp, ap), lambda k, s: lg.integrate(q, k, s), nv)
        worst = max(worst, assert_close("dtau_dq", dtau_dq, fd, 1e-6))
        fd = central(lambda x: lg.rnea(q, x, ap), lambda k, s: vp + s * e(k), nv)
        worst = max(worst, assert_close("dtau_dv", dtau_dv, fd, 1e-6))
        fd = central(lambda x: lg.aba(x, vp, tp), lambda k, s: lg.integrate(q, k, s), nv)
        worst = max(worst, assert_close("dqacc_dq", dqacc_dq, fd, 1e-6))
        fd = central(lambda x: lg.aba(q, x, tp), lambda k, s: vp + s * e(k), nv)
        worst = max(worst, assert_close("dqacc_dv", dqacc_dv, fd, 1e-6))
        fd = central(lambda x: lg.aba(q, vp, x), lambda k, s: tp + s * e(k), nv)
        worst = max(worst, assert_close("dqacc_dtau", dqacc_dtau, fd, 1e-6))
        m = conv.mat_to_ours
        states.append(
            {
                "q": q.tolist(),
                "v": v.tolist(),
                "a": a.tolist(),
                "tau": tau.tolist(),
                "rnea_tau": conv.to_ours(lg.rnea(q, vp, ap)).tolist(),
                "aba_qacc": conv.to_ours(lg.aba(q, vp, tp)).tolist(),
                "dtau_dq": m(dtau_dq).tolist(),
                "dtau_dv": m(dtau_dv).tolist(),
                "dqacc_dq": m(dqacc_dq).tolist(),
                "dqacc_dv": m(dqacc_dv).tolist(),
                "dqacc_dtau": m(dqacc_dtau).tolist(),
            }
        )
    print("%-8s conversion vs central differences: worst %.1e" % (robot, worst), file=sys.stderr)
    return {
        "robot": robot,
        "model": rel,
        "floating": floating,
        "nq": conv.nq,
        "nv": conv.nv,
        "generator": "pinocchio %s, %s" % (pin.__version__, SCRIPT),
        "seed": SEED,
        "conventions": "lagrange's: q columns in MuJoCo's mj_integratePos tangent, free-joint linear "
        "velocity and force in world axes; rows are outputs",
        "states": states,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="recompute in memory; exit 1 if a file differs")
    args = ap.parse_args()
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    stale = []
    for i, robot in enumerate(ROBOTS):
        doc = generate(robot, np.random.default_rng([SEED, i]))
        text = dump(doc) + "\n"
        assert json.loads(text) == json.loads(json.dumps(doc)), "dump() lost information"
        out = OUT_DIR / ("%s.json" % robot)
        old = out.read_text() if out.exists() else None
        if args.check:
            status = check_status(old, text, json.loads(text), CHECK_REL)
            if not status.startswith("ok"):
                stale.append(out.relative_to(REPO).as_posix())
        else:
            status = "unchanged" if old == text else "written"
            if old != text:
                out.write_text(text)
        print("%-8s nv=%-3d %d states  %-9s %s" % (robot, doc["nv"], len(doc["states"]), status,
                                                 out.relative_to(REPO).as_posix()))
    if args.check and stale:
        print("Pinocchio derivative golden data out of date: %s" % ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
