#!/usr/bin/env python3
"""MuJoCo's integrators on lagrange's work-precision measurement (issue 15): the same model, initial
state, duration and step sizes as `lagrange workprec`, errors against lagrange's reference solution
(adaptive Dormand-Prince 5(4) at rtol 1e-13), measured the same way.

    validation/.venv/bin/python validation/workprec_mujoco.py MODEL [--duration T] [--dts 8e-3,...]
        [--keyframe NAME] [--repeats N] [--integrators euler,rk4,implicit,implicitfast]
        [--out mujoco.json] [--lagrange-out lagrange.json] [--plot both.svg] [--lagrange BIN]
    validation/.venv/bin/python validation/workprec_mujoco.py --reference REF.json [--out mujoco.json]
        [--lagrange-json lagrange.json] [--plot both.svg]

With MODEL it runs `lagrange workprec MODEL --json --dump-reference REF` itself (passing --duration,
--dts, --keyframe, --repeats) and gets lagrange's rows and the reference; with --reference it reads
a reference dumped earlier (lagrange's rows then come from --lagrange-json, if given). The reference
file holds the model path, the initial state (q0, v0, ctrl), the `--disable` flags, duration,
sample interval, step sizes, the reference trajectory (q, v, energy at every sample time) and the
energy scale.

Per MuJoCo integrator (`m.opt.integrator`) and step size (`m.opt.timestep`, set for every run):
- error: final-time max-norm over q (hinge/slide differences, ball/free rotations as the angle of
  q_ref^-1 q, free positions as differences) and v - v_ref;
- error_l2: RMS over the sample times t > 0 of the 2-norm of (q - q_ref on the manifold, v - v_ref);
- energy_error: max over the sample times of |E - E_ref| / energy_scale (E from mj_energyPos/Vel
  with the energy flag on, in a separate MjData, outside the timed loop);
- cpu_s: the thread's CPU time of one `mj_step(m, d, nstep=N)` call over the whole run (the loop
  runs in C), minimum of --repeats runs (default 3).
Auto-reset on divergence is switched off; a run whose state becomes non-finite (or that MuJoCo
flags with a warning) is reported and left out. Writes the rows as JSON in lagrange's format
(`{"model", "duration", "reference", "rows"}`, integrators named `mujoco-euler`, ...) to --out, and
prints the combined table via `lagrange workprec --from-json ... --extra-rows ...` (which also
draws --plot with both engines).

Conventions: qpos/qvel layouts are MuJoCo's in both engines (quaternions w-first, ball and free
angular velocity in the body frame). MuJoCo's `Euler` is implicit in joint damping unless the
`eulerdamp` flag is disabled, and so is lagrange's `euler`: the same method on damped models.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import mujoco
import numpy as np

INTEGRATORS = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
}


def whole_multiple(span, dt):
    n = round(span / dt)
    if n < 1 or abs(n * dt - span) > 1e-9 * span:
        raise SystemExit(f"step {dt} does not divide {span}")
    return n


def quat_angle(q_ref, q):
    """The angle of q_ref^-1 q (unit quaternions, w first), in [0, pi]."""
    w0, x0, y0, z0 = q_ref
    w1, x1, y1, z1 = q
    # conj(q_ref) * q
    w = w0 * w1 + x0 * x1 + y0 * y1 + z0 * z1
    x = w0 * x1 - x0 * w1 - y0 * z1 + z0 * y1
    y = w0 * y1 + x0 * z1 - y0 * w1 - z0 * x1
    z = w0 * z1 - x0 * y1 + y0 * x1 - z0 * w1
    n = math.sqrt(w * w + x * x + y * y + z * z)
    return 2.0 * math.atan2(math.sqrt(x * x + y * y + z * z) / n, abs(w) / n)


def state_error(joints, q_ref, v_ref, q, v):
    """(max-norm, squared 2-norm) of (q on the manifold, v) against the reference."""
    terms = []
    for j in joints:
        a = j["qposadr"]
        if j["type"] == "ball":
            terms.append(quat_angle(q_ref[a:a + 4], q[a:a + 4]))
        elif j["type"] == "free":
            terms.extend(abs(q[a + k] - q_ref[a + k]) for k in range(3))
            terms.append(quat_angle(q_ref[a + 3:a + 7], q[a + 3:a + 7]))
        elif j["type"] == "planar":
            terms.extend(abs(q[a + k] - q_ref[a + k]) for k in range(3))
        else:
            terms.append(abs(q[a] - q_ref[a]))
    dv = np.asarray(v) - np.asarray(v_ref)
    mx = max([0.0] + terms + [float(np.max(np.abs(dv))) if dv.size else 0.0])
    return mx, sum(t * t for t in terms) + float(dv @ dv)


class Runner:
    def __init__(self, ref):
        self.ref = ref
        path = ref["model_path"]
        self.m = mujoco.MjModel.from_xml_path(path)
        m = self.m
        if (m.nq, m.nv) != (ref["nq"], ref["nv"]):
            raise SystemExit(f"{path}: MuJoCo has nq={m.nq}, nv={m.nv}; lagrange had {ref['nq']}, {ref['nv']}")
        names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, i) for i in range(m.njnt)]
        theirs = [j["name"] for j in ref["joints"]]
        if names != theirs or list(m.jnt_qposadr) != [j["qposadr"] for j in ref["joints"]]:
            raise SystemExit(f"{path}: joints differ: MuJoCo {names}, lagrange {theirs}")
        for flag in ref.get("disabled_flags", []):
            bit = getattr(mujoco.mjtDisableBit, "mjDSBL_" + flag.upper(), None)
            if bit is None:
                raise SystemExit(f"--disable {flag}: MuJoCo has no such flag")
            m.opt.disableflags |= int(bit)
        # A diverging run must fail, not restart from qpos0 silently.
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
        self.d = mujoco.MjData(m)
        self.de = mujoco.MjData(m)
        self.samples = round(ref["duration"] / ref["sample_dt"])
        s = ref["samples"]
        self.q_ref, self.v_ref, self.e_ref = s["q"], s["v"], s["energy"]

    def reset(self, integrator, dt):
        m, d = self.m, self.d
        m.opt.integrator = INTEGRATORS[integrator]
        m.opt.timestep = dt  # per run: the model's own timestep is not the one measured
        mujoco.mj_resetData(m, d)
        d.qpos[:] = self.ref["q0"]
        d.qvel[:] = self.ref["v0"]
        if m.nu:
            d.ctrl[:] = self.ref["ctrl"]

    def energy(self, q, v):
        m, de = self.m, self.de
        de.qpos[:] = q
        de.qvel[:] = v
        m.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_ENERGY)
        mujoco.mj_forward(m, de)
        m.opt.enableflags &= ~int(mujoco.mjtEnableBit.mjENBL_ENERGY)
        return float(de.energy[0] + de.energy[1])

    def diverged(self):
        d = self.d
        bad = not (np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel)))
        return bad or d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0

    def measure(self, integrator, dt, repeats):
        ref, m, d = self.ref, self.m, self.d
        n = whole_multiple(ref["sample_dt"], dt)
        self.reset(integrator, dt)
        sum_sq, last, energy = 0.0, 0.0, 0.0
        for k in range(1, self.samples + 1):
            mujoco.mj_step(m, d, nstep=n)
            if self.diverged():
                return None, f"diverged before t = {k * ref['sample_dt']:.4f} s"
            mx, sq = state_error(ref["joints"], self.q_ref[k], self.v_ref[k], d.qpos, d.qvel)
            sum_sq += sq
            last = mx
            e = self.energy(d.qpos, d.qvel)
            energy = max(energy, abs(e - self.e_ref[k]) / ref["energy_scale"])
        cpu = math.inf
        for _ in range(repeats):
            self.reset(integrator, dt)
            t0 = time.thread_time()
            mujoco.mj_step(m, d, nstep=n * self.samples)
            cpu = min(cpu, time.thread_time() - t0)
        return {
            "integrator": "mujoco-" + integrator,
            "dt": dt,
            "rtol": None,
            "steps": n * self.samples,
            "error": last,
            "error_l2": math.sqrt(sum_sq / self.samples),
            "energy_error": energy,
            "cpu_s": cpu,
        }, None


def table(rows):
    out = [f"{'integrator':<20} {'dt':>10} {'steps':>9} {'error':>10} {'error_l2':>10} {'energy':>10} {'cpu_s':>10}"]
    for r in rows:
        out.append(
            f"{r['integrator']:<20} {r['dt']:>10.3e} {r['steps']:>9} {r['error']:>10.3e} "
            f"{r['error_l2']:>10.3e} {r['energy_error']:>10.3e} {r['cpu_s']:>10.3e}"
        )
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("model", nargs="?", help="model file (runs lagrange workprec on it)")
    ap.add_argument("--reference", help="a `lagrange workprec --dump-reference` file instead of MODEL")
    ap.add_argument("--lagrange", default=os.path.join(here, "..", "target", "release", "lagrange"))
    ap.add_argument("--lagrange-json", help="lagrange's `workprec --json` rows (with --reference)")
    ap.add_argument("--lagrange-out", help="save lagrange's rows here (with MODEL)")
    ap.add_argument("--duration")
    ap.add_argument("--dts")
    ap.add_argument("--keyframe")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--integrators", default="euler,rk4,implicit,implicitfast")
    ap.add_argument("--out", help="write MuJoCo's rows (JSON) here")
    ap.add_argument("--plot", help="combined plot of both engines (.svg or .png), drawn by lagrange")
    args = ap.parse_args()
    if (args.model is None) == (args.reference is None):
        ap.error("give MODEL or --reference REF.json (one of them)")
    integrators = [s.strip() for s in args.integrators.split(",")]
    for name in integrators:
        if name not in INTEGRATORS:
            ap.error(f"--integrators: unknown MuJoCo integrator '{name}' (known: {', '.join(INTEGRATORS)})")
    if args.repeats < 1:
        ap.error("--repeats: give at least 1")
    tmp = tempfile.mkdtemp(prefix="workprec-")
    lagrange_json = args.lagrange_json
    if args.model:
        ref_path = os.path.join(tmp, "reference.json")
        cmd = [args.lagrange, "workprec", args.model, "--json", "--dump-reference", ref_path,
               "--repeats", str(args.repeats)]
        for flag in ("duration", "dts", "keyframe"):
            if getattr(args, flag) is not None:
                cmd += ["--" + flag, getattr(args, flag)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
        sys.stderr.write(r.stderr)
        lagrange_json = args.lagrange_out or os.path.join(tmp, "lagrange.json")
        with open(lagrange_json, "w") as f:
            f.write(r.stdout)
    else:
        ref_path = args.reference
    with open(ref_path) as f:
        ref = json.load(f)

    # Divergence is detected from the state and d.warning; MuJoCo's own messages would only repeat it.
    mujoco.set_mju_user_warning(lambda msg: None)
    runner = Runner(ref)
    e0 = runner.energy(ref["q0"], ref["v0"])
    print(f"MuJoCo {mujoco.__version__} on {ref['model']}: {ref['duration']} s from {ref['start']}; "
          f"E0 = {e0:.12g} J (lagrange's reference: {ref['samples']['energy'][0]:.12g} J)")
    rows, failures = [], []
    for name in integrators:
        for dt in ref["dts"]:
            row, why = runner.measure(name, dt, args.repeats)
            if row is None:
                failures.append(f"mujoco-{name} at dt {dt:g}: {why}")
            else:
                rows.append(row)
    report = {"model": ref["model"], "duration": ref["duration"],
              "reference": {"integrator": ref["reference"]["integrator"], "rtol": ref["reference"]["rtol"]},
              "rows": rows}
    out = args.out or os.path.join(tmp, "mujoco.json")
    with open(out, "w") as f:
        json.dump(report, f)
        f.write("\n")
    for msg in failures:
        print(f"warning: {msg} (left out)")
    if lagrange_json:
        cmd = [args.lagrange, "workprec", "--from-json", lagrange_json, "--extra-rows", out]
        if args.plot:
            cmd += ["--plot", args.plot]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
        print(r.stdout, end="")
    else:
        print(table(rows))
        if args.plot:
            print("--plot needs lagrange's rows: give MODEL or --lagrange-json", file=sys.stderr)
    if args.out:
        print(f"MuJoCo rows written to {args.out}")


if __name__ == "__main__":
    main()
