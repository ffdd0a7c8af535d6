#!/usr/bin/env python3
"""MuJoCo's mesh hull graphs and face polygons, for lagrange's qhull tests (tests/mesh_graph.rs).

Run from the repository root with the validation venv (see validation/README.md):

    python validation/mujoco_qhull_golden.py            # (re)write tests/data/mujoco/qhull.json
    python validation/mujoco_qhull_golden.py --check    # recompute in memory, exit 1 if it differs

MuJoCo's compiler hulls every mesh with qhull (mjCMesh::MakeGraph in src/user/user_mesh.cc) and
merges the hull's coplanar triangles into face polygons (MakePolygons). The order of qhull's
vertices and facets decides the mesh graph (mesh_graph: hull vertices, their neighbour lists, the
triangles) and where each polygon starts (mesh_polyvert); the polygon order follows MakePolygons'
hash map. For each mesh this records, from the compiled model: the mesh's vertices as MuJoCo
read them (mesh_vert count; the file's vertices, repeated ones removed), mesh_graph, and the
polygons (mesh_polynum, the vertex lists of mesh_polyvert, mesh_polymap). Meshes: the corpus
meshes under tests/data/meshes/mujoco, the mesh_pile scene's meshes (validation/scenes/meshes),
and inline vertex sets (a random cloud, prisms with many-sided faces, a box with extra points on
its faces; vertices given as f32-exact decimals). The integers must match exactly; --check
compares them exactly.
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys

import mujoco
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from mujoco_golden import check_status, dump  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parent.parent
OUT = REPO / "tests" / "data" / "mujoco" / "qhull.json"
SEED = 20261127


def file_meshes() -> list[tuple[str, str]]:
    """(name, repository-relative path) of the mesh files."""
    paths = sorted((REPO / "tests" / "data" / "meshes" / "mujoco").rglob("*"))
    paths = [p for p in paths if p.suffix.lower() in (".stl", ".obj")]
    paths += sorted((REPO / "validation" / "scenes" / "meshes").glob("*.obj"))
    return [(p.stem, str(p.relative_to(REPO))) for p in paths]


def f32(x: float) -> float:
    return float(np.float32(x))


def inline_meshes() -> list[tuple[str, list[float]]]:
    """(name, flat vertex list) of the inline vertex sets (f32-exact values)."""
    rng = np.random.default_rng(SEED)
    out = []
    cloud = rng.normal(size=(60, 3)) * np.array([0.05, 0.03, 0.02])
    out.append(("cloud60", [f32(v) for v in cloud.ravel()]))
    for sides, h in ((5, 0.02), (8, 0.03), (11, 0.015)):
        r = 0.04
        verts = []
        turn = rng.uniform(0, 2 * math.pi)
        for z in (-h, h):
            for k in range(sides):
                a = turn + 2 * math.pi * k / sides
                verts += [f32(r * math.cos(a)), f32(r * math.sin(a)), f32(z)]
        out.append((f"prism{sides}", verts))
    # A box with points inside its faces (coplanar points qhull drops) and a corner cut.
    verts = []
    for i in range(8):
        verts += [0.05 if i & 1 else -0.05, 0.03 if i & 2 else -0.03, 0.02 if i & 4 else -0.02]
    verts += [0.0, 0.0, 0.02, 0.01, -0.01, -0.02, 0.05, 0.0, 0.0, 0.0125, 0.03, 0.0]
    out.append(("box_facepoints", [f32(v) for v in verts]))
    return out


def record(model: mujoco.MjModel, i: int) -> dict:
    """The mesh's hull graph and polygons."""
    nv = int(model.mesh_vertnum[i])
    gadr = int(model.mesh_graphadr[i])
    numvert, numface = int(model.mesh_graph[gadr]), int(model.mesh_graph[gadr + 1])
    graph = model.mesh_graph[gadr : gadr + 2 + 3 * numvert + 6 * numface].tolist()
    polys = []
    padr, pnum = int(model.mesh_polyadr[i]), int(model.mesh_polynum[i])
    for p in range(padr, padr + pnum):
        a, n = int(model.mesh_polyvertadr[p]), int(model.mesh_polyvertnum[p])
        polys.append(model.mesh_polyvert[a : a + n].tolist())
    polymap = []
    for v in range(nv):
        a = int(model.mesh_polymapadr[int(model.mesh_vertadr[i]) + v])
        n = int(model.mesh_polymapnum[int(model.mesh_vertadr[i]) + v])
        polymap.append(model.mesh_polymap[a : a + n].tolist())
    return {"nvert": nv, "graph": graph, "polygons": polys, "polymap": polymap}


def compute() -> dict:
    meshes = []
    assets = []
    for name, path in file_meshes():
        assets.append(f'<mesh name="{name}" file="{REPO / path}"/>')
        meshes.append({"name": name, "file": path})
    for name, verts in inline_meshes():
        assets.append(f'<mesh name="{name}" vertex="{" ".join(repr(v) for v in verts)}"/>')
        meshes.append({"name": name, "vertex": verts})
    # A colliding geom per mesh: MuJoCo builds the graph only for meshes that collide.
    geoms = "".join(f'<geom type="mesh" mesh="{m["name"]}"/>' for m in meshes)
    xml = f"<mujoco><asset>{''.join(assets)}</asset><worldbody><body>{geoms}</body></worldbody></mujoco>"
    model = mujoco.MjModel.from_xml_string(xml)
    for i, m in enumerate(meshes):
        assert mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_MESH, i) == m["name"]
        m.update(record(model, i))
    return {
        "generator": "validation/mujoco_qhull_golden.py",
        "mujoco": mujoco.__version__,
        "meshes": meshes,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="recompute in memory; exit 1 if the file differs")
    args = ap.parse_args()
    doc = compute()
    text = dump(doc) + "\n"
    if args.check:
        old = OUT.read_text() if OUT.exists() else None
        status = check_status(old, text, doc, 0.0)
        print(f"{OUT.relative_to(REPO)}: {status}")
        return 0 if status.startswith("ok") else 1
    OUT.write_text(text)
    print(f"wrote {OUT.relative_to(REPO)} ({len(doc['meshes'])} meshes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
