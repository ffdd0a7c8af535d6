"""Reference data for the placement of geoms and sites that share their body's frame or inertial
frame (MuJoCo's `geom_sameframe`, `site_sameframe`; src/io/sameframe.rs) and for the frame MuJoCo
moves a mesh into (`mesh_pos`, `mesh_quat`; src/mass/eig3.rs, src/io/geom_hull.rs):
- "meshes": for every mesh under tests/data/meshes/mujoco at scales 1, 0.001 and 10, MuJoCo's
  `mesh_pos` and `mesh_quat` (a free body holding only that mesh, legacy inertia; left out where
  MuJoCo refuses the mesh at that scale);
- "models": for tests/data/mjcf/sameframe/flags.xml and the MJCF models under models/mjcf, MuJoCo's
  `geom_sameframe`, `site_sameframe` and, after mj_forward at qpos0, `geom_xpos`, `geom_xmat`,
  `site_xpos`, `site_xmat`.
Writes tests/data/mujoco/sameframe.json (generated: do not edit); with --check, recomputes and exits
1 when the committed file differs beyond 1e-12. Read by tests/mujoco_sameframe.rs.

  python validation/mujoco_sameframe_golden.py [--check]
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco

sys.path.insert(0, str(Path(__file__).resolve().parent))
from golden_common import golden_main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MESHES = ROOT / "tests/data/meshes/mujoco"
OUT = ROOT / "tests/data/mujoco/sameframe.json"
SCALES = [1.0, 0.001, 10.0]
MODELS = [
    "tests/data/mjcf/sameframe/flags.xml",
    "models/mjcf/humanoid/humanoid.xml",
    "models/mjcf/franka_emika_panda/scene.xml",
    "models/mjcf/unitree_go1/scene.xml",
]


def mesh_model(path: Path, scale: float) -> str:
    """A free body holding only the mesh at `path` (relative to MESHES) scaled by `scale`."""
    return (f'<mujoco><compiler meshdir="{MESHES}"/><asset><mesh name="m" file="{path}" '
            f'scale="{scale!r} {scale!r} {scale!r}"/></asset><worldbody><body><freejoint/>'
            f'<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/><geom type="mesh" mesh="m" mass="0"/>'
            f'</body></worldbody></mujoco>')


def meshes() -> list:
    out = []
    files = sorted(p.relative_to(MESHES) for p in MESHES.rglob("*") if p.suffix.lower() in (".stl", ".obj"))
    for path in files:
        for scale in SCALES:
            try:
                m = mujoco.MjModel.from_xml_string(mesh_model(path, scale))
            except ValueError:
                continue  # MuJoCo refuses it at this scale (a volume below mjMINVAL)
            out.append({"file": path.as_posix(), "scale": scale, "mesh_pos": m.mesh_pos[0].tolist(),
                        "mesh_quat": m.mesh_quat[0].tolist()})
    return out


def models() -> list:
    out = []
    for rel in MODELS:
        m = mujoco.MjModel.from_xml_path(str(ROOT / rel))
        d = mujoco.MjData(m)
        mujoco.mj_forward(m, d)
        out.append({"model": rel, "geom_sameframe": m.geom_sameframe.tolist(),
                    "site_sameframe": m.site_sameframe.tolist(), "geom_xpos": d.geom_xpos.tolist(),
                    "geom_xmat": d.geom_xmat.tolist(), "site_xpos": d.site_xpos.tolist(),
                    "site_xmat": d.site_xmat.tolist()})
    return out


def main() -> int:
    return golden_main(__doc__, "validation/mujoco_sameframe_golden.py", "sameframe", OUT, ROOT,
                       lambda: {"meshes": meshes(), "models": models()})


if __name__ == "__main__":
    sys.exit(main())
