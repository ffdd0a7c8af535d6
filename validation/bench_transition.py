#!/usr/bin/env python3
"""Same-run timing of transition Jacobians: lagrange's transition_jacobians (examples/transition_cost.rs;
finite differences with stage skipping, and the hybrid method with analytic velocity and control
columns) against MuJoCo's mjd_transitionFD (centred, eps 1e-6, no sensors), at the states of
tests/data/mujoco/transition/*.json with each model's own solver options. Report only.

    python validation/bench_transition.py [--lagrange-example PATH] [--rounds 5]

Each round times MuJoCo (median of 20 calls per state) then lagrange's two methods (the same), per
scene; the ratio of each round is lagrange / MuJoCo; prints a markdown table (median ratio and
range).
"""

from __future__ import annotations

import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import time

import mujoco as mj
import numpy as np

REPO = pathlib.Path(__file__).resolve().parent.parent
SCENES = ["go1_standing", "go1_walking", "humanoid_floor", "panda_free", "gripper_box"]


def mujoco_us(scene: str, reps: int) -> tuple[int, list[float]]:
    doc = json.loads((REPO / "tests/data/mujoco/transition" / (scene + ".json")).read_text())
    m = mj.MjModel.from_xml_path(str(REPO / doc["model"]))
    d = mj.MjData(m)
    ndx = 2 * m.nv + m.na
    A, B = np.zeros((ndx, ndx)), np.zeros((ndx, m.nu))
    out = []
    for st in doc["states"]:
        d.qpos[:], d.qvel[:], d.ctrl[:] = st["qpos"], st["qvel"], st["ctrl"]
        if m.na:
            d.act[:] = st["act"]
        d.qacc_warmstart[:] = st["qacc_warmstart"]
        mj.mjd_transitionFD(m, d, 1e-6, True, A, B, None, None)
        ts = []
        for _ in range(reps):
            t0 = time.perf_counter()
            mj.mjd_transitionFD(m, d, 1e-6, True, A, B, None, None)
            ts.append((time.perf_counter() - t0) * 1e6)
        out.append(statistics.median(ts))
    return m.nv, out


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--lagrange-example", default=str(REPO / "target/release/examples/transition_cost"))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--reps", type=int, default=20)
    args = ap.parse_args()
    rows = []
    for scene in SCENES:
        ours, hyb, theirs, ratios, hratios = [], [], [], [], []
        for _ in range(args.rounds):
            nv, mu = mujoco_us(scene, args.reps)
            theirs.append(statistics.median(mu))
            for mode, times, rs in (("skip", ours, ratios), ("hybrid", hyb, hratios)):
                res = subprocess.run([args.lagrange_example, scene, str(args.reps), mode],
                                     capture_output=True, text=True, check=True)
                times.append(statistics.median(json.loads(res.stdout)["us"]))
                rs.append(times[-1] / theirs[-1])
        rows.append("| %s | %d | %.0f | %.0f | %.0f | %.2f (%.2f–%.2f) | %.2f (%.2f–%.2f) |" % (
            scene, nv, statistics.median(ours), statistics.median(hyb), statistics.median(theirs),
            statistics.median(ratios), min(ratios), max(ratios),
            statistics.median(hratios), min(hratios), max(hratios)))
    print("| scene | nv | lagrange FD µs | lagrange hybrid µs | MuJoCo µs | FD / MuJoCo | hybrid / MuJoCo |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    print("\n".join(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
