#!/usr/bin/env python3
"""Strips the purely visual meshes from a shipped Menagerie MJCF model, as strip_meshes.py does for
the URDF robots: deletes `<geom class="visual" ...>` lines that use a mesh and the `<mesh>` assets
and files no longer referenced. Geoms of the visual class have no mass and no contacts
(contype = conaffinity = 0, density 0), so the dynamics are unchanged; every body keeps its
explicit <inertial>. MuJoCo loads the stripped file. Usage:

    python3 validation/strip_mjcf_visuals.py models/mjcf/franka_emika_panda/panda.xml
"""
import os
import re
import sys
import xml.etree.ElementTree as ET


def main(path):
    text = open(path).read()
    root = ET.fromstring(text)
    meshdir = (root.find("compiler").get("meshdir") if root.find("compiler") is not None else "") or ""
    # Lines of visual mesh geoms go; everything else stays byte for byte.
    kept_lines = [l for l in text.splitlines(keepends=True)
                  if not (re.search(r'<geom\b[^>]*class="visual"', l) and "mesh=" in l)]
    kept = "".join(kept_lines)
    used = set(re.findall(r'<geom\b[^>]*\bmesh="([^"]+)"', kept))
    out, removed = [], []
    for l in kept.splitlines(keepends=True):
        m = re.search(r'<mesh\b([^>]*)/>', l)
        if m:
            attrs = dict(re.findall(r'(\w+)="([^"]*)"', m.group(1)))
            name = attrs.get("name") or os.path.splitext(os.path.basename(attrs["file"]))[0]
            if name not in used:
                removed.append(attrs["file"])
                continue
        out.append(l)
    with open(path, "w") as f:
        f.write("".join(out))
    folder = os.path.join(os.path.dirname(path), meshdir)
    for file in removed:
        p = os.path.join(folder, file)
        if os.path.exists(p):
            os.remove(p)
    print(f"{path}: removed {len(removed)} visual meshes")


if __name__ == "__main__":
    for p in sys.argv[1:]:
        main(p)
