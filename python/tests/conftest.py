"""Shared fixtures of the lagrange Python tests: the repository root, model paths, and tight
copies of MJCF scenes (MuJoCo's Newton solver run to round-off, as validation/crossval_common
does) so that lagrange and MuJoCo meet the same constrained optimum."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
GO1 = ROOT / "models/mjcf/unitree_go1/scene.xml"
HUMANOID = ROOT / "models/mjcf/humanoid/humanoid.xml"
UR5 = ROOT / "models/ur5/ur5.urdf"
PANDA = ROOT / "models/panda/panda.urdf"
SOLO12 = ROOT / "models/solo12/solo12.urdf"
SENSOR_SCENES = [ROOT / "tests/data/mjcf/sensors" / n for n in ("imu_force.xml", "quadruped.xml", "frames.xml")]

TIGHT = ('<option solver="Newton" tolerance="1e-15" iterations="1000" ls_iterations="100" '
         'ls_tolerance="1e-12" jacobian="dense"')


def tight_text(path: Path) -> str:
    """The MJCF text of `path` with the tight solver options merged into its <option> and
    repeated last (an included file's <option> would otherwise win)."""
    text = path.read_text()
    m = re.search(r"<option\b([^>]*?)(/?)>", text)
    if m:
        attrs = re.sub(r'\b(solver|tolerance|iterations|ls_iterations|ls_tolerance|jacobian)="[^"]*"', "", m.group(1))
        text = text[:m.start()] + TIGHT + attrs + m.group(2) + ">" + text[m.end():]
    else:
        text = re.sub(r"(<mujoco\b[^>]*>)", r"\1" + TIGHT + "/>", text, count=1)
    head, sep, tail = text.rpartition("</mujoco>")
    return head + TIGHT + "/>" + sep + tail if sep else text


@pytest.fixture
def tight_copy():
    """Writes tight copies beside the originals (includes and meshes resolve) and removes them."""
    made = []

    def make(path: Path) -> Path:
        out = path.with_name(f".pytest-{path.stem}-{os.getpid()}-{len(made)}.xml")
        out.write_text(tight_text(path))
        made.append(out)
        return out

    yield make
    for p in made:
        p.unlink(missing_ok=True)


def rel_err(a, b) -> float:
    """max |a - b| / max(1, max |b|)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.max(np.abs(a - b), initial=0.0) / max(1.0, float(np.max(np.abs(b), initial=0.0))))


@pytest.fixture(scope="session")
def cluster():
    """A local Ray cluster of 2 CPUs for the session (the running one if Ray is initialized)."""
    ray = pytest.importorskip("ray")
    started = not ray.is_initialized()
    if started:
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    yield ray
    if started:
        ray.shutdown()
