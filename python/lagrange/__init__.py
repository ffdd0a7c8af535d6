"""lagrange: multibody dynamics with MuJoCo's and Pinocchio's Python idioms.

    import lagrange
    m = lagrange.Model.from_file("models/mjcf/unitree_go1/scene.xml")
    d = lagrange.Data(m)
    lagrange.reset_keyframe(m, d, "home")
    lagrange.step(m, d, nstep=100)

`Data` arrays (`qpos`, `qvel`, `ctrl`, `sensordata`, ...) are NumPy views of the engine's
buffers, without copies. `lagrange.rollout` runs many rollouts on all cores without the GIL;
`lagrange.distributed.rollout` spreads them over a Ray cluster. See docs/python.md.
"""

from ._lagrange import (
    Contact,
    Data,
    InputError,
    LagrangeError,
    LoadError,
    Model,
    Options,
    SimulationError,
    __version__,
    aba,
    aba_derivatives,
    center_of_mass,
    contact_force,
    crba,
    forward,
    jacobian,
    kinetic_energy,
    potential_energy,
    reset,
    reset_keyframe,
    rnea,
    rnea_derivatives,
    rollout,
    step,
    transition_jacobians,
)

__all__ = [
    "Contact",
    "Data",
    "InputError",
    "LagrangeError",
    "LoadError",
    "Model",
    "Options",
    "SimulationError",
    "__version__",
    "aba",
    "aba_derivatives",
    "center_of_mass",
    "contact_force",
    "crba",
    "forward",
    "jacobian",
    "kinetic_energy",
    "potential_energy",
    "reset",
    "reset_keyframe",
    "rnea",
    "rnea_derivatives",
    "rollout",
    "step",
    "transition_jacobians",
]
