#!/usr/bin/env python3
"""Actuator forces: lagrange's `eval` `forward.actuator_force` and `forward.qfrc_actuator` against
MuJoCo's `mj_forward` on every MJCF model of the corpus (and tests/data/mjcf/actuators/) that has
actuators, at random states with random controls — a third of them outside `ctrlrange`, so the
clamping is exercised, and velocities large enough to reach `forcerange`.

Compared: the actuators lagrange simulates (no activation dynamics; fixed or affine gain; none or
affine bias; hinge/slide joint or fixed-tendon transmission); qfrc_actuator when every actuator of
the model is simulated. Others are counted as skipped with the reason. Tolerance 1e-9 relative
(max|Δ| / max(1, max|ref|)). Contacts are off on both sides (forces only).

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
    if I(m.actuator_dyntype[i]) != I(mj.mjtDyn.mjDYN_NONE):
        return "activation dynamics"
    if I(m.actuator_gaintype[i]) not in (I(mj.mjtGain.mjGAIN_FIXED), I(mj.mjtGain.mjGAIN_AFFINE)):
        return "muscle or user gain"
    if I(m.actuator_biastype[i]) not in (I(mj.mjtBias.mjBIAS_NONE), I(mj.mjtBias.mjBIAS_AFFINE)):
        return "muscle or user bias"
    t, obj = I(m.actuator_trntype[i]), I(m.actuator_trnid[i][0])
    if t in (I(mj.mjtTrn.mjTRN_JOINT), I(mj.mjtTrn.mjTRN_JOINTINPARENT)):
        ok = I(m.jnt_type[obj]) in (I(mj.mjtJoint.mjJNT_HINGE), I(mj.mjtJoint.mjJNT_SLIDE))
        return None if ok else "ball/free joint"
    if t == I(mj.mjtTrn.mjTRN_TENDON):
        adr, num = I(m.tendon_adr[obj]), I(m.tendon_num[obj])
        fixed = all(I(m.wrap_type[adr + k]) == I(mj.mjtWrap.mjWRAP_JOINT) for k in range(num))
        return None if fixed else "spatial tendon"
    return "site, body or slider-crank transmission"


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
        for i in range(m.nu):
            lo, hi = m.actuator_ctrlrange[i] if m.actuator_ctrllimited[i] else (-2.0, 2.0)
            mid, half = (lo + hi) / 2, (hi - lo) / 2
            ctrl[i] = mid + half * rng.uniform(-1.5, 1.5)
        out.append((q, v, ctrl))
    return out


def main() -> int:
    import mujoco as mj

    binary = REPO / "target" / "release" / "lagrange"
    entries = [e for e in corpus() if e.fmt == "mjcf"]
    entries += [type(entries[0])(str(p.relative_to(REPO)), str(p.relative_to(REPO)), "tests", p, "mjcf")
                for p in sorted((REPO / "tests" / "data" / "mjcf" / "actuators").glob("*.xml"))]
    rng = np.random.default_rng(SEED)
    passed = failed = skipped = 0
    compared_actuators = 0
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
            json.dump({"states": [{"q": list(map(float, q)), "v": list(map(float, v)), "ctrl": list(map(float, c))}
                                  for q, v, c in sts]}, f)
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
        worst_f = worst_q = worst_m = 0.0
        for (q, v, c), r in zip(sts, results):
            d.qpos[:], d.qvel[:], d.ctrl[:] = q, v, c
            mj.mj_forward(m, d)
            ours = np.asarray(r["forward"]["actuator_force"])[mask]
            ref = d.actuator_force[mask]
            if mask.any():
                worst_f = max(worst_f, np.abs(ours - ref).max() / max(1.0, np.abs(ref).max()))
                # actuator_moment (MuJoCo 4.0 stores it sparse): the simulated actuators' rows.
                dense = np.zeros((m.nu, m.nv))
                mj.mju_sparse2dense(dense, d.actuator_moment, d.moment_rownnz, d.moment_rowadr, d.moment_colind)
                mom = np.asarray(r["forward"]["actuator_moment"]).reshape(m.nu, m.nv)[mask]
                worst_m = max(worst_m, np.abs(mom - dense[mask]).max() / max(1.0, np.abs(dense[mask]).max()))
            if mask.all():
                qa = np.asarray(r["forward"]["qfrc_actuator"])
                worst_q = max(worst_q, np.abs(qa - d.qfrc_actuator).max() / max(1.0, np.abs(d.qfrc_actuator).max()))
        missing = sorted({r for r in reasons if r})
        ok = worst_f <= TOL and worst_q <= TOL and worst_m <= TOL
        status = "PASS" if ok else "FAIL"
        if not mask.any():
            status, ok = "SKIP", True
            skipped += 1
        elif ok:
            passed += 1
            compared_actuators += int(mask.sum())
        else:
            failed += 1
        print("%s %-60s nu %3d, compared %3d: actuator_force %.1e, actuator_moment %.1e, qfrc_actuator %s%s"
              % (status, e.name, m.nu, int(mask.sum()), worst_f, worst_m, "%.1e" % worst_q if mask.all() else "— (not all simulated)",
                 ("; not simulated: " + ", ".join(missing)) if missing else ""))
    print("actuators: %d models, %d actuators compared" % (passed + failed, compared_actuators))
    print("actuators: %d passed, %d failed, %d skipped" % (passed, failed, skipped))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
