"""`lagrange.distributed.rollout` on a local Ray cluster of 2 worker CPUs: the same arrays as
`lagrange.rollout`, bit for bit, with the model given as a path or as a Model, in
chunks smaller than the batch; and the sweep helper over model variants loaded from text."""

from __future__ import annotations

import numpy as np
import pytest

import lagrange
from conftest import GO1
from test_rollout import batch

pytest.importorskip("ray")


def test_distributed_equals_local(cluster, tmp_path, monkeypatch):
    import lagrange.distributed as dist

    m = lagrange.Model.from_file(GO1)
    states, controls = batch(m, 7, 25, seed=4)
    local = lagrange.rollout(m, states, controls, 25, threads=1)
    monkeypatch.chdir(tmp_path)  # the workers do not rely on the driver's working directory
    for model, chunk in [(str(GO1), 3), (m, None)]:
        out = dist.rollout(model, states, controls, 25, chunk=chunk)
        assert out["error"] == [None] * 7
        for key in ("qpos", "qvel", "act", "time", "sensordata"):
            assert np.array_equal(out[key], local[key]), key


def test_sweep(cluster):
    import lagrange.distributed as dist

    xml = """<mujoco><worldbody><body><joint type="hinge" axis="0 1 0" damping="{}"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/></body></worldbody></mujoco>"""
    models = [lagrange.Model.from_string(xml.format(c)) for c in (0.0, 0.5, 2.0)]
    states = np.array([[0.3, 0.0]])
    outs = dist.sweep(models, states, nstep=100)
    for model, out in zip(models, outs):
        assert np.array_equal(out["qpos"], lagrange.rollout(model, states, nstep=100)["qpos"])
    finals = [abs(out["qvel"][0, -1, 0]) for out in outs]
    assert finals[0] > finals[1] > finals[2]
