#!/usr/bin/env python3
"""Writes the small test meshes of tests/mass.rs into this folder (deterministic; standard library
only). Run from anywhere: python3 tests/data/meshes/make_meshes.py

The unit cube [0, 1]^3 in various formats and states of repair:
  cube.obj                quads, with v/vt/vn references, comments, a negative (relative) index
  cube_ascii.stl          ASCII STL
  cube_binary.stl         binary STL whose 80-byte header starts with "solid" (a classic trap)
  cube.msh                MuJoCo's binary MSH
  two_objects.obj         the cube ("o first") and a copy shifted by +2 in x ("o second"):
                          MuJoCo's OBJ decoder keeps only the first object's faces (but every
                          vertex, so its convex hull spans both)
  open_cube.stl           the top face missing (a real hole)
  misoriented_cube.obj    one triangle wound the wrong way
  inside_out_cube.stl     every triangle wound the wrong way (negative volume)
  flat_square.obj         both sides of a unit square in z = 0: closed, area 2, no volume
  collinear.obj           four points on a line (zero area)
  three_vertices.obj      a single triangle (fewer than 4 vertices)
  bad_index.obj           a face refers to vertex 9 of 8
  truncated.stl           binary STL cut short
  garbage.stl             neither binary nor ASCII STL
  tjunction_box.stl       a 2x1x1 box whose bottom is split at x = 1 but whose front and back
                          faces are not: T-junctions, combinatorially open, geometrically closed
  cube.dae                a COLLADA file (unsupported)
"""

import pathlib
import struct

HERE = pathlib.Path(__file__).resolve().parent

V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
QUADS = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
TRIS = [t for q in QUADS for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))]


def write(name: str, data) -> None:
    path = HERE / name
    if isinstance(data, str):
        path.write_text(data)
    else:
        path.write_bytes(data)


def obj(vertices, faces, header="") -> str:
    lines = [header] if header else []
    lines += [f"v {x} {y} {z}" for x, y, z in vertices]
    lines += ["f " + " ".join(str(i + 1) for i in f) for f in faces]
    return "\n".join(lines) + "\n"


def normal(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    w = [c[i] - a[i] for i in range(3)]
    return (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])


def stl_ascii(vertices, tris, name="cube") -> str:
    out = [f"solid {name}"]
    for t in tris:
        a, b, c = (vertices[i] for i in t)
        out.append("  facet normal {} {} {}".format(*normal(a, b, c)))
        out.append("    outer loop")
        for p in (a, b, c):
            out.append("      vertex {} {} {}".format(*p))
        out.append("    endloop")
        out.append("  endfacet")
    out.append(f"endsolid {name}")
    return "\n".join(out) + "\n"


def stl_binary(vertices, tris, header=b"binary STL") -> bytes:
    data = header.ljust(80, b" ") + struct.pack("<I", len(tris))
    for t in tris:
        a, b, c = (vertices[i] for i in t)
        data += struct.pack("<12fH", *normal(a, b, c), *a, *b, *c, 0)
    return data


def main() -> None:
    # cube.obj: quads with texture/normal references and one relative index.
    lines = ["# unit cube, quads", "mtllib none.mtl", "o cube"]
    lines += [f"v {x} {y} {z}" for x, y, z in V]
    lines += ["vt 0 0", "vn 0 0 1"]
    for k, q in enumerate(QUADS):
        if k == 1:  # top face with negative indices: -8 is vertex 1 (0-based 0) after 8 vertices
            lines.append("f " + " ".join(f"{i - 8}/1/1" for i in q))
        else:
            lines.append("f " + " ".join(f"{i + 1}/1/1" for i in q))
    write("cube.obj", "\n".join(lines) + "\n")
    write("cube_ascii.stl", stl_ascii(V, TRIS))
    write("cube_binary.stl", stl_binary(V, TRIS, header=b"solid cube (binary, despite this header)"))
    msh = struct.pack("<4i", len(V), 0, 0, len(TRIS))
    msh += b"".join(struct.pack("<3f", *v) for v in V) + b"".join(struct.pack("<3i", *t) for t in TRIS)
    write("cube.msh", msh)
    shifted = [(x + 2, y, z) for x, y, z in V]
    write("two_objects.obj", "o first\n" + obj(V, TRIS) + "o second\n"
          + "\n".join(f"v {x} {y} {z}" for x, y, z in shifted) + "\n"
          + "\n".join("f " + " ".join(str(i + 9) for i in t) for t in TRIS) + "\n")
    write("open_cube.stl", stl_binary(V, TRIS[:2] + TRIS[4:]))  # no top (tris 2 and 3)
    flipped = list(TRIS)
    flipped[5] = (TRIS[5][0], TRIS[5][2], TRIS[5][1])
    write("misoriented_cube.obj", obj(V, flipped, "# one triangle of the cube wound clockwise"))
    write("inside_out_cube.stl", stl_binary(V, [(a, c, b) for a, b, c in TRIS]))
    write("flat_square.obj", obj([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)],
                                 [(0, 1, 2), (0, 2, 3), (0, 3, 1), (1, 3, 2)], "# both sides of a square"))
    write("collinear.obj", obj([(0, 0, 0), (1, 0, 0), (2, 0, 0), (3, 0, 0)], [(0, 1, 2), (1, 2, 3)]))
    write("three_vertices.obj", obj([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)]))
    write("bad_index.obj", obj(V, TRIS[:-1]) + "f 1 2 9\n")
    write("truncated.stl", stl_binary(V, TRIS)[:-20])
    write("garbage.stl", b"\x00\x01 not an stl file")
    # 2x1x1 box: the bottom is split at x = 1 (vertex 8 = (1,0,0), 9 = (1,1,0)), the front and back
    # are not, so their long bottom edges meet two shorter edges each (two T-junctions).
    B = [(0, 0, 0), (2, 0, 0), (2, 1, 0), (0, 1, 0), (0, 0, 1), (2, 0, 1), (2, 1, 1), (0, 1, 1),
         (1, 0, 0), (1, 1, 0)]
    box = [
        (0, 9, 8), (0, 3, 9), (8, 2, 1), (8, 9, 2),  # bottom in two squares
        (4, 5, 6), (4, 6, 7),  # top
        (0, 1, 5), (0, 5, 4),  # front (y = 0): its edge 0-1 passes vertex 8 of the bottom
        (3, 7, 6), (3, 6, 2),  # back (y = 1): its edge 2-3 passes vertex 9
        (0, 4, 7), (0, 7, 3),  # left
        (1, 2, 6), (1, 6, 5),  # right
    ]
    write("tjunction_box.stl", stl_ascii(B, box, "tjunction_box"))
    write("cube.dae", '<?xml version="1.0"?>\n<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1"/>\n')


if __name__ == "__main__":
    main()
