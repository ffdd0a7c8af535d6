"""The bindings' own contract: loading and its errors, sizes and names, zero-copy views that keep
their Data alive, keyframes, contact lists, pickling, and bad input (wrong shapes, dtypes,
non-contiguous arrays, NaN, unknown names) raising Python exceptions, never crashing."""

from __future__ import annotations

import gc
import pickle

import numpy as np
import pytest

import lagrange
from conftest import GO1, HUMANOID, ROOT, UR5

PENDULUM = """<mujoco><option timestep="0.01"/><worldbody><body name="arm" pos="0 0 1">
  <joint name="hinge" type="hinge" axis="0 1 0" damping="0.1"/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05" mass="1"/>
  <site name="tip" pos="0.5 0 0"/></body></worldbody>
  <actuator><motor name="motor" joint="hinge"/></actuator>
  <sensor><jointpos name="angle" joint="hinge"/><jointvel name="rate" joint="hinge"/></sensor>
  <keyframe><key name="up" qpos="1.5" qvel="0.5" ctrl="0.2"/></keyframe></mujoco>"""


@pytest.fixture
def pendulum():
    m = lagrange.Model.from_string(PENDULUM)
    return m, lagrange.Data(m)


def test_sizes_names_options(pendulum):
    m, _ = pendulum
    assert (m.nq, m.nv, m.nu, m.na, m.nbody, m.nsensordata, m.nkey) == (1, 1, 1, 0, 2, 2, 1)
    assert m.body_names == ["world", "arm"]
    assert m.name2id("body", "arm") == 1 and m.name2id("joint", "hinge") == 0
    assert m.name2id("actuator", "motor") == 0 and m.name2id("sensor", "rate") == 1
    assert m.name2id("site", "tip") == 0 and m.name2id("key", "up") == 0
    assert m.name2id("body", "nope") == -1
    with pytest.raises(ValueError):
        m.name2id("widget", "arm")
    assert m.opt.timestep == 0.01 and m.opt.gravity == [0.0, 0.0, -9.81]
    assert m.constraints == "soft"
    key = m.keyframe("up")
    assert key["qpos"].tolist() == [1.5] and key["ctrl"].tolist() == [0.2]
    go1 = lagrange.Model.from_file(GO1)
    assert (go1.nq, go1.nv, go1.nu, go1.nbody) == (19, 18, 12, 14)
    ur5 = lagrange.Model.from_file(UR5)
    assert ur5.constraints == "exact" and ur5.nv == 6
    assert lagrange.Model.from_file(GO1, constraints="exact").constraints == "exact"


def test_load_errors_carry_file_and_line(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco>\n<worldbody>\n<body>\n<joint type='hinge'/>\n<geom type='sphere' size='-1'/>\n</body>\n</worldbody>\n</mujoco>\n")
    with pytest.raises(lagrange.LoadError, match=r"bad\.xml:\d+"):
        lagrange.Model.from_file(bad)
    with pytest.raises(lagrange.LoadError):
        lagrange.Model.from_file(tmp_path / "missing.xml")
    with pytest.raises(lagrange.LoadError):
        lagrange.Model.from_string("<html/>")
    with pytest.raises(lagrange.LoadError, match="flag"):
        lagrange.Model.from_string(PENDULUM, disable=["no_such_flag"])
    assert issubclass(lagrange.LoadError, lagrange.LagrangeError)


def test_views_are_zero_copy(pendulum):
    m, d = pendulum
    q = d.qpos
    assert q.base is d and d.qpos.base is d
    assert np.shares_memory(d.qpos, q)
    lagrange.forward(m, d)
    a0 = d.qacc.copy()
    q[0] = 1.0  # through the view: forward sees it
    lagrange.forward(m, d)
    assert d.qacc[0] != a0[0]
    expected = d.qacc.copy()
    d.qpos = [1.0]  # assignment copies into the same buffer
    assert q[0] == 1.0 and np.shares_memory(d.qpos, q)
    qacc = d.qacc
    lagrange.step(m, d)
    assert qacc[0] == expected[0] and q[0] != 1.0  # a view read before the step shows the step
    assert d.sensordata[0] == 1.0  # the sensors of the state the step started from
    d.ctrl[0] = 3.0
    lagrange.forward(m, d)
    assert d.qfrc_actuator[0] == 3.0 and d.actuator_force[0] == 3.0
    d.qfrc_applied[0] = -3.0
    d.xfrc_applied[1, 4] = 0.0
    lagrange.forward(m, d)
    assert d.qfrc_applied.tolist() == [-3.0]
    assert d.xfrc_applied.shape == (2, 6) and d.mocap_pos.shape == (0, 3)


def test_view_keeps_data_alive():
    m = lagrange.Model.from_string(PENDULUM)
    q = lagrange.Data(m).qpos  # the Data object has no other reference
    gc.collect()
    q[0] = 0.5
    assert q[0] == 0.5 and isinstance(q.base, lagrange.Data)


def test_reset_keyframe_time_and_contacts(pendulum):
    m, d = pendulum
    lagrange.reset_keyframe(m, d, "up")
    assert (d.qpos[0], d.qvel[0], d.ctrl[0], d.time) == (1.5, 0.5, 0.2, 0.0)
    lagrange.step(m, d, nstep=10)
    assert abs(d.time - 0.1) < 1e-15
    lagrange.reset(m, d)
    assert (d.qpos[0], d.qvel[0], d.ctrl[0], d.time) == (0.0, 0.0, 0.0, 0.0)
    with pytest.raises(lagrange.InputError, match="keyframe"):
        lagrange.reset_keyframe(m, d, "down")
    go1 = lagrange.Model.from_file(GO1)
    g = lagrange.Data(go1)
    lagrange.reset_keyframe(go1, g, "home")
    lagrange.step(go1, g, nstep=100)
    lagrange.forward(go1, g)
    assert g.ncon == 4 and len(g.contact) == 4
    feet = {go1.body_names[c.body2] for c in g.contact}
    assert feet == {"FR_calf", "FL_calf", "RR_calf", "RL_calf"}
    normal = sum(lagrange.contact_force(go1, g, i)[0] for i in range(g.ncon))
    assert abs(normal - go1.total_mass * 9.81) < 0.05 * go1.total_mass * 9.81
    with pytest.raises(lagrange.InputError):
        lagrange.contact_force(go1, g, 4)


def test_bad_input_raises(pendulum):
    m, d = pendulum
    z = np.zeros(1)
    with pytest.raises(ValueError, match="shape"):
        lagrange.rnea(m, d, np.zeros(2), z, z)
    with pytest.raises(TypeError, match="float64"):
        lagrange.rnea(m, d, np.zeros(1, dtype=np.int64), z, z)
    with pytest.raises(TypeError):
        lagrange.aba(m, d, [0.0], z, z)
    ur5 = lagrange.Model.from_file(UR5)
    with pytest.raises(ValueError, match="contiguous"):
        lagrange.crba(ur5, lagrange.Data(ur5), np.zeros(12)[::2])
    with pytest.raises(ValueError, match="finite"):
        lagrange.aba(m, d, z, np.array([np.nan]), z)
    with pytest.raises(ValueError, match="shape"):
        d.qpos = [1.0, 2.0]
    with pytest.raises(ValueError):
        lagrange.jacobian(m, d, "nowhere")
    with pytest.raises(ValueError):
        lagrange.jacobian(m, d, "tip", reference="sideways")
    d.qpos[0] = np.nan
    with pytest.raises(lagrange.InputError, match="finite"):
        lagrange.forward(m, d)
    with pytest.raises(lagrange.SimulationError):
        lagrange.step(m, d)
    with pytest.raises(lagrange.SimulationError, match="reset"):  # refused until reset
        lagrange.step(m, d)
    lagrange.reset(m, d)
    lagrange.step(m, d)
    other = lagrange.Model.from_file(UR5)
    with pytest.raises(ValueError, match="another model"):
        lagrange.forward(other, d)
    with pytest.raises(ValueError):
        lagrange.rollout(m, np.zeros((2, 3)), nstep=1)
    with pytest.raises(ValueError, match="finite"):
        lagrange.rollout(m, np.full((2, 2), np.nan), nstep=1)
    with pytest.raises(ValueError):
        lagrange.rollout(m, np.zeros((2, 2)), np.zeros((2, 3, 2)))
    with pytest.raises(TypeError):
        lagrange.rollout(m, "states", nstep=1)


def test_pickle_and_from_string_base(pendulum):
    m, _ = pendulum
    again = pickle.loads(pickle.dumps(m))
    assert (again.nq, again.body_names) == (m.nq, m.body_names)
    go1 = lagrange.Model.from_file(GO1)
    assert pickle.loads(pickle.dumps(go1)).path == GO1
    text = (ROOT / "models/mjcf/humanoid/humanoid.xml").read_text()
    h = lagrange.Model.from_string(text, base=HUMANOID.parent)
    assert h.nv == 27 and pickle.loads(pickle.dumps(h)).nv == 27


def test_gil_released_while_stepping(pendulum):
    """Another thread runs Python while one steps many times (nstep > 1 releases the GIL)."""
    import threading

    m = lagrange.Model.from_file(HUMANOID)
    d = lagrange.Data(m)
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(1)

    t = threading.Thread(target=tick)
    t.start()
    lagrange.step(m, d, nstep=2000)
    done.set()
    t.join()
    assert len(ticks) > 100


@pytest.mark.parametrize("integrator", ["Euler", "RK4", "implicit", "implicitfast"])
def test_buffers_never_move(integrator):
    """Every viewed buffer keeps its address through forward, steps of each integrator, reset
    and keyframes: the library moves buffers out and back within a call, never reallocates."""
    xml = PENDULUM.replace('<option timestep="0.01"/>', f'<option timestep="0.01" integrator="{integrator}"/>')
    m = lagrange.Model.from_string(xml)
    d = lagrange.Data(m)
    names = ["qpos", "qvel", "act", "ctrl", "qfrc_applied", "xfrc_applied", "mocap_pos", "mocap_quat", "qacc",
             "qfrc_constraint", "qfrc_bias", "qfrc_passive", "qfrc_actuator", "actuator_force", "sensordata"]
    views = {n: getattr(d, n) for n in names}
    address = {n: v.__array_interface__["data"][0] for n, v in views.items()}
    lagrange.reset_keyframe(m, d, "up")
    lagrange.forward(m, d)
    lagrange.step(m, d, nstep=20)
    lagrange.rnea(m, d, np.array([0.1]), np.zeros(1), np.zeros(1))
    for n in names:
        assert getattr(d, n).__array_interface__["data"][0] == address[n], n
    assert views["qpos"][0] == d.qpos[0] != 1.5 and views["sensordata"][1] == d.sensordata[1]
    lagrange.reset(m, d)
    assert all(getattr(d, n).__array_interface__["data"][0] == address[n] for n in names)


def test_max_contacts_is_a_load_option():
    # Three boxes resting on a plane: 4 corner contacts each (MuJoCo's box-plane points).
    boxes = "".join(
        f"<body pos='{0.3 * k} 0 0.039'><freejoint/><geom type='box' size='0.04 0.04 0.04'/></body>"
        for k in range(3)
    )
    xml = f"<mujoco><worldbody><geom type='plane' size='0 0 1'/>{boxes}</worldbody></mujoco>"
    for budget, kept in ((None, 12), (5, 5)):
        m = lagrange.Model.from_string(xml, max_contacts=budget)
        d = lagrange.Data(m)
        lagrange.forward(m, d)
        assert d.ncon == kept
        # The option travels with the model (pickle reloads it with its options).
        again = pickle.loads(pickle.dumps(m))
        d2 = lagrange.Data(again)
        lagrange.forward(again, d2)
        assert d2.ncon == kept
    assert "contact_full" in d.warnings, d.warnings
