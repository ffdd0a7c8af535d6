"""lagrange's bindings against MuJoCo's Python bindings on the same scenes and states: the mass
matrix, bias forces, qacc, contact forces (mj_contactForce), sensors, and one step (mj_step).

Scenes are tight copies (Newton solves to round-off) so both engines meet the same optimum of
the soft contact problem; states are MuJoCo's own simulation from the keyframe, 50 steps on,
with random velocities and controls. Measured on 2026-11-26: M ≤ 7e-16, bias ≤ 5e-16, qacc
≤ 1.5e-11 (go1), contact forces ≤ 1.1e-10 (go1), sensors ≤ 2e-13, one step qvel ≤ 2.1e-10."""

from __future__ import annotations

import numpy as np
import pytest

import lagrange
from conftest import GO1, HUMANOID, SENSOR_SCENES, rel_err

mj = pytest.importorskip("mujoco")

SCENES = [GO1, HUMANOID] + SENSOR_SCENES
TOL = {"M": 1e-13, "bias": 1e-13, "qacc": 1e-9, "contact": 1e-8, "sensors": 1e-10, "qpos": 1e-11, "qvel": 1e-8}


def same_state(path, seed=1):
    """MuJoCo and lagrange at the same state of scene `path` (after MuJoCo's forward)."""
    mm = mj.MjModel.from_xml_path(str(path))
    md = mj.MjData(mm)
    m = lagrange.Model.from_file(path)
    d = lagrange.Data(m)
    if mm.nkey:
        mj.mj_resetDataKeyframe(mm, md, 0)
        lagrange.reset_keyframe(m, d, 0)
    rng = np.random.default_rng(seed)
    for _ in range(50):
        mj.mj_step(mm, md)
    md.qvel[:] += 0.1 * rng.standard_normal(mm.nv)
    if mm.nu:
        md.ctrl[:] = 0.1 * rng.standard_normal(mm.nu)
    d.qpos[:] = md.qpos
    d.qvel[:] = md.qvel
    d.ctrl[:] = md.ctrl
    d.act[:] = md.act
    d.time = md.time
    mj.mj_forward(mm, md)
    lagrange.forward(m, d)
    return mm, md, m, d


@pytest.mark.parametrize("scene", SCENES, ids=lambda p: p.stem)
def test_forward_against_mujoco(scene, tight_copy):
    mm, md, m, d = same_state(tight_copy(scene))
    assert (m.nq, m.nv, m.nu, m.na, m.nsensordata) == (mm.nq, mm.nv, mm.nu, mm.na, mm.nsensordata)
    full = np.zeros((mm.nv, mm.nv))
    mj.mj_fullM(mm, md, full)
    q, v = np.array(d.qpos), np.array(d.qvel)
    assert rel_err(lagrange.crba(m, d, q), full) < TOL["M"]
    assert rel_err(lagrange.rnea(m, d, q, v, np.zeros(m.nv)), md.qfrc_bias) < TOL["bias"]
    assert rel_err(d.qacc, md.qacc) < TOL["qacc"]
    if mm.nsensordata:
        assert rel_err(d.sensordata, md.sensordata) < TOL["sensors"]
    assert d.ncon == md.ncon
    if md.ncon:
        ours = np.array([lagrange.contact_force(m, d, i) for i in range(d.ncon)])
        theirs = np.zeros((md.ncon, 6))
        for i in range(md.ncon):
            mj.mj_contactForce(mm, md, i, theirs[i])
        assert [(c.geom1, c.geom2) for c in d.contact] == [(md.contact[i].geom1, md.contact[i].geom2) for i in range(md.ncon)]
        assert rel_err(ours, theirs) < TOL["contact"]
        assert np.array_equal(np.array([c.force for c in d.contact]), ours)
        assert rel_err([c.dist for c in d.contact], md.contact.dist) < 1e-12
        assert rel_err([c.pos for c in d.contact], md.contact.pos) < 1e-12


@pytest.mark.parametrize("scene", SCENES, ids=lambda p: p.stem)
def test_step_against_mujoco(scene, tight_copy):
    mm, md, m, d = same_state(tight_copy(scene), seed=2)
    mj.mj_step(mm, md)
    lagrange.step(m, d)
    assert d.time == md.time
    assert rel_err(d.qpos, md.qpos) < TOL["qpos"]
    assert rel_err(d.qvel, md.qvel) < TOL["qvel"]
    if mm.nsensordata:  # the sensors of the state the step started from, as mj_step
        assert rel_err(d.sensordata, md.sensordata) < TOL["sensors"]


def test_body_poses_against_mujoco(tight_copy):
    mm, md, m, d = same_state(tight_copy(GO1))
    assert m.nbody == mm.nbody
    for b in range(mm.nbody):
        name = mj.mj_id2name(mm, mj.mjtObj.mjOBJ_BODY, b)
        assert m.name2id("body", name) == b
    assert rel_err(d.xpos, md.xpos) < 1e-14
    assert rel_err(d.xquat, md.xquat) < 1e-14
    assert rel_err(d.xmat, md.xmat) < 1e-14
    assert rel_err(lagrange.center_of_mass(m, d), md.subtree_com[0]) < 1e-14


def test_delayed_controls_against_mujoco():
    """Delayed actuators (delay, nsample, interp) stepped from the reset state with changing
    controls: the history buffers (a writable state array, MuJoCo's layout), the forces and the
    state after every step; a history set from MuJoCo's mid-run state continues as MuJoCo's."""
    from conftest import ROOT

    path = ROOT / "tests/data/mjcf/delay/arm_rk4.xml"
    mm = mj.MjModel.from_xml_path(str(path))
    md = mj.MjData(mm)
    m = lagrange.Model.from_file(path)
    d = lagrange.Data(m)
    assert m.nhistory == mm.nhistory
    assert np.array_equal(d.history, md.history)
    rng = np.random.default_rng(5)
    for _ in range(20):
        md.ctrl[:] = d.ctrl[:] = rng.uniform(-1, 1, mm.nu)
        mj.mj_step(mm, md)
        lagrange.step(m, d)
        assert rel_err(d.history, md.history) < 1e-14
        assert rel_err(d.actuator_force, md.actuator_force) < 1e-9
        assert rel_err(d.qvel, md.qvel) < 1e-9
    # Continue from MuJoCo's state, history included.
    d.qpos[:], d.qvel[:], d.act[:], d.history[:], d.time = md.qpos, md.qvel, md.act, md.history, md.time
    md.ctrl[:] = d.ctrl[:] = 0.7
    mj.mj_step(mm, md)
    lagrange.step(m, d)
    assert rel_err(d.qvel, md.qvel) < 1e-9
    assert rel_err(d.history, md.history) < 1e-14
