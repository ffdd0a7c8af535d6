"""Reference data for the sensors: MuJoCo's sensordata after mj_forward on the scenes of
SCENES at random states (configurations perturbed from qpos0, random velocities, controls and
times) and at hand-made states with the puck pressed into the floor; and after three mj_step
(Euler) from the first state, where MuJoCo's sensordata is the one of the state each step started
from. Writes tests/data/mujoco_sensors/<scene>.json (generated: do not edit); with --check,
recomputes and exits 1 when the committed files differ beyond 1e-12.

  python validation/mujoco_sensor_golden.py [--check]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES = [ROOT / "tests/data/mjcf/sensors/kinematic.xml", ROOT / "tests/data/mjcf/sensors/imu_force.xml"]
OUT = ROOT / "tests/data/mujoco_sensors"
# MuJoCo's enum names that differ from the MJCF tags lagrange labels unnamed sensors with.
TAG = {"jointactfrc": "jointactuatorfrc", "tendonactfrc": "tendonactuatorfrc", "geomdist": "distance",
       "geomnormal": "normal", "geomfromto": "fromto"}


def sensor_label(m: mujoco.MjModel, i: int) -> str:
    """The name lagrange reports sensor i under: its name, or TAG#i."""
    s = m.sensor(i)
    if s.name:
        return s.name
    tag = mujoco.mjtSensor(s.type[0]).name[len("mjSENS_"):].lower()
    return f"{TAG.get(tag, tag)}#{i}"


def sensors(m: mujoco.MjModel, d: mujoco.MjData) -> dict:
    return {sensor_label(m, i): d.sensordata[m.sensor_adr[i]:m.sensor_adr[i] + m.sensor_dim[i]].tolist()
            for i in range(m.nsensor)}


def states(m: mujoco.MjModel) -> list[dict]:
    rng = np.random.default_rng(7)
    out = []
    for k in range(6):
        q = m.qpos0.copy()
        mujoco.mj_integratePos(m, q, 0.6 * rng.standard_normal(m.nv), 1.0)
        v = 0.8 * rng.standard_normal(m.nv)
        out.append({"q": q.tolist(), "v": v.tolist(), "ctrl": rng.uniform(-1, 1, m.nu).tolist(), "time": 0.25 * k})
    # The puck pressed 5 mm into the floor, tilted, sliding: contact rows and forces.
    free = m.jnt_qposadr[m.joint("free").id]
    for depth, tilt in ((0.005, 0.0), (0.002, 0.05)):
        q = m.qpos0.copy()
        q[free:free + 7] = [-1.0, 0.0, 0.05 - depth, np.cos(tilt / 2), np.sin(tilt / 2), 0.0, 0.0]
        v = np.zeros(m.nv)
        v[m.jnt_dofadr[m.joint("free").id]] = 0.3
        out.append({"q": q.tolist(), "v": v.tolist(), "ctrl": [0.0] * m.nu, "time": 1.0})
    return out


def run(scene: Path) -> dict:
    m = mujoco.MjModel.from_xml_path(str(scene))
    d = mujoco.MjData(m)
    forward = []
    for s in states(m):
        d.qpos[:], d.qvel[:], d.ctrl[:], d.time = s["q"], s["v"], s["ctrl"], s["time"]
        mujoco.mj_forward(m, d)
        forward.append({**s, "ncon": int(d.ncon), "sensors": sensors(m, d)})
    first = forward[0]
    d.qpos[:], d.qvel[:], d.ctrl[:], d.time = first["q"], first["v"], first["ctrl"], first["time"]
    steps = []
    for _ in range(3):
        before = {"q": d.qpos.tolist(), "v": d.qvel.tolist(), "time": d.time}
        mujoco.mj_step(m, d)
        steps.append({"before": before, "sensors": sensors(m, d)})
    return {"generated_by": "validation/mujoco_sensor_golden.py (do not edit)", "mujoco": mujoco.__version__,
            "model": str(scene.relative_to(ROOT)), "forward": forward, "steps": steps}


def max_difference(a: dict, b: dict) -> float:
    worst = 0.0
    for x, y in zip(a["forward"] + a["steps"], b["forward"] + b["steps"]):
        for k, v in x["sensors"].items():
            if k not in y["sensors"] or len(y["sensors"][k]) != len(v):
                return float("inf")
            worst = max(worst, float(np.max(np.abs(np.array(v) - np.array(y["sensors"][k])), initial=0.0)))
    return worst


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    status = 0
    for scene in SCENES:
        doc = run(scene)
        path = OUT / f"{scene.stem}.json"
        if args.check:
            worst = max_difference(doc, json.loads(path.read_text()))
            ok = worst <= 1e-12
            print(f"sensor reference data {path.name}: live MuJoCo {mujoco.__version__} differs by {worst:.1e} "
                  f"({'ok' if ok else 'CHANGED'})")
            status |= 0 if ok else 1
        else:
            path.write_text(json.dumps(doc, indent=1) + "\n")
            print(f"wrote {path.relative_to(ROOT)}")
    return status


if __name__ == "__main__":
    sys.exit(main())
