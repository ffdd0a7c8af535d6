"""`lagrange.rollout`: the same result bit for bit for any thread count, and equal bit for bit to
the same rollouts stepped one by one from a fresh Data with per-step controls; sensors recorded
as mj_step leaves them; a failing rollout reports its error and the others go on."""

from __future__ import annotations

import numpy as np
import pytest

import lagrange
from conftest import GO1, SENSOR_SCENES


def batch(m, nbatch, nstep, seed=0):
    rng = np.random.default_rng(seed)
    d = lagrange.Data(m)
    if m.nkey:
        lagrange.reset_keyframe(m, d, 0)
    states = np.tile(np.concatenate([d.qpos, d.qvel, d.act]), (nbatch, 1))
    states[:, m.nq:m.nq + m.nv] += 0.2 * rng.standard_normal((nbatch, m.nv))
    controls = 0.3 * rng.standard_normal((nbatch, nstep, m.nu))
    return states, controls


def one_by_one(m, states, controls):
    nbatch, nstep, _ = controls.shape
    out = {k: [] for k in ("qpos", "qvel", "act", "time", "sensordata")}
    for i in range(nbatch):
        d = lagrange.Data(m)
        d.qpos[:] = states[i, :m.nq]
        d.qvel[:] = states[i, m.nq:m.nq + m.nv]
        d.act[:] = states[i, m.nq + m.nv:]
        rows = {k: [] for k in out}

        def record():
            rows["qpos"].append(d.qpos.copy())
            rows["qvel"].append(d.qvel.copy())
            rows["act"].append(d.act.copy())
            rows["time"].append(d.time)

        record()
        for k in range(nstep):
            d.ctrl[:] = controls[i, k]
            lagrange.step(m, d)
            rows["sensordata"].append(d.sensordata.copy())
            record()
        lagrange.forward(m, d)
        rows["sensordata"].append(d.sensordata.copy())
        for k in out:
            out[k].append(np.array(rows[k]))
    return {k: np.array(v) for k, v in out.items()}


@pytest.mark.parametrize("path", [GO1, SENSOR_SCENES[1]], ids=lambda p: p.stem)
def test_rollout_equals_one_by_one_for_any_thread_count(path):
    m = lagrange.Model.from_file(path)
    states, controls = batch(m, 5, 40)
    reference = one_by_one(m, states, controls)
    for threads in (1, 2, 3, None):
        out = lagrange.rollout(m, states, controls, 40, threads=threads)
        assert out["error"] == [None] * 5
        assert out["qpos"].shape == (5, 41, m.nq) and out["sensordata"].shape == (5, 41, m.nsensordata)
        for key, value in reference.items():
            assert np.array_equal(out[key], value), (threads, key)
    assert not np.array_equal(reference["qpos"][0], reference["qpos"][1])


def test_rollout_without_controls_and_failures():
    # A spring far too stiff for the step: it diverges from a displaced start, not from rest.
    m = lagrange.Model.from_string("""<mujoco><option timestep="0.01" gravity="0 0 0"/><worldbody><body>
        <joint type="slide" axis="0 0 1" stiffness="1e10"/><geom size="0.1" mass="1"/></body></worldbody></mujoco>""")
    states = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]])
    out = lagrange.rollout(m, states, nstep=100, threads=1)
    assert out["error"][0] is None and "diverged" in out["error"][1].lower()
    assert np.all(np.isfinite(out["qpos"][0])) and np.isnan(out["qpos"][1, -1, 0])
    # The rollouts after a failed one (on the same worker's Data) are unaffected.
    assert out["error"][2] is None and np.array_equal(out["qpos"][2], out["qpos"][0])
    assert np.array_equal(out["time"][0, :4], [0.0, 0.01, 0.02, 0.03])
    empty = lagrange.rollout(m, np.zeros((0, 2)), nstep=2)
    assert empty["qpos"].shape == (0, 3, 1)
