#!/usr/bin/env python3
"""Actuator forces: lagrange's `eval` `forward.actuator_force`, `actuator_moment`,
`actuator_length`, `act_dot` and `qfrc_actuator` against MuJoCo's `mj_forward` on every MJCF
model of the corpus (and tests/data/mjcf/actuators/) that has actuators, at random states with
random controls — a third of them outside `ctrlrange`, so the clamping is exercised, velocities
large enough to reach `forcerange` — and random activations `act` (within `actrange` when
limited, with some outside it).

Compared: the actuators lagrange simulates (dyntype none, integrator, filter or filterexact,
`actearly` included; fixed or affine gain; none or affine bias; muscles with a lengthrange;
joint — hinge, slide, ball, free —, jointinparent, fixed- or spatial-tendon, slider-crank or site
transmission, with or without refsite);
qfrc_actuator when every actuator of the model is simulated. Others are counted as skipped with
the reason. Tolerance 1e-9 relative (max|Δ| / max(1, max|ref|)). Contacts are off on both sides
(forces only). Then activations (and q, v) are stepped against mj_step on the test models
(STEP_CASES).

    validation/crossval_actuators            # table; exit 1 on a difference
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from crossval_corpus import REPO, corpus  # noqa: E402

TOL = 1e-9
N_STATES = 5
SEED = 20261124


def simulated(m, i) -> str | None:
    """Why MuJoCo actuator i is not simulated by lagrange, or None."""
    import mujoco as mj

    I = int  # MuJoCo's enums compare with Python ints, not with numpy integers
    muscle = (I(m.actuator_dyntype[i]) == I(mj.mjtDyn.mjDYN_MUSCLE)
              or I(m.actuator_gaintype[i]) == I(mj.mjtGain.mjGAIN_MUSCLE)
              or I(m.actuator_biastype[i]) == I(mj.mjtBias.mjBIAS_MUSCLE))
    if muscle and not m.actuator_lengthrange[i][0] < m.actuator_lengthrange[i][1]:
        return "muscle without a lengthrange"
    if I(m.actuator_dyntype[i]) not in (I(mj.mjtDyn.mjDYN_NONE), I(mj.mjtDyn.mjDYN_INTEGRATOR),
                                        I(mj.mjtDyn.mjDYN_FILTER), I(mj.mjtDyn.mjDYN_FILTEREXACT),
                                        I(mj.mjtDyn.mjDYN_MUSCLE)):
        return "user dynamics"
    if I(m.actuator_gaintype[i]) not in (I(mj.mjtGain.mjGAIN_FIXED), I(mj.mjtGain.mjGAIN_AFFINE),
                                         I(mj.mjtGain.mjGAIN_MUSCLE)):
        return "user gain"
    if I(m.actuator_biastype[i]) not in (I(mj.mjtBias.mjBIAS_NONE), I(mj.mjtBias.mjBIAS_AFFINE),
                                         I(mj.mjtBias.mjBIAS_MUSCLE)):
        return "user bias"
    t, obj = I(m.actuator_trntype[i]), I(m.actuator_trnid[i][0])
    if t in (I(mj.mjtTrn.mjTRN_JOINT), I(mj.mjtTrn.mjTRN_JOINTINPARENT), I(mj.mjtTrn.mjTRN_SITE),
             I(mj.mjtTrn.mjTRN_SLIDERCRANK)):
        return None
    if t == I(mj.mjtTrn.mjTRN_TENDON):
        return None
    return "body (adhesion) transmission"


def states(m, rng):
    out = []
    for _ in range(N_STATES):
        q = m.qpos0.copy()
        for j in range(m.njnt):
            if m.jnt_type[j] in (2, 3):
                lo, hi = m.jnt_range[j] if m.jnt_limited[j] else (-1.0, 1.0)
                q[m.jnt_qposadr[j]] = rng.uniform(lo, hi)
        v = rng.normal(scale=3.0, size=m.nv)
        ctrl = np.empty(m.nu)
        act = np.empty(m.na)
        for i in range(m.nu):
            lo, hi = m.actuator_ctrlrange[i] if m.actuator_ctrllimited[i] else (-2.0, 2.0)
            mid, half = (lo + hi) / 2, (hi - lo) / 2
            ctrl[i] = mid + half * rng.uniform(-1.5, 1.5)
            adr = int(m.actuator_actadr[i])
            for k in range(int(m.actuator_actnum[i])):
                lo, hi = m.actuator_actrange[i] if m.actuator_actlimited[i] else (-2.0, 2.0)
                mid, half = (lo + hi) / 2, (hi - lo) / 2
                act[adr + k] = mid + half * rng.uniform(-1.2, 1.2)
        out.append((q, v, ctrl, act))
    return out


STEP_TOL = 1e-9
# (model, lagrange integrator, MuJoCo integrator, steps): activations integrated by the steppers
# against mj_step from the same state — Euler and implicitfast everywhere, RK4 where every joint is
# flat (lagrange's RK4 differs from MuJoCo's on quaternion joints by design: it is fourth order
# there). Euler only on models without joint damping (MuJoCo's Euler is implicit in it).
STEP_CASES = [
    ("tests/data/mjcf/actuators/activation.xml", "euler", "mjINT_EULER", 100),
    ("tests/data/mjcf/actuators/activation.xml", "rk4", "mjINT_RK4", 100),
    ("tests/data/mjcf/actuators/transmissions.xml", "euler", "mjINT_EULER", 100),
    # implicitfast: implicit in joint damping, actuator damping/armature and the actuators'
    # velocity derivatives (MuJoCo's mjd_actuator_vel).
    ("tests/data/mjcf/actuators/activation.xml", "implicitfast", "mjINT_IMPLICITFAST", 100),
    ("tests/data/mjcf/actuators/damping_armature.xml", "implicitfast", "mjINT_IMPLICITFAST", 100),
    ("tests/data/mjcf/actuators/transmissions.xml", "implicitfast", "mjINT_IMPLICITFAST", 100),
]


def step_checks(binary: Path) -> int:
    """Trajectories with activations: final qpos, qvel and act after N steps, ours against mj_step
    (joint limits and contacts disabled on both sides), from a random state, control and act."""
    import mujoco as mj

    failed = 0
    rng = np.random.default_rng(SEED + 1)
    for rel, ours_int, mj_int, n in STEP_CASES:
        path = REPO / rel
        m = mj.MjModel.from_xml_path(str(path))
        m.opt.integrator = int(getattr(mj.mjtIntegrator, mj_int))
        m.opt.disableflags |= int(mj.mjtDisableBit.mjDSBL_CONTACT) | int(mj.mjtDisableBit.mjDSBL_LIMIT)
        q, v, c, a = states(m, rng)[0]
        # Moderate velocities and controls: the light finger of transmissions.xml must stay stable.
        v, c = v / 10.0, c / 5.0
        d = mj.MjData(m)
        d.qpos[:], d.qvel[:], d.ctrl[:] = q, v, c
        d.act[:] = a
        # lagrange takes the initial act from a keyframe: write one into a copy of the model.
        text = path.read_text()
        key = '<keyframe><key name="xv" qpos="%s" qvel="%s" ctrl="%s" act="%s"/></keyframe>' % tuple(
            " ".join(repr(float(x)) for x in arr) for arr in (q, v, c, a))
        text = text.replace("<keyframe>", "<!--").replace("</keyframe>", "-->")
        text = text.replace("</mujoco>", key + "\n</mujoco>")
        with tempfile.NamedTemporaryFile("w", suffix=".xml", dir=path.parent, delete=False) as f:
            f.write(text)
            tmp = f.name
        try:
            p = subprocess.run([str(binary), "simulate", tmp, "--keyframe", "xv", "--integrator", ours_int,
                                "--duration", repr(n * m.opt.timestep), "--json", "--disable", "contact",
                                "--disable", "limit", "--constraints", "exact"],
                               capture_output=True, text=True, timeout=300)
        finally:
            os.unlink(tmp)
        for _ in range(n):
            mj.mj_step(m, d)
        if p.returncode != 0:
            print("FAIL step %-45s %s: %s" % (rel, ours_int, (p.stderr or p.stdout).strip()[:200]))
            failed += 1
            continue
        r = json.loads(p.stdout)
        errs = {}
        for name, ours, ref in (("qpos", r["q"], d.qpos), ("qvel", r["v"], d.qvel), ("act", r["act"], d.act)):
            ours, ref = np.asarray(ours), np.asarray(ref)
            errs[name] = np.abs(ours - ref).max() / max(1.0, np.abs(ref).max()) if len(ref) else 0.0
        ok = max(errs.values()) <= STEP_TOL
        failed += 0 if ok else 1
        print("%s step %-50s %-12s %d steps: qpos %.1e, qvel %.1e, act %.1e (na %d)"
              % ("PASS" if ok else "FAIL", rel, ours_int, n, errs["qpos"], errs["qvel"], errs["act"], m.na))
    return failed


def main() -> int:
    import mujoco as mj

    binary = Path(os.environ.get("LAGRANGE_BIN", REPO / "target" / "release" / "lagrange"))
    entries = [e for e in corpus() if e.fmt == "mjcf"]
    entries += [type(entries[0])(str(p.relative_to(REPO)), str(p.relative_to(REPO)), "tests", p, "mjcf")
                for p in sorted((REPO / "tests" / "data" / "mjcf" / "actuators").glob("*.xml"))]
    rng = np.random.default_rng(SEED)
    passed = failed = skipped = 0
    compared_actuators = compared_act = 0
    worst = {"actuator_force": 0.0, "actuator_moment": 0.0, "actuator_length": 0.0, "act_dot": 0.0,
             "qfrc_actuator": 0.0}
    for e in entries:
        try:
            m = mj.MjModel.from_xml_path(str(e.path))
        except Exception:
            continue
        if m.nu == 0:
            continue
        reasons = [simulated(m, i) for i in range(m.nu)]
        mask = np.array([r is None for r in reasons])
        sts = states(m, rng)
        with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
            json.dump({"states": [{"q": list(map(float, q)), "v": list(map(float, v)), "ctrl": list(map(float, c)),
                                   "act": list(map(float, a))}
                                  for q, v, c, a in sts]}, f)
            path = f.name
        try:
            p = subprocess.run([str(binary), "eval", str(e.path), "--states", path, "--disable", "contact",
                                "--constraints", "exact"], capture_output=True, text=True, timeout=300)
        finally:
            os.unlink(path)
        if p.returncode != 0:
            why = (p.stderr or p.stdout).strip().splitlines()[0][:200] if (p.stderr or p.stdout) else "eval failed"
            print("SKIP %-60s lagrange: %s" % (e.name, why))
            skipped += 1
            continue
        results = json.loads(p.stdout)["results"]
        if len(results[0]["forward"]["actuator_force"]) != m.nu:
            print("SKIP %-60s lagrange types %d of MuJoCo's %d actuators (kinds not typed yet)"
                  % (e.name, len(results[0]["forward"]["actuator_force"]), m.nu))
            skipped += 1
            continue
        d = mj.MjData(m)
        m.opt.disableflags |= int(mj.mjtDisableBit.mjDSBL_CONTACT)
        worst_f = worst_q = worst_m = worst_l = worst_a = 0.0
        # act_dot of the compared actuators with an activation.
        act_mask = np.zeros(m.na, dtype=bool)
        for i in range(m.nu):
            if mask[i] and m.actuator_actnum[i]:
                act_mask[int(m.actuator_actadr[i])] = True
        for (q, v, c, a), r in zip(sts, results):
            d.qpos[:], d.qvel[:], d.ctrl[:] = q, v, c
            if m.na:
                d.act[:] = a
            mj.mj_forward(m, d)
            if act_mask.any():
                ours = np.asarray(r["forward"]["act_dot"])[act_mask]
                ref = d.act_dot[act_mask]
                worst_a = max(worst_a, np.abs(ours - ref).max() / max(1.0, np.abs(ref).max()))
            ours = np.asarray(r["forward"]["actuator_force"])[mask]
            ref = d.actuator_force[mask]
            if mask.any():
                worst_f = max(worst_f, np.abs(ours - ref).max() / max(1.0, np.abs(ref).max()))
                ours_l = np.asarray(r["forward"]["actuator_length"])[mask]
                ref_l = d.actuator_length[mask]
                worst_l = max(worst_l, np.abs(ours_l - ref_l).max() / max(1.0, np.abs(ref_l).max()))
                # actuator_moment (MuJoCo 4.0 stores it sparse): the simulated actuators' rows.
                dense = np.zeros((m.nu, m.nv))
                mj.mju_sparse2dense(dense, d.actuator_moment, d.moment_rownnz, d.moment_rowadr, d.moment_colind)
                mom = np.asarray(r["forward"]["actuator_moment"]).reshape(m.nu, m.nv)[mask]
                worst_m = max(worst_m, np.abs(mom - dense[mask]).max() / max(1.0, np.abs(dense[mask]).max()))
            if mask.all():
                qa = np.asarray(r["forward"]["qfrc_actuator"])
                worst_q = max(worst_q, np.abs(qa - d.qfrc_actuator).max() / max(1.0, np.abs(d.qfrc_actuator).max()))
        missing = sorted({r for r in reasons if r})
        ok = max(worst_f, worst_q, worst_m, worst_l, worst_a) <= TOL
        status = "PASS" if ok else "FAIL"
        if not mask.any():
            status, ok = "SKIP", True
            skipped += 1
        elif ok:
            passed += 1
            compared_actuators += int(mask.sum())
            compared_act += int(act_mask.sum())
        else:
            failed += 1
        if mask.any():
            for k, x in (("actuator_force", worst_f), ("actuator_moment", worst_m), ("actuator_length", worst_l),
                         ("act_dot", worst_a), ("qfrc_actuator", worst_q)):
                worst[k] = max(worst[k], x)
        print("%s %-60s nu %3d, na %3d, compared %3d: actuator_force %.1e, actuator_moment %.1e, "
              "actuator_length %.1e, act_dot %s, qfrc_actuator %s%s"
              % (status, e.name, m.nu, m.na, int(mask.sum()), worst_f, worst_m, worst_l,
                 "%.1e" % worst_a if act_mask.any() else "—",
                 "%.1e" % worst_q if mask.all() else "— (not all simulated)",
                 ("; not simulated: " + ", ".join(missing)) if missing else ""))
    print("actuators: %d models, %d actuators compared (%d with activation dynamics)"
          % (passed + failed, compared_actuators, compared_act))
    print("actuators: worst relative errors: " + ", ".join("%s %.1e" % kv for kv in worst.items()))
    print("actuators: %d passed, %d failed, %d skipped" % (passed, failed, skipped))
    step_failed = step_checks(binary)
    print("actuator steps: %d cases, %d failed" % (len(STEP_CASES), step_failed))
    return 1 if failed or step_failed else 0


if __name__ == "__main__":
    sys.exit(main())
