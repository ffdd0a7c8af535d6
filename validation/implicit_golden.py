#!/usr/bin/env python3
"""Golden values for tests/implicit.rs (issue 15): MuJoCo's `mj_step` with integrator="implicit"
on damped passive scenes, from the initial states below; prints the final qpos/qvel as Rust
constants.

    validation/.venv/bin/python validation/implicit_golden.py
"""
import os

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TEXTBOOK = os.path.join(HERE, "..", "models", "textbook")

# (name, file, qpos0, qvel0, steps): the double pendulum swung hard so that Coriolis terms are
# large; the mixed tree (ball, hinge, slide, free) spinning.
CASES = [
    ("DOUBLE_PENDULUM", "damped_double_pendulum.xml", [1.0, -0.5], [4.0, -6.0], 100),
    (
        "MIXED_TREE",
        "damped_mixed_tree.xml",
        [0.9, 0.3, 0.2, 0.1, 0.4, 0.05, 1.0, 0.0, 1.0, 0.98006657784, 0.0, 0.19866933080, 0.0],
        [3.0, -2.0, 8.0, 5.0, 0.3, 0.5, -0.2, 1.0, 6.0, -4.0, 10.0],
        200,
    ),
]


def run(m, q0, v0, steps, integrator):
    """`steps` mj_steps of `integrator` from (q0, v0); returns the final MjData."""
    m.opt.integrator = integrator
    d = mujoco.MjData(m)
    d.qpos[:] = q0
    d.qvel[:] = v0
    mujoco.mj_normalizeQuat(m, d.qpos)
    for _ in range(steps):
        mujoco.mj_step(m, d)
    return d


def main():
    print(f"// mujoco {mujoco.__version__}")
    for name, file, q0, v0, steps in CASES:
        m = mujoco.MjModel.from_xml_path(os.path.join(TEXTBOOK, file))
        d = run(m, q0, v0, steps, mujoco.mjtIntegrator.mjINT_IMPLICIT)
        fmt = lambda a: "[" + ", ".join(repr(float(x)) for x in a) + "]"
        print(f"// {file}: {steps} steps of {m.opt.timestep} s, implicit")
        print(f"const {name}_QPOS: [f64; {m.nq}] = {fmt(d.qpos)};")
        print(f"const {name}_QVEL: [f64; {m.nv}] = {fmt(d.qvel)};")
        # implicitfast on the same state, to show the Coriolis derivatives change the result.
        d2 = run(m, q0, v0, steps, mujoco.mjtIntegrator.mjINT_IMPLICITFAST)
        diff = max(np.abs(d2.qpos - d.qpos).max(), np.abs(d2.qvel - d.qvel).max())
        print(f"// implicitfast differs from implicit by {diff:.3e} (max abs, qpos and qvel)")


if __name__ == "__main__":
    main()
