"""One full step in soft mode beside MuJoCo's mj_step, in the same run (issue 12, item 5).

For each scene: MuJoCo 4.0's `mj_step` (C loop, `nstep`) and `lagrange bench --json`'s
`soft_step_us` (lagrange's Simulation in soft mode), both with the model's own <option>
(integrator, timestep, solver, tolerance), from the first keyframe with its ctrl, for the same
number of steps; three interleaved rounds, medians. Prints µs per step and the ratio
lagrange / MuJoCo. Report only (no threshold): timings on a shared machine.
  validation/.venv/bin/python validation/bench_soft_step.py [--lagrange target/release/lagrange]
"""

import argparse
import json
import platform
import statistics
import subprocess
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENES = [("go1 (scene.xml)", "models/mjcf/unitree_go1/scene.xml"),
          ("humanoid (dm_control)", "models/mjcf/humanoid/humanoid.xml")]


def mujoco_step_us(mj, path: Path, steps: int) -> tuple[float, int]:
    m = mj.MjModel.from_xml_path(str(path))
    d = mj.MjData(m)
    if m.nkey:
        mj.mj_resetDataKeyframe(m, d, 0)
    t0 = time.perf_counter()
    mj.mj_step(m, d, nstep=steps)
    return (time.perf_counter() - t0) * 1e6 / steps, int(d.nefc)


def main():
    import mujoco as mj

    ap = argparse.ArgumentParser()
    ap.add_argument("--lagrange", default=str(ROOT / "target/release/lagrange"))
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    print(f"one step in soft mode beside mj_step (MuJoCo {mj.__version__}), the model's <option>, "
          f"from its first keyframe; {platform.processor() or platform.machine()}, medians of {args.rounds} rounds")
    print(f"{'scene':<24} {'lagrange µs':>12} {'rows':>5} {'MuJoCo µs':>10} {'rows':>5} {'ratio':>7}")
    for name, rel in SCENES:
        path = ROOT / rel
        ours, theirs = [], []
        rows = (0, 0)
        for _ in range(args.rounds):
            p = subprocess.run([args.lagrange, "bench", str(path), "--json"], capture_output=True, text=True,
                               check=True)
            b = json.loads(p.stdout)
            ours.append(b["soft_step_us"])
            t, n = mujoco_step_us(mj, path, b["soft_steps"])
            theirs.append(t)
            rows = (b["soft_step_rows"], n)
        a, b = statistics.median(ours), statistics.median(theirs)
        print(f"{name:<24} {a:>12.2f} {rows[0]:>5} {b:>10.2f} {rows[1]:>5} {a / b:>7.2f}")


if __name__ == "__main__":
    main()
