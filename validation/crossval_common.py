"""Shared pieces of the cross-validation harness (validation/crossval.py): the joint layout
("slots"), random states, relative errors and the tolerances.

Every engine (lagrange, MuJoCo, Pinocchio) is driven in ONE set of coordinates, the *canonical*
layout: lagrange's, which is MuJoCo's qpos/qvel layout (docs/architecture.md, "Conventions"):

- free joint  q = [x y z qw qx qy qz], v = [world-frame linear velocity of the body origin,
  body-frame angular velocity];
- ball joint  q = [qw qx qy qz], v = body-frame angular velocity;
- hinge/slide one coordinate each (a URDF continuous joint is one angle);
- joints are matched between engines by NAME, never by index.

Each engine converts the canonical state into its own coordinates and its results back.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass, field

import numpy as np

# ---------------------------------------------------------------------------------------------
# Tolerances and the relative error (the same definition as tests/common/mod.rs)
# ---------------------------------------------------------------------------------------------

#: Agreement required against a reference (docs/architecture.md "Truth"; tests/common/mod.rs REF_REL).
REF_REL = 1e-9

#: Floor of the relative error's denominator: only turns 0/0 into 0 (tests/common REL_FLOOR).
REL_FLOOR = 1e-300

#: The compared quantities, in report order, with their column titles.
QUANTITIES = [
    ("M", "M"),
    ("bias", "bias"),
    ("qacc", "ABA"),
    ("pose", "poses"),
    ("jac", "Jac"),
    ("mass", "mass"),
    ("com", "com"),
    ("kinetic", "T"),
    ("potential", "V"),
]
QUANTITY_KEYS = [q for q, _ in QUANTITIES]


def rel_err(a, b) -> float:
    """Norm-wise relative error ``‖a − b‖∞ / max(‖a‖∞, ‖b‖∞, REL_FLOOR)`` (tests/common/mod.rs
    ``rel_err_vec``); NaN anywhere gives NaN (reported as a failure)."""
    a = np.asarray(a, dtype=float).ravel()
    b = np.asarray(b, dtype=float).ravel()
    if a.shape != b.shape:
        return math.nan
    if a.size == 0:
        return 0.0
    d = np.abs(a - b)
    if np.isnan(d).any():
        return math.nan
    scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))), REL_FLOOR)
    return float(np.max(d)) / scale


# ---------------------------------------------------------------------------------------------
# Joint layout
# ---------------------------------------------------------------------------------------------

KIND_DIMS = {"free": (7, 6), "ball": (4, 3), "hinge": (1, 1), "slide": (1, 1), "planar": (3, 3)}


@dataclass
class Slot:
    """One joint in some engine's coordinates. ``kind`` is free, ball, hinge, slide or planar;
    ``body`` names the joint's child body (used to match unnamed joints and composites)."""

    name: str
    kind: str
    body: str
    qadr: int
    vadr: int
    nq: int
    nv: int
    range: tuple[float, float] | None = None  # joint range (rad or m) when limited


@dataclass
class Layout:
    slots: list[Slot]
    nq: int
    nv: int
    source: str  # which engine the canonical layout came from

    def by_name(self) -> dict[str, Slot]:
        return {s.name: s for s in self.slots}


def layout_from_slots(slots: list[Slot], source: str) -> Layout:
    nq = sum(s.nq for s in slots)
    nv = sum(s.nv for s in slots)
    return Layout(slots, nq, nv, source)


@dataclass
class State:
    q: np.ndarray
    v: np.ndarray
    tau: np.ndarray


def model_rng(seed: int, model_id: str) -> np.random.Generator:
    """One reproducible stream per model, independent of the corpus order."""
    return np.random.default_rng([seed, zlib.crc32(model_id.encode())])


def random_unit_quat(rng) -> list[float]:
    """Uniformly random rotation as a w-first unit quaternion with w ≥ 0."""
    quat = rng.standard_normal(4)
    quat /= np.linalg.norm(quat)
    if quat[0] < 0:
        quat = -quat
    return quat.tolist()


#: Draws of limited joints stay within ±HINGE_CAP rad and ±SLIDE_CAP m.
HINGE_CAP = 2 * math.pi
SLIDE_CAP = 10.0


def random_states(rng, layout: Layout, ranges: dict[str, tuple[float, float]], n: int) -> list[State]:
    """``n`` states in the canonical layout:

    - free joint: position uniform in [-1, 1]³, a uniformly random unit quaternion (w ≥ 0);
    - ball joint: a uniformly random unit quaternion;
    - hinge/slide: uniform inside the joint range when it has one (``ranges`` by joint name,
      else the slot's own range) clipped to ±2π rad / ±10 m, else uniform in [-π, π] (hinge) or
      [-1, 1] (slide);
    - planar: x, y uniform in [-1, 1], θ in [-π, π];
    - v uniform in [-2, 2], tau uniform in [-5, 5] per coordinate.
    """
    states = []
    for _ in range(n):
        q = np.zeros(layout.nq)
        for s in layout.slots:
            if s.kind == "free":
                q[s.qadr : s.qadr + 7] = rng.uniform(-1.0, 1.0, 3).tolist() + random_unit_quat(rng)
            elif s.kind == "ball":
                q[s.qadr : s.qadr + 4] = random_unit_quat(rng)
            elif s.kind == "planar":
                q[s.qadr : s.qadr + 3] = [rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-math.pi, math.pi)]
            else:
                r = ranges.get(s.name, s.range)
                if r is not None:
                    # Ranges like ±1e16 (example-robot-data's iris rotors) mean "unlimited": far
                    # out, sin/cos argument reduction (ε·|q|) swamps every comparison.
                    cap = HINGE_CAP if s.kind == "hinge" else SLIDE_CAP
                    r = (max(r[0], -cap), min(r[1], cap))
                if r is not None and r[0] < r[1]:
                    q[s.qadr] = rng.uniform(r[0], r[1])
                elif s.kind == "hinge":
                    q[s.qadr] = rng.uniform(-math.pi, math.pi)
                else:
                    q[s.qadr] = rng.uniform(-1.0, 1.0)
        v = rng.uniform(-2.0, 2.0, layout.nv)
        tau = rng.uniform(-5.0, 5.0, layout.nv)
        states.append(State(q, v, tau))
    return states


# ---------------------------------------------------------------------------------------------
# Small geometry helpers
# ---------------------------------------------------------------------------------------------


def quat_wxyz_to_mat(qw) -> np.ndarray:
    w, x, y, z = np.asarray(qw, dtype=float) / np.linalg.norm(qw)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


@dataclass
class Result:
    """What one engine computed for one state, in the canonical layout.

    ``poses`` maps a body (frame) name to (position, 3×3 rotation) in the world frame; ``jac``
    maps a frame name to its 6×nv world-aligned Jacobian (rows: linear velocity of the frame
    origin, then angular velocity)."""

    M: np.ndarray
    bias: np.ndarray
    qacc: np.ndarray
    poses: dict[str, tuple[np.ndarray, np.ndarray]]
    jac: dict[str, np.ndarray]
    kinetic: float
    potential: float
    com: np.ndarray
    mass: float


@dataclass
class EngineRun:
    """The outcome of one engine on one model."""

    engine: str
    status: str  # "ok", "load-error", "incomparable", "eval-error", "not-run"
    detail: str = ""
    layout: Layout | None = None
    results: list[Result] = field(default_factory=list)
    bodies: list[str] = field(default_factory=list)  # comparable body names
    sites: list[str] = field(default_factory=list)
    leaves: list[str] = field(default_factory=list)  # leaf bodies (Jacobian candidates)
    seconds: float = 0.0
    cond_M: float = math.nan  # max over states of cond(M) (reported with loosened tolerances)
    note: str = ""  # how the engine was run, when it differs from the default (shown in the report)
    # Pinocchio on a URDF with <mimic>: why its mimic support (mimic=True) refuses the file, if it
    # does. lagrange enforces mimics, so its refusal of such a file matches the reference's.
    mimic_refusal: str = ""


def max_sample_difference(new: list[dict], old: list[dict], keys: tuple[str, ...] = ("qpos", "qvel")) -> float:
    """The largest absolute difference between two runs' samples (lists of dicts holding the
    vectors `keys`), for the reference-data scripts' --check: how far the live reference moved."""
    worst = 0.0
    for a, b in zip(new, old):
        for key in keys:
            worst = max(worst, float(np.max(np.abs(np.array(a[key]) - np.array(b[key])))))
    return worst
