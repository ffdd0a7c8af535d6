#!/usr/bin/env python3
"""Copy the validation robots out of example-robot-data, stripping mesh geometry.

For each robot, every ``<visual>`` / ``<collision>`` element of a ``<link>`` whose
``<geometry>`` references a ``<mesh>`` is removed. Visual/collision elements using
primitive shapes (box, cylinder, sphere) are kept. Everything else in the file is
left byte-identical: the removal works on the raw text (a small tag scanner that
skips comments, CDATA and processing instructions), deleting each removed element
together with the indentation before it and the newline after it.

The result is checked with ElementTree: the stripped tree must equal the original
tree minus exactly the removed elements, and must contain no ``<mesh>`` any more.

Usage (from the repository root, with the validation venv):

    python validation/strip_meshes.py            # write models/*/<robot>.urdf
    python validation/strip_meshes.py --check    # verify the committed copies
"""

from __future__ import annotations

import argparse
import pathlib
import re
import sys
import sysconfig
import xml.etree.ElementTree as ET

REPO = pathlib.Path(__file__).resolve().parent.parent

# robot -> (path inside example-robot-data/robots/, output path inside the repo)
ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "models/ur5/ur5.urdf"),
    "panda": ("panda_description/urdf/panda.urdf", "models/panda/panda.urdf"),
    "solo12": ("solo_description/robots/solo12.urdf", "models/solo12/solo12.urdf"),
}


def erd_robots_dir() -> pathlib.Path:
    """Locate <site-packages>/cmeel.prefix/share/example-robot-data/robots."""
    candidates = []
    for key in ("purelib", "platlib"):
        candidates.append(
            pathlib.Path(sysconfig.get_paths()[key])
            / "cmeel.prefix/share/example-robot-data/robots"
        )
    for c in candidates:
        if c.is_dir():
            return c
    sys.exit(
        "example-robot-data not found (looked in %s); install "
        "validation/requirements.txt into the active venv" % candidates
    )


_NAME = r"[A-Za-z_:][-A-Za-z0-9_:.]*"
_TOKEN = re.compile(
    r"<!--.*?-->"  # comment
    r"|<!\[CDATA\[.*?\]\]>"  # CDATA
    r"|<\?.*?\?>"  # processing instruction / xml declaration
    r"|<!.*?>"  # doctype etc.
    r"|<(/?)(" + _NAME + r")((?:[^>\"']|\"[^\"]*\"|'[^']*')*?)(/?)>",  # tag
    re.S,
)


def mesh_spans(text: str) -> list[tuple[int, int]]:
    """Return (start, end) spans of <visual>/<collision> children of <link>
    that contain a <mesh> element (anywhere below them)."""
    stack: list[str] = []
    spans = []
    current = None  # [start, depth, has_mesh]
    for m in _TOKEN.finditer(text):
        if m.group(2) is None:
            continue  # comment / CDATA / PI
        closing, name, _attrs, selfclose = m.group(1), m.group(2), m.group(3), m.group(4)
        if closing:
            if not stack or stack[-1] != name:
                raise ValueError("unbalanced </%s> at offset %d" % (name, m.start()))
            stack.pop()
            if current is not None and len(stack) == current[1]:
                if current[2]:
                    spans.append((current[0], m.end()))
                current = None
            continue
        if current is not None and name == "mesh":
            current[2] = True
        if (
            current is None
            and name in ("visual", "collision")
            and stack
            and stack[-1] == "link"
        ):
            if selfclose:
                continue  # empty element: no mesh
            current = [m.start(), len(stack), False]
        if not selfclose:
            stack.append(name)
    if stack:
        raise ValueError("unclosed elements: %s" % stack)
    return spans


def strip(text: str) -> tuple[str, int]:
    spans = mesh_spans(text)
    out = []
    pos = 0
    for start, end in spans:
        # Extend over the line's leading whitespace and the trailing newline when
        # the element occupies whole lines, so no blank lines are left behind.
        line_start = text.rfind("\n", 0, start) + 1
        if text[line_start:start].strip() == "":
            s = line_start
        else:
            s = start
        e = end
        rest = re.match(r"[ \t]*\r?\n", text[end:])
        if rest and s == line_start:
            e = end + rest.end()
        out.append(text[pos:s])
        pos = e
    out.append(text[pos:])
    return "".join(out), len(spans)


def _canon(elem: ET.Element):
    return (
        elem.tag,
        tuple(sorted(elem.attrib.items())),
        (elem.text or "").strip(),
        tuple(_canon(c) for c in elem),
    )


def _reference_strip(root: ET.Element) -> ET.Element:
    for link in root.iter("link"):
        for child in list(link):
            if child.tag in ("visual", "collision") and child.find(".//mesh") is not None:
                link.remove(child)
    return root


def verify(original: str, stripped: str) -> None:
    a = _reference_strip(ET.fromstring(original.encode()))
    b = ET.fromstring(stripped.encode())
    if _canon(a) != _canon(b):
        raise AssertionError("stripped tree differs from the reference strip")
    if b.find(".//mesh") is not None:
        raise AssertionError("a <mesh> survived stripping")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="only verify models/ is up to date")
    args = ap.parse_args()
    src_root = erd_robots_dir()
    status = 0
    for robot, (src_rel, dst_rel) in ROBOTS.items():
        src = src_root / src_rel
        dst = REPO / dst_rel
        original = src.read_bytes().decode("utf-8")
        stripped, n = strip(original)
        verify(original, stripped)
        if args.check:
            ok = dst.exists() and dst.read_bytes() == stripped.encode("utf-8")
            print("%-14s %s" % (robot, "ok" if ok else "OUT OF DATE"))
            status |= 0 if ok else 1
        else:
            dst.parent.mkdir(parents=True, exist_ok=True)
            dst.write_bytes(stripped.encode("utf-8"))
            print(
                "%-14s %s -> %s: removed %d mesh visual/collision elements, %d -> %d bytes"
                % (robot, src_rel, dst_rel, n, len(original.encode()), len(stripped.encode()))
            )
    return status


if __name__ == "__main__":
    sys.exit(main())
