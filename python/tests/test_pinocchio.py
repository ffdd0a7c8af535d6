"""lagrange's kernels against Pinocchio's Python bindings on the URDF robots of models/: RNEA,
CRBA (full symmetric M), ABA, a frame Jacobian in the three reference frames, the centre of
mass and the kinetic and potential energies, at random states (fixed bases; both order the
joints depth-first as the URDF lists them)."""

from __future__ import annotations

import numpy as np
import pytest

import lagrange
from conftest import PANDA, SOLO12, UR5, rel_err

pin = pytest.importorskip("pinocchio")

ROBOTS = [(UR5, "tool0"), (PANDA, "panda_hand"), (SOLO12, "FL_FOOT")]
TOL = 1e-12


def load(path):
    m = lagrange.Model.from_file(path)
    model = pin.buildModelFromUrdf(str(path))
    model.gravity = pin.Motion(np.array(m.opt.gravity), np.zeros(3))
    assert (model.nq, model.nv) == (m.nq, m.nv)
    return m, lagrange.Data(m), model, model.createData()


@pytest.mark.parametrize("path,frame", ROBOTS, ids=lambda x: getattr(x, "stem", x))
def test_kernels_against_pinocchio(path, frame):
    m, d, model, data = load(path)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-1.0, 1.0, m.nq)
        v, a, tau = (rng.standard_normal(m.nv) for _ in range(3))
        assert rel_err(lagrange.rnea(m, d, q, v, a), pin.rnea(model, data, q, v, a)) < TOL
        mass = pin.crba(model, data, q)
        mass = np.triu(mass) + np.triu(mass, 1).T
        ours = lagrange.crba(m, d, q)
        assert np.array_equal(ours, ours.T)
        assert rel_err(ours, mass) < TOL
        assert rel_err(lagrange.aba(m, d, q, v, tau), pin.aba(model, data, q, v, tau)) < 1e-10
        assert abs(lagrange.kinetic_energy(m, d, q, v) - pin.computeKineticEnergy(model, data, q, v)) < 1e-12 * max(
            1.0, abs(pin.computeKineticEnergy(model, data, q, v)))
        assert abs(lagrange.potential_energy(m, d, q) - pin.computePotentialEnergy(model, data, q)) < 1e-11
        d.qpos[:] = q
        assert rel_err(lagrange.center_of_mass(m, d), pin.centerOfMass(model, data, q)) < TOL
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        fid = model.getFrameId(frame)
        for ours_ref, theirs_ref in [("local_world_aligned", pin.LOCAL_WORLD_ALIGNED), ("local", pin.LOCAL),
                                     ("world", pin.WORLD)]:
            theirs = pin.getFrameJacobian(model, data, fid, theirs_ref)
            assert rel_err(lagrange.jacobian(m, d, frame, ours_ref), theirs) < TOL, ours_ref
