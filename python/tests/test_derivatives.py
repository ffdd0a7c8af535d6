"""The derivative functions of the bindings: RNEA and ABA derivatives against Pinocchio's
computeRNEADerivatives / computeABADerivatives on the fixed-base URDF arms (the same joint
coordinates, so no change of variables), and the transition Jacobians against MuJoCo's
mjd_transitionFD on a contact-free MJCF model, plus bad input."""

from __future__ import annotations

import numpy as np
import pytest

import lagrange
from conftest import PANDA, ROOT, UR5, rel_err

pin = pytest.importorskip("pinocchio")
mujoco = pytest.importorskip("mujoco")


@pytest.mark.parametrize("path", [UR5, PANDA], ids=lambda p: p.stem)
def test_rnea_and_aba_derivatives_against_pinocchio(path):
    m = lagrange.Model.from_file(path)
    d = lagrange.Data(m)
    model = pin.buildModelFromUrdf(str(path))
    model.gravity = pin.Motion(np.array(m.opt.gravity), np.zeros(3))
    data = model.createData()
    rng = np.random.default_rng(7)
    for _ in range(3):
        q = rng.uniform(-1.0, 1.0, m.nq)
        v, a, tau = (rng.standard_normal(m.nv) for _ in range(3))
        dq, dv = lagrange.rnea_derivatives(m, d, q, v, a)
        pdq, pdv, _ = pin.computeRNEADerivatives(model, data, q, v, a)
        assert rel_err(dq, pdq) < 1e-9 and rel_err(dv, pdv) < 1e-9
        dq, dv, dtau = lagrange.aba_derivatives(m, d, q, v, tau)
        pdq, pdv, pdtau = pin.computeABADerivatives(model, data, q, v, tau)
        pdtau = np.triu(pdtau) + np.triu(pdtau, 1).T
        assert rel_err(dq, pdq) < 1e-9 and rel_err(dv, pdv) < 1e-9 and rel_err(dtau, pdtau) < 1e-9


def test_transition_jacobians_against_mujoco():
    path = ROOT / "models/textbook/damped_double_pendulum.xml"
    m = lagrange.Model.from_file(path)
    d = lagrange.Data(m)
    d.qpos[:] = [0.4, -0.3]
    d.qvel[:] = [0.2, 0.1]
    A, B = lagrange.transition_jacobians(m, d, eps=1e-6, centered=True)
    assert list(d.qpos) == [0.4, -0.3], "the state is restored"
    mm = mujoco.MjModel.from_xml_path(str(path))
    md = mujoco.MjData(mm)
    md.qpos[:] = [0.4, -0.3]
    md.qvel[:] = [0.2, 0.1]
    n = 2 * mm.nv + mm.na
    Am, Bm = np.zeros((n, n)), np.zeros((n, mm.nu))
    mujoco.mjd_transitionFD(mm, md, 1e-6, True, Am, Bm, None, None)
    assert A.shape == Am.shape and B.shape == Bm.shape
    assert rel_err(A, Am) < 1e-6
    Ah, Bh = lagrange.transition_jacobians(m, d, method="hybrid")
    assert rel_err(Ah, Am) < 1e-6 and Bh.shape == B.shape


def test_derivative_arguments_are_checked():
    m = lagrange.Model.from_file(UR5)
    d = lagrange.Data(m)
    with pytest.raises(lagrange.InputError):
        lagrange.rnea_derivatives(m, d, np.zeros(5), np.zeros(6), np.zeros(6))
    with pytest.raises(lagrange.InputError):
        lagrange.aba_derivatives(m, d, np.zeros(6), np.full(6, np.nan), np.zeros(6))
    with pytest.raises(lagrange.LagrangeError):
        lagrange.transition_jacobians(m, d, eps=-1.0)
    with pytest.raises(ValueError):
        lagrange.transition_jacobians(m, d, method="analytic")
