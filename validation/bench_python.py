"""Per-call overhead and rollout throughput of lagrange's Python bindings beside MuJoCo's and
Pinocchio's (issue 29 item 5; report only, no thresholds).

- Per call, µs (median of rounds of N calls, interleaved): `lagrange.step(m, d)` beside
  `mujoco.mj_step(m, d)` on a 1-dof pendulum (the call's overhead dominates), go1 and the humanoid;
  `lagrange.aba(m, d, q, v, tau)` beside `pinocchio.aba(model, data, q, v, tau)` on ur5, panda and
  solo12 (fixed bases), the same arguments each call.
- Rollout throughput, steps/s: `lagrange.rollout(m, states, controls, nstep, threads=k)` beside
  `mujoco.rollout.rollout(m, [MjData] * k, states, controls)` with k = 1, 2 threads, on go1 and the
  humanoid from their keyframe / qpos0 with small random velocities and controls (both engines
  record every state; MuJoCo's per-thread MjData made once, outside the timing).

Writes the "Python bindings" section of validation/bench.md (replacing an earlier one, after the
native benchmark's text: bench_native rewrites the file, so run this after it) and prints it.
Usage: validation/.venv/bin/python validation/bench_python.py [--quick] [--no-write]
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

import lagrange

ROOT = Path(__file__).resolve().parent.parent
BENCH = ROOT / "validation/bench.md"
HEADER = "## Python bindings (validation/bench_python.py)"
PENDULUM = """<mujoco><worldbody><body><joint name="hinge" type="hinge" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05" mass="1"/></body></worldbody>
  <actuator><motor joint="hinge"/></actuator></mujoco>"""


def per_call(fns: dict, n: int, rounds: int) -> dict:
    """Median µs per call of each function, rounds interleaved."""
    times = {k: [] for k in fns}
    for _ in range(rounds):
        for k, f in fns.items():
            t0 = time.perf_counter()
            for _ in range(n):
                f()
            times[k].append((time.perf_counter() - t0) / n * 1e6)
    return {k: statistics.median(v) for k, v in times.items()}


def step_rows(mj, quick: bool) -> list[str]:
    rows = []
    scenes = [("pendulum (1 dof)", None), ("go1", ROOT / "models/mjcf/unitree_go1/scene.xml"),
              ("humanoid", ROOT / "models/mjcf/humanoid/humanoid.xml")]
    for name, path in scenes:
        if path is None:
            mm, m = mj.MjModel.from_xml_string(PENDULUM), lagrange.Model.from_string(PENDULUM)
        else:
            mm, m = mj.MjModel.from_xml_path(str(path)), lagrange.Model.from_file(path)
        md, d = mj.MjData(mm), lagrange.Data(m)
        if mm.nkey:
            mj.mj_resetDataKeyframe(mm, md, 0)
            lagrange.reset_keyframe(m, d, 0)
        n = 200 if quick else 2000
        t = per_call({"lagrange": lambda: lagrange.step(m, d), "mujoco": lambda: mj.mj_step(mm, md)}, n,
                     3 if quick else 7)
        rows.append(f"| `step` | {name} | {t['lagrange']:.2f} | `mj_step` {t['mujoco']:.2f} | {t['lagrange'] / t['mujoco']:.2f} |")
    return rows


def aba_rows(pin, quick: bool) -> list[str]:
    rows = []
    for name in ("ur5", "panda", "solo12"):
        path = ROOT / f"models/{name}/{name}.urdf"
        m, model = lagrange.Model.from_file(path), pin.buildModelFromUrdf(str(path))
        d, data = lagrange.Data(m), model.createData()
        rng = np.random.default_rng(0)
        q = rng.uniform(-1, 1, m.nq)
        v, tau = rng.standard_normal(m.nv), rng.standard_normal(m.nv)
        n = 2000 if quick else 20000
        t = per_call({"lagrange": lambda: lagrange.aba(m, d, q, v, tau), "pin": lambda: pin.aba(model, data, q, v, tau)},
                     n, 3 if quick else 7)
        rows.append(f"| `aba` | {name} | {t['lagrange']:.2f} | `pinocchio.aba` {t['pin']:.2f} | {t['lagrange'] / t['pin']:.2f} |")
    return rows


def rollout_rows(mj, quick: bool) -> list[str]:
    from mujoco import rollout as mj_rollout

    rows = []
    nbatch, nstep = (8, 50) if quick else (16, 250)
    for name, path in [("go1", ROOT / "models/mjcf/unitree_go1/scene.xml"),
                       ("humanoid", ROOT / "models/mjcf/humanoid/humanoid.xml")]:
        mm, m = mj.MjModel.from_xml_path(str(path)), lagrange.Model.from_file(path)
        md, d = mj.MjData(mm), lagrange.Data(m)
        if mm.nkey:
            mj.mj_resetDataKeyframe(mm, md, 0)
            lagrange.reset_keyframe(m, d, 0)
        rng = np.random.default_rng(1)
        vel = 0.05 * rng.standard_normal((nbatch, m.nv))
        ctrl = 0.05 * rng.standard_normal((nbatch, nstep, m.nu))
        ours = np.tile(np.concatenate([d.qpos, d.qvel, d.act]), (nbatch, 1))
        ours[:, m.nq:m.nq + m.nv] += vel
        spec = mj.mjtState.mjSTATE_FULLPHYSICS
        full = np.zeros(mj.mj_stateSize(mm, spec))
        states = []
        for i in range(nbatch):
            md.qvel[:] = vel[i] + (mm.key_qvel[0] if mm.nkey else 0)
            mj.mj_getState(mm, md, full, spec)
            states.append(full.copy())
        states = np.array(states)
        steps = nbatch * nstep
        for threads in (1, 2):
            datas = [mj.MjData(mm) for _ in range(threads)]
            t_ours, t_mj = [], []
            for _ in range(2 if quick else 5):
                t0 = time.perf_counter()
                lagrange.rollout(m, ours, ctrl, nstep, threads=threads)
                t_ours.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                mj_rollout.rollout(mm, datas, states, ctrl, nstep=nstep)
                t_mj.append(time.perf_counter() - t0)
            a, b = steps / min(t_ours), steps / min(t_mj)
            rows.append(f"| rollout, {threads} thread{'s' if threads > 1 else ''} | {name} | {a:,.0f} | `mujoco.rollout` {b:,.0f} | {a / b:.2f} |")
    return rows


def main() -> int:
    import mujoco as mj
    import pinocchio as pin

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="fewer calls and rounds (a smoke test)")
    ap.add_argument("--no-write", action="store_true", help="print only, leave validation/bench.md")
    args = ap.parse_args()
    load = os.getloadavg()[0]
    calls = step_rows(mj, args.quick) + aba_rows(pin, args.quick)
    rolls = rollout_rows(mj, args.quick)
    lines = [
        HEADER, "",
        f"{datetime.date.today()}, {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs (shared; "
        f"load average {load:.1f} before the run), "
        f"Python {platform.python_version()}, MuJoCo {mj.__version__}, Pinocchio {pin.__version__}, "
        f"lagrange {lagrange.__version__}{' (--quick)' if args.quick else ''}. Median µs per call from Python "
        "(arguments prepared outside the timing), and rollout throughput; ratio below 1 (per call) or "
        "above 1 (throughput): lagrange better.", "",
        "| call | model | lagrange µs | other µs | lagrange / other |", "| --- | --- | ---: | ---: | ---: |", *calls, "",
        "| rollout | model | lagrange steps/s | other steps/s | lagrange / other |", "| --- | --- | ---: | ---: | ---: |",
        *rolls, "",
    ]
    section = "\n".join(lines)
    print(section)
    if not args.no_write:
        text = BENCH.read_text()
        if HEADER in text:
            start = text.index(HEADER)
            nxt = text.find("\n## ", start + len(HEADER))
            text = text[:start] + section + ("" if nxt < 0 else text[nxt + 1:])
        else:
            text = text.rstrip("\n") + "\n\n" + section
        BENCH.write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
