"""Type stubs of the extension module lagrange._lagrange (re-exported by `lagrange`)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

FloatArray = npt.NDArray[np.float64]

class LagrangeError(Exception):
    """Base class of the errors lagrange raises for loading and simulating."""

class LoadError(LagrangeError):
    """A model file or text could not be loaded (file:line, element, what is wrong)."""

class SimulationError(LagrangeError):
    """A step failed (diverged, did not converge) or was refused after a failure until reset."""

class InputError(ValueError):
    """An argument does not fit the model: a wrong shape or length, an unknown name, a non-finite value."""

class Options:
    """A model's simulation options (read-only; MuJoCo's mjOption)."""

    timestep: float
    integrator: str
    cone: str
    solver: str
    iterations: int
    tolerance: float
    impratio: float
    gravity: List[float]

class Model:
    """A compiled model (MuJoCo's mjModel); pickles as its source and load options."""

    @staticmethod
    def from_file(
        path: Union[str, PathLike],
        *,
        package_dirs: Optional[Sequence[str]] = None,
        floating: bool = False,
        accept_nonphysical_inertia: bool = False,
        disable: Optional[Sequence[str]] = None,
        clamp_effort: bool = False,
        constraints: Optional[str] = None,
        max_contacts: Optional[int] = None,
    ) -> Model: ...
    @staticmethod
    def from_string(
        xml: str,
        *,
        base: Optional[Union[str, PathLike]] = None,
        package_dirs: Optional[Sequence[str]] = None,
        floating: bool = False,
        accept_nonphysical_inertia: bool = False,
        disable: Optional[Sequence[str]] = None,
        clamp_effort: bool = False,
        constraints: Optional[str] = None,
        max_contacts: Optional[int] = None,
    ) -> Model: ...
    @staticmethod
    def _restore(kind: str, text: str, path: Union[str, PathLike], opts: Dict[str, Any]) -> Model: ...
    def __reduce__(self) -> Tuple[Any, ...]: ...
    @property
    def path(self) -> Optional[str]: ...
    @property
    def constraints(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def nq(self) -> int: ...
    @property
    def nv(self) -> int: ...
    @property
    def nu(self) -> int: ...
    @property
    def na(self) -> int: ...
    @property
    def nbody(self) -> int: ...
    @property
    def njnt(self) -> int: ...
    @property
    def ngeom(self) -> int: ...
    @property
    def nsite(self) -> int: ...
    @property
    def nmocap(self) -> int: ...
    @property
    def nsensor(self) -> int: ...
    @property
    def nsensordata(self) -> int: ...
    @property
    def nkey(self) -> int: ...
    @property
    def total_mass(self) -> float: ...
    @property
    def qpos0(self) -> List[float]: ...
    @property
    def body_names(self) -> List[str]: ...
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def geom_names(self) -> List[str]: ...
    @property
    def site_names(self) -> List[str]: ...
    @property
    def actuator_names(self) -> List[str]: ...
    @property
    def sensor_names(self) -> List[str]: ...
    @property
    def key_names(self) -> List[str]: ...
    @property
    def sensor_adr(self) -> List[Tuple[int, int]]: ...
    @property
    def jnt_adr(self) -> List[Tuple[int, int]]: ...
    @property
    def opt(self) -> Options: ...
    def keyframe(self, name: str) -> Dict[str, Any]: ...
    def name2id(self, kind: str, name: str) -> int: ...

class Contact:
    """One contact of the last collision pass, its force in the contact frame."""

    geom1: int
    geom2: int
    body1: int
    body2: int
    pos: List[float]
    frame: List[List[float]]
    dist: float
    condim: int
    friction: List[float]
    active: bool
    force: List[float]

class Data:
    """One simulation's state, inputs and outputs; arrays are NumPy views without copies."""

    def __init__(self, model: Model) -> None: ...
    @property
    def model(self) -> Model: ...
    time: float
    qpos: FloatArray
    qvel: FloatArray
    act: FloatArray
    ctrl: FloatArray
    qfrc_applied: FloatArray
    xfrc_applied: FloatArray
    mocap_pos: FloatArray
    mocap_quat: FloatArray
    qacc: FloatArray
    qfrc_constraint: FloatArray
    qfrc_bias: FloatArray
    qfrc_passive: FloatArray
    qfrc_actuator: FloatArray
    actuator_force: FloatArray
    sensordata: FloatArray
    @property
    def xpos(self) -> FloatArray: ...
    @property
    def xquat(self) -> FloatArray: ...
    @property
    def xmat(self) -> FloatArray: ...
    @property
    def ncon(self) -> int: ...
    @property
    def nefc(self) -> int: ...
    @property
    def contact(self) -> List[Contact]: ...
    @property
    def warnings(self) -> str: ...

def forward(m: Model, d: Data) -> None: ...
def step(m: Model, d: Data, nstep: int = 1) -> None: ...
def reset(m: Model, d: Data) -> None: ...
def reset_keyframe(m: Model, d: Data, key: Union[str, int]) -> None: ...
def contact_force(m: Model, d: Data, i: int) -> FloatArray: ...
def rnea(m: Model, d: Data, q: FloatArray, v: FloatArray, a: FloatArray) -> FloatArray: ...
def crba(m: Model, d: Data, q: FloatArray) -> FloatArray: ...
def aba(m: Model, d: Data, q: FloatArray, v: FloatArray, tau: FloatArray) -> FloatArray: ...
def jacobian(m: Model, d: Data, frame: str, reference: str = "local_world_aligned") -> FloatArray: ...
def center_of_mass(m: Model, d: Data) -> FloatArray: ...
def kinetic_energy(m: Model, d: Data, q: FloatArray, v: FloatArray) -> float: ...
def potential_energy(m: Model, d: Data, q: FloatArray) -> float: ...
def rnea_derivatives(m: Model, d: Data, q: FloatArray, v: FloatArray, a: FloatArray) -> Tuple[FloatArray, FloatArray]:
    """(dtau_dq, dtau_dv) of inverse dynamics; q columns in each joint's tangent space."""
def aba_derivatives(
    m: Model, d: Data, q: FloatArray, v: FloatArray, tau: FloatArray
) -> Tuple[FloatArray, FloatArray, FloatArray]:
    """(dqacc_dq, dqacc_dv, dqacc_dtau = M⁻¹) of unconstrained forward dynamics."""
def transition_jacobians(
    m: Model, d: Data, eps: float = 1e-6, centered: bool = True, method: str = "fd"
) -> Tuple[FloatArray, FloatArray]:
    """(A, B) of one step from d's state, as MuJoCo's mjd_transitionFD; method="hybrid": the
    velocity and control columns analytic."""
def rollout(
    model: Model,
    initial_states: FloatArray,
    controls: Optional[FloatArray] = None,
    nstep: Optional[int] = None,
    *,
    threads: Optional[int] = None,
) -> Dict[str, Any]: ...
