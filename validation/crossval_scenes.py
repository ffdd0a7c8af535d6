#!/usr/bin/env python3
"""Contact scenes stepped against MuJoCo 4.0's mj_step (issue 25, items 4 and 5): corpus grippers
and hands with objects, quadrupeds and humanoids on floors, boxes and convex meshes on tables
(validation/scenes/compose.py lists them and composes the ones that need it).

Each scene is compared in a copy with a tight solver (crossval_common.tight_copy: Newton to
round-off, dense Jacobians), so that what differs is the model and the collision, not the
solver's stopping point; the scene's own integrator, timestep and cone. Started from its
keyframe (or qpos0 at rest) with the keyframe's controls, held.

(a) **stepwise**: MuJoCo runs 200 steps; from its state before each step (qpos, qvel, act, ctrl,
    time, qacc_warmstart) lagrange takes one step (`lagrange eval --step 1`). Compared: the qpos
    after the step (max |Δ| on the manifold, mj_differentiatePos) and the contact set of the
    step's collision pass (MuJoCo's d.contact after mj_step): count, geom pairs and positions,
    matched pair by pair to POS_TOL. Pass: qpos ≤ STEP_TOL and equal contact sets at all 200.
(b) **trajectory**: 100 steps from the start, lagrange alone (`eval --step 100`), qpos against
    MuJoCo's at step 100, ≤ TRAJ_TOL. MuJoCo's own sensitivity: the same run with qvel moved by
    1e-12 (every entry), max |Δ qpos| at step 100; below SENSITIVE the scene is
    "sensitivity-allowed" and (b) applies, otherwise the error is reported with it.
(c) **benchmark** (report only, in validation/bench.md): the scene as shipped (its own solver
    options): MuJoCo's mjTIMER_STEP and mjTIMER_POS_COLLISION per step over 200 mj_step from the
    start (the best of 3 runs, C clock); lagrange's own 200 steps from the start (`eval --step
    200`: µs per step, the best of 3 runs) and its collision pass alone at MuJoCo's 200 states
    (`collide_us`, the median over the states: a shared machine's preemptions inflate a mean);
    BENCH_ROUNDS rounds alternating the engines, each figure its best over them.

Exit status 0 whatever the figures (the collision work of issue 25 is in progress: the table is
the deliverable); 1 when a scene fails to load or lagrange fails (crash, error exit).

    validation/crossval_scenes [--lagrange BIN] [--only NAME] [--no-report] [--no-bench]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent / "scenes"))

from compose import scenes  # noqa: E402
from crossval_common import lagrange_eval_json, menagerie, tight_copy  # noqa: E402
from crossval_corpus import REPO, site_packages  # noqa: E402

STEPS_A = 200
STEPS_B = 100
STEP_TOL = 1e-9
POS_TOL = 1e-9
TRAJ_TOL = 1e-6
PERTURB = 1e-12
SENSITIVE = 1e-8
BENCH_STEPS = 200
# Timing rounds per scene, MuJoCo and lagrange alternating (`bench`).
BENCH_ROUNDS = 5
SECTION = "## Contact scenes"
BENCH_SECTION = "## Contact scenes: step and collision time beside MuJoCo"


def start_state(mj, m, d, keyframe):
    if keyframe is not None and m.nkey > keyframe:
        mj.mj_resetDataKeyframe(m, d, keyframe)
    else:
        mj.mj_resetData(m, d)


def state_of(d) -> dict:
    s = {"q": d.qpos.tolist(), "v": d.qvel.tolist(), "time": float(d.time),
         "qacc_warmstart": d.qacc_warmstart.tolist()}
    if d.ctrl.size:
        s["ctrl"] = d.ctrl.tolist()
    if d.act.size:
        s["act"] = d.act.tolist()
    return s


def mj_contacts(d) -> list[tuple[tuple[int, int], np.ndarray]]:
    return [(tuple(sorted((int(c.geom1), int(c.geom2)))), np.array(c.pos)) for c in d.contact[:d.ncon]]


def lg_contacts(result) -> list[tuple[tuple[int, int], np.ndarray]]:
    return [(tuple(sorted(c["geom_ids"])), np.array(c["pos"])) for c in result["contacts"]]


def match(a, b) -> tuple[bool, float, str]:
    """Whether two contact sets (MuJoCo's `a`, lagrange's `b`) have the same count and geom pairs,
    the largest distance of a contact to its nearest same-pair partner (greedy, closest first;
    inf when unmatched), and how they differ in words."""
    if len(a) != len(b):
        return False, math.inf, f"MuJoCo {len(a)} contacts, lagrange {len(b)}"
    groups: dict = {}
    for pair, p in a:
        groups.setdefault(pair, ([], []))[0].append(p)
    for pair, p in b:
        groups.setdefault(pair, ([], []))[1].append(p)
    worst = 0.0
    for pa, pb in groups.values():
        if len(pa) != len(pb):
            return False, math.inf, f"geoms {pair}: MuJoCo {len(pa)} contacts, lagrange {len(pb)}"
        left = list(range(len(pb)))
        for p in pa:
            k = min(left, key=lambda j: float(np.linalg.norm(p - pb[j])))
            worst = max(worst, float(np.linalg.norm(p - pb[k])))
            left.remove(k)
    return True, worst, f"positions {worst:.1e} m apart"


def qpos_err(mj, m, qa, qb) -> float:
    if m.nv == 0:
        return 0.0
    dq = np.zeros(m.nv)
    mj.mj_differentiatePos(m, dq, 1.0, np.asarray(qa, float), np.asarray(qb, float))
    return float(np.max(np.abs(dq)))


def not_simulated(binary: Path, path: Path) -> str:
    """What lagrange parses but does not simulate in the scene (`info --json` elements), by kind:
    a scene with such elements moves differently for that reason, not its contacts."""
    p = subprocess.run([str(binary), "info", str(path), "--json"], capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        raise RuntimeError("lagrange info failed: " + (p.stderr or p.stdout)[:300])
    counts: dict[str, int] = {}
    for e in json.loads(p.stdout)["elements"]:
        if e["status"] == "parsed, not simulated":
            key = f"{e['category']} {e['kind']}"
            counts[key] = counts.get(key, 0) + 1
    return ", ".join(f"{k} ×{n}" for k, n in sorted(counts.items()))


def stepwise(mj, m, binary: Path, path: Path, keyframe) -> dict:
    d = mj.MjData(m)
    start_state(mj, m, d, keyframe)
    states, after, contacts = [], [], []
    for _ in range(STEPS_A):
        states.append(state_of(d))
        mj.mj_step(m, d)
        after.append(d.qpos.copy())
        contacts.append(mj_contacts(d))
    res = lagrange_eval_json(binary, path, states, ["--step", "1"])["results"]
    errs, equal, pos, ncon = [], 0, 0.0, 0
    first_diff = None
    for k, (r, q, c) in enumerate(zip(res, after, contacts)):
        errs.append(qpos_err(mj, m, q, r["qpos"]))
        same, w, why = match(c, lg_contacts(r))
        ncon = max(ncon, len(c))
        if same and w <= POS_TOL:
            equal += 1
        elif first_diff is None:
            first_diff = (k, why)
        if same:
            pos = max(pos, w)
    return {"qpos": max(errs), "qpos_median": float(np.median(errs)), "equal": equal, "pos": pos, "ncon": ncon,
            "first_diff": first_diff, "states": states}


def trajectory(mj, m, binary: Path, path: Path, keyframe) -> dict:
    d = mj.MjData(m)
    start_state(mj, m, d, keyframe)
    s0 = state_of(d)
    v0 = d.qvel.copy()
    for _ in range(STEPS_B):
        mj.mj_step(m, d)
    q_ref = d.qpos.copy()
    start_state(mj, m, d, keyframe)
    d.qvel[:] = v0 + PERTURB
    for _ in range(STEPS_B):
        mj.mj_step(m, d)
    sens = qpos_err(mj, m, q_ref, d.qpos)
    r = lagrange_eval_json(binary, path, [s0], ["--step", str(STEPS_B)])["results"][0]
    return {"err": qpos_err(mj, m, q_ref, r["qpos"]), "sens": sens}


def bench(mj, binary: Path, path: Path, keyframe, clock) -> dict:
    """The scene as shipped: MuJoCo's timers over BENCH_STEPS steps (best of 3 runs), lagrange's
    own run of as many steps and its collision pass at MuJoCo's states."""
    m = mj.MjModel.from_xml_path(str(path))
    d = mj.MjData(m)
    best = {"step": math.inf, "collision": math.inf}
    states = []
    start_state(mj, m, d, keyframe)
    for _ in range(BENCH_STEPS):
        states.append(state_of(d))
        mj.mj_step(m, d)
    lg_step, lg_collision = math.inf, math.inf
    # BENCH_ROUNDS rounds alternating the engines (a shared machine's speed drifts from one
    # second to the next), each the best of 3 runs from the start; the best over the rounds.
    for _ in range(BENCH_ROUNDS):
        for _ in range(3):
            start_state(mj, m, d, keyframe)
            mj.mj_step(m, d, nstep=BENCH_STEPS)
            for key, timer in (("step", "mjTIMER_STEP"), ("collision", "mjTIMER_POS_COLLISION")):
                t = d.timer[int(getattr(mj.mjtTimer, timer))]
                best[key] = min(best[key], t.duration / t.number if t.number else math.nan)
        own = lagrange_eval_json(binary, path, [states[0]] * 3, ["--step", str(BENCH_STEPS)])["results"]
        at = lagrange_eval_json(binary, path, states, ["--step", "1"])["results"]
        lg_step = min(lg_step, min(r["step_us"] for r in own))
        lg_collision = min(lg_collision, float(np.median([r["collide_us"] for r in at])))
    return {"mj_step": best["step"], "mj_collision": best["collision"], "lg_step": lg_step,
            "lg_collision": lg_collision, "ngeom": m.ngeom}


def replace_section(report: Path, section: str, text: str) -> None:
    old = report.read_text() if report.exists() else ""
    ls = old.splitlines()
    start = next((i for i, l in enumerate(ls) if l.strip() == section), None)
    if start is None:
        new = old.rstrip("\n") + "\n\n" + text
    else:
        end = next((i for i in range(start + 1, len(ls)) if ls[i].startswith("## ")), len(ls))
        new = "\n".join(ls[:start] + text.rstrip("\n").splitlines() + ([""] + ls[end:] if end < len(ls) else [])) + "\n"
    report.write_text(new)


def fmt(x: float) -> str:
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else ("inf" if x == math.inf else f"{x:.1e}")


def main() -> int:
    import mujoco as mj

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lagrange", default=str(REPO / "target/release/lagrange"))
    ap.add_argument("--only", help="scenes whose name contains this")
    ap.add_argument("--no-report", action="store_true", help="do not write validation/report.md, bench.md")
    ap.add_argument("--no-bench", action="store_true", help="skip the timing (c)")
    ap.add_argument("--cache", default=str(REPO / "target/scenes"), help="where composed scenes are written")
    args = ap.parse_args()
    binary = Path(args.lagrange)
    t0 = time.time()
    from crossval_sensors import timer_callback

    clock = None if args.no_bench else timer_callback()
    all_scenes = scenes(mj, menagerie(), site_packages(), Path(args.cache))
    if args.only:
        all_scenes = [s for s in all_scenes if args.only in s.name]
    print(f"contact scenes against MuJoCo {mj.__version__}: (a) one lagrange step from MuJoCo's state at each of "
          f"{STEPS_A} mj_step, qpos ≤ {STEP_TOL:g} and equal contact sets (pairs, positions ≤ {POS_TOL:g} m); "
          f"(b) {STEPS_B} steps ≤ {TRAJ_TOL:g} where MuJoCo's sensitivity (qvel + {PERTURB:g}) < {SENSITIVE:g}")
    head = (f"{'scene':<20} {'nv':>3} {'ncon':>4} {'(a) qpos':>9} {'contacts=':>9} {'pos':>8} {'a':>4} "
            f"{'(b) qpos':>9} {'sens':>8} {'b':>9}")
    print(head)
    rows, crashed = [], 0
    if clock is not None:
        mj.set_mjcb_time(clock)
    try:
        for s in all_scenes:
            copy = None
            try:
                copy = tight_copy(s.path)
                m = mj.MjModel.from_xml_path(str(copy))
                a = stepwise(mj, m, binary, copy, s.keyframe)
                b = trajectory(mj, m, binary, copy, s.keyframe)
                c = None if args.no_bench else bench(mj, binary, s.path, s.keyframe, clock)
                unsimulated = not_simulated(binary, s.path)
            except (RuntimeError, ValueError, KeyError, subprocess.SubprocessError) as e:
                crashed += 1
                print(f"{s.name:<20} ERROR {str(e)[:300]}")
                rows.append({"scene": s, "error": str(e)[:300]})
                continue
            finally:
                if copy is not None and copy.exists():
                    copy.unlink()
            pass_a = a["qpos"] <= STEP_TOL and a["equal"] == STEPS_A
            allowed = b["sens"] < SENSITIVE
            pass_b = b["err"] <= TRAJ_TOL
            verdict_b = ("ok" if pass_b else "FAIL") if allowed else ("(ok)" if pass_b else "sensitive")
            print(f"{s.name:<20} {m.nv:>3} {a['ncon']:>4} {a['qpos']:9.1e} {a['equal']:>5}/{STEPS_A} {fmt(a['pos']):>8} "
                  f"{'ok' if pass_a else 'FAIL':>4} {b['err']:9.1e} {b['sens']:8.1e} {verdict_b:>9}"
                  + (f"  first differing contact set: step {a['first_diff'][0]} ({a['first_diff'][1]})"
                     if a["first_diff"] else "")
                  + (f"  not simulated: {unsimulated}" if unsimulated else ""))
            rows.append({"scene": s, "nv": m.nv, "a": a, "b": b, "c": c, "pass_a": pass_a, "pass_b": pass_b,
                         "allowed": allowed, "unsimulated": unsimulated})
    finally:
        if clock is not None:
            mj.set_mjcb_time(None)
    ok = [r for r in rows if "error" not in r]
    n_a = sum(r["pass_a"] for r in ok)
    n_allowed = sum(r["allowed"] for r in ok)
    n_b = sum(r["pass_b"] and r["allowed"] for r in ok)
    seconds = time.time() - t0
    print(f"scenes: {len(rows)}; (a) stepwise {n_a} pass; (b) trajectory {n_b} of {n_allowed} sensitivity-allowed "
          f"pass; {crashed} errors ({seconds:.0f} s)")
    if not args.no_bench:
        print_bench(ok)
    if not args.no_report:
        write_report(rows, seconds, mj.__version__, n_a, n_b, n_allowed)
        if not args.no_bench:
            write_bench(ok, mj.__version__, clock is not None)
    return 1 if crashed else 0


def print_bench(rows) -> None:
    print(f"\ntiming, the scenes as shipped (µs per step; MuJoCo: mjTIMER_STEP / mjTIMER_POS_COLLISION, best of 3 "
          f"runs of {BENCH_STEPS} steps; lagrange: best of 3 runs of its own {BENCH_STEPS} steps, its collision "
          f"pass at MuJoCo's states)")
    print(f"{'scene':<20} {'mj_step':>9} {'lagrange':>9} {'ratio':>6} | {'mj coll':>9} {'lagrange':>9} {'ratio':>6}")
    for r in rows:
        c = r["c"]
        print(f"{r['scene'].name:<20} {c['mj_step']:9.1f} {c['lg_step']:9.1f} {c['lg_step'] / c['mj_step']:6.2f} | "
              f"{c['mj_collision']:9.2f} {c['lg_collision']:9.2f} {ratio(c['lg_collision'], c['mj_collision']):>6}")


def ratio(a: float, b: float) -> str:
    return f"{a / b:.2f}" if b > 0 else "—"


def commit() -> str:
    sha = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True).stdout.strip()
    # The two files this script writes do not count as changes.
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", ".", ":!validation/report.md",
                            ":!validation/bench.md"], cwd=REPO, capture_output=True, text=True).stdout.strip()
    return sha + (" + uncommitted changes" if dirty else "")


def write_report(rows, seconds, version, n_a, n_b, n_allowed) -> None:
    lines = [SECTION, "",
             f"`validation/crossval_scenes` (lagrange {commit()}, MuJoCo {version}, {seconds:.0f} s): {len(rows)} contact "
             f"scenes (validation/scenes/compose.py), each with a tight solver (Newton to round-off), its own "
             f"integrator, timestep and cone, from its keyframe with its controls. (a) one `lagrange eval --step 1` "
             f"from MuJoCo's state before each of {STEPS_A} `mj_step`: max |Δqpos| on the manifold (pass ≤ "
             f"{STEP_TOL:g}) and the states whose contact set equals MuJoCo's (count, geom pairs, positions ≤ "
             f"{POS_TOL:g} m; pos: the worst matched distance where pairs and counts agree); (b) {STEPS_B} steps of "
             f"lagrange alone against MuJoCo's, pass ≤ {TRAJ_TOL:g} where MuJoCo's own step-{STEPS_B} state moves "
             f"less than {SENSITIVE:g} when qvel is moved by {PERTURB:g} (sens); \"sensitive\" scenes are reported, not "
             f"judged. Report only for now (issue 25's collision work is in progress).", "",
             f"**(a) stepwise: {n_a} of {len(rows)} scenes pass; (b) trajectory: {n_b} of {n_allowed} "
             f"sensitivity-allowed scenes pass.**", "",
             "| scene | kind | what | nv | max contacts | (a) qpos | contact sets equal | pos | (a) | (b) qpos | sens | (b) "
             "| first differing contact set | lagrange: not simulated |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        s = r["scene"]
        if "error" in r:
            lines.append(f"| {s.name} | {s.kind} | {s.what} | | | | | | ERROR: {r['error']} | | | | | |")
            continue
        a, b = r["a"], r["b"]
        vb = ("ok" if r["pass_b"] else "FAIL") if r["allowed"] else ("(ok)" if r["pass_b"] else "sensitive")
        lines.append(f"| {s.name} | {s.kind} | {s.what} | {r['nv']} | {a['ncon']} | {fmt(a['qpos'])} | "
                     f"{a['equal']}/{STEPS_A} | {fmt(a['pos'])} | {'ok' if r['pass_a'] else 'FAIL'} | {fmt(b['err'])} | "
                     f"{fmt(b['sens'])} | {vb} | "
                     + (f"step {a['first_diff'][0]}: {a['first_diff'][1]}" if a["first_diff"] else "")
                     + f" | {r['unsimulated']} |")
    replace_section(REPO / "validation" / "report.md", SECTION, "\n".join(lines) + "\n")
    print("wrote the Contact scenes section of validation/report.md")


def write_bench(rows, version, timers: bool) -> None:
    if not rows:
        return
    step_ratios = [r["c"]["lg_step"] / r["c"]["mj_step"] for r in rows]
    lines = [BENCH_SECTION, "",
             f"Written by `validation/crossval_scenes` on {time.strftime('%Y-%m-%d', time.gmtime())} (UTC), lagrange "
             f"{commit()}, MuJoCo {version}, {platform.machine()}, not pinned, machine load not controlled (load average "
             f"{' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} CPUs when written: with more "
             f"runnable processes than CPUs, figures move by 2× from run to run). Report only. "
             f"The scenes of the Contact scenes section of validation/report.md as shipped (their own solver options), "
             f"from their keyframes. MuJoCo: `mjTIMER_STEP` and `mjTIMER_POS_COLLISION` per step over {BENCH_STEPS} "
             f"`mj_step` (a C clock as `mjcb_time`), the best of 3 runs in each of {BENCH_ROUNDS} rounds that alternate "
             f"the engines. lagrange, in the same script run: the mean µs per "
             f"step of its own {BENCH_STEPS} steps from the same start (`eval --step {BENCH_STEPS}`, the best of 3 "
             f"runs), and its collision "
             f"pass alone (broad and narrow phase, body poses untimed) at MuJoCo's {BENCH_STEPS} states, the median. "
             f"Ratios: lagrange / MuJoCo (below 1: lagrange is faster). Issue 25 asks the collision pass ≤ 1× on "
             f"each scene and the step ≤ 1× on the median, ≤ 2× on each.", "",
             f"Step ratio: median {np.median(step_ratios):.2f}, worst {max(step_ratios):.2f}; step ≤ 2× on "
             f"{sum(x <= 2 for x in step_ratios)} of {len(rows)} scenes; collision pass ≤ 1× on "
             f"{sum(r['c']['lg_collision'] <= r['c']['mj_collision'] for r in rows)} of {len(rows)}.", "",
             "| scene | geoms | mj_step µs | lagrange step µs | step ratio | MuJoCo collision µs | lagrange collision µs "
             "| collision ratio |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        c = r["c"]
        lines.append(f"| {r['scene'].name} | {c['ngeom']} | {c['mj_step']:.1f} | {c['lg_step']:.1f} | "
                     f"{c['lg_step'] / c['mj_step']:.2f} | {c['mj_collision']:.2f} | {c['lg_collision']:.2f} | "
                     f"{ratio(c['lg_collision'], c['mj_collision'])} |")
    if not timers:
        lines += ["", "(no C compiler for MuJoCo's timer clock: MuJoCo's figures are not measured)"]
    replace_section(REPO / "validation" / "bench.md", BENCH_SECTION, "\n".join(lines) + "\n")
    print("wrote the contact-scene section of validation/bench.md")


if __name__ == "__main__":
    sys.exit(main())
