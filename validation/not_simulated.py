#!/usr/bin/env python3
"""The count of what lagrange parses but does not simulate: `lagrange info` on every MJCF model of the corpus (validation/crossval_corpus.py,
`--extra` adds MyoSuite's), listing each element it reports as "parsed, not simulated" other than
flexes, skins, plugins and user sensors (which stay outside the engine). Prints the count and the
elements; exits 1 when a model has one, or when lagrange cannot load a model MuJoCo loads.

    python validation/not_simulated.py [--lagrange BIN] [--extra]
"""

from __future__ import annotations

import argparse
import collections
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from crossval_corpus import REPO, corpus  # noqa: E402

OUTSIDE = ("flex", "skin", "plugin", "user sensor")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lagrange", default=str(REPO / "target/release/lagrange"))
    ap.add_argument("--extra", action="store_true")
    args = ap.parse_args()
    import mujoco

    seen, found, failed = set(), collections.defaultdict(list), []
    for e in corpus(extra=args.extra):
        path = str(e.path)
        if e.fmt != "mjcf" or path in seen:
            continue
        seen.add(path)
        r = subprocess.run([args.lagrange, "info", path], capture_output=True, text=True, timeout=600)
        if r.returncode != 0:
            try:
                mujoco.MjModel.from_xml_path(path)
            except Exception:  # MuJoCo refuses it too (a fragment, a missing asset): not counted
                continue
            failed.append((e.name, (r.stderr.strip().splitlines() or ["?"])[-1][:300]))
            continue
        for line in (r.stdout + r.stderr).splitlines():
            if "not simulated" in line and not any(w in line for w in OUTSIDE):
                found[line.strip()[:200]].append(e.name)
    n = sum(len(v) for v in found.values())
    print(f"not simulated: {n} element lines on {len(seen)} corpus MJCF models "
          f"(flexes, skins, plugins and user sensors aside); {len(failed)} models MuJoCo loads and lagrange refuses")
    for line, models in found.items():
        print(f"  {line}  ({len(models)}: {', '.join(models[:3])}{' …' if len(models) > 3 else ''})")
    for name, why in failed:
        print(f"  refused: {name}: {why}")
    return 1 if n or failed else 0


if __name__ == "__main__":
    sys.exit(main())
