"""Contact-rich scenes beside `mj_step`: per-step time of lagrange's soft and
exact modes against MuJoCo 4.0 in the same run, and the growth of the step time with the number
of objects in a bin (time ∝ Nᵏ, fitted for both engines), and the quality of each mode after
`--settle` seconds: penetration, energy rise, unconverged solves, the rest state against MuJoCo's
(soft) and the closed form (exact stacks). Report only: writes the section
"## Contact-rich scenes: soft and exact step beside mj_step" of validation/bench.md. `.ci/run`
runs `--quick` (under a minute); the large bins take minutes:

    validation/.venv/bin/python validation/bench_contact_rich.py [--quick] [--binary target/release/lagrange]

Scenes (generated here, deterministic): box stacks of 5/10/20 on a floor, a heavy box on a light
one at mass ratios 10/100/1000, bins of N = 10/50/100/200/400 mixed primitives (spheres, capsules,
boxes) dropped into a walled bin, a 30-link capsule chain falling onto the floor, a parallel
gripper holding a box (validation/scenes/gripper_box.xml, keyframe `hold`); and the shipped go1 and
dm_control humanoid (a ragdoll: its motors at zero control) scenes. Every scene: Euler, 2 ms, Newton (MuJoCo's defaults), pyramidal
cones, from rest. MuJoCo: `mjTIMER_STEP` per step (a C clock as `mjcb_time`), the best of 3 runs.
lagrange: `eval --step S` from the same start, `step_us` (the best of 3 in one process), in soft
and in exact mode; the two engines alternate over ROUNDS rounds and each figure is its best (`--constraints exact`); a run that fails (divergence, NaN) is reported with its
message. `--quick` keeps the bins of 10 and 50 only. `--soft-only-above N` leaves out the exact
mode (timing and quality) on the bins of more than N primitives — its second of settling there takes
many minutes per bin — and reports it as not run, with the reason, in the tables; its growth
exponent is then fitted over the bins it ran on.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))
from crossval_common import lagrange_eval_json  # noqa: E402
from crossval_scenes import commit, replace_section  # noqa: E402

SECTION = "## Contact-rich scenes: soft and exact step beside mj_step"
OPTION = '<option timestep="0.002" integrator="Euler" solver="Newton" cone="pyramidal"/>'
FLOOR = '<geom name="floor" type="plane" size="0 0 1"/>'
# Timing rounds per scene, MuJoCo and lagrange alternating (see `main`).
ROUNDS = 3
# An exact step slower than this (µs) is timed by one run of one round (a 400-sphere bin: about
# 0.2 s per step, 40 s per run).
SLOW_STEP_US = 20_000.0


def stack(n: int) -> str:
    bodies = "".join(
        f'<body pos="0 0 {0.05 + 0.1 * k + 1e-4 * k:.6f}"><freejoint/>'
        f'<geom type="box" size="0.05 0.05 0.05" mass="1"/></body>' for k in range(n))
    return f"<mujoco>{OPTION}<worldbody>{FLOOR}{bodies}</worldbody></mujoco>"


def mass_ratio(r: float) -> str:
    return (f"<mujoco>{OPTION}<worldbody>{FLOOR}"
            '<body pos="0 0 0.05"><freejoint/><geom type="box" size="0.05 0.05 0.05" mass="1"/></body>'
            f'<body pos="0 0 0.1501"><freejoint/><geom type="box" size="0.1 0.1 0.05" mass="{r}"/></body>'
            "</worldbody></mujoco>")


def bin_scene(n: int) -> str:
    """N primitives on a grid above a walled bin whose floor area grows with N (a pile ~3 deep)."""
    rng = np.random.default_rng(26 + n)
    side = max(2, math.ceil(math.sqrt(n / 3)))
    half = 0.06 * side
    walls = "".join(
        f'<geom type="box" pos="{x} {y} 0.3" size="{sx} {sy} 0.3"/>'
        for x, y, sx, sy in ((half + 0.01, 0, 0.01, half), (-half - 0.01, 0, 0.01, half),
                             (0, half + 0.01, half, 0.01), (0, -half - 0.01, half, 0.01)))
    bodies = []
    for k in range(n):
        i, j, layer = k % side, (k // side) % side, k // (side * side)
        x = -half + 0.06 + 0.12 * i + rng.uniform(-0.01, 0.01)
        y = -half + 0.06 + 0.12 * j + rng.uniform(-0.01, 0.01)
        z = 0.06 + 0.12 * layer
        kind = k % 3
        geom = ('<geom type="sphere" size="0.04"/>', '<geom type="capsule" size="0.025 0.03"/>',
                '<geom type="box" size="0.035 0.035 0.035"/>')[kind]
        bodies.append(f'<body pos="{x:.6f} {y:.6f} {z:.6f}" euler="{rng.uniform(0, 90):.3f} 0 0">'
                      f"<freejoint/>{geom}</body>")
    return f"<mujoco>{OPTION}<worldbody>{FLOOR}{walls}{''.join(bodies)}</worldbody></mujoco>"


def chain(n: int = 30) -> str:
    """A capsule chain of n links on ball joints, its free root 0.3 m above the floor, lying
    horizontally: it falls and drapes."""
    inner = ""
    for _ in range(n - 1):
        inner = f'<body pos="0.1 0 0"><joint type="ball"/><geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.02"/>{inner}</body>'
    return (f"<mujoco>{OPTION}<worldbody>{FLOOR}<body pos=\"0 0 0.3\"><freejoint/>"
            f'<geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.02"/>{inner}</body></worldbody></mujoco>')


def scenes(quick: bool) -> list[tuple[str, str, object, int]]:
    """(name, group, MJCF text or a path, steps)."""
    out: list[tuple[str, str, object, int]] = []
    for n in (5, 10, 20):
        out.append((f"stack_{n}", "stack", stack(n), 200))
    for r in (10, 100, 1000):
        out.append((f"ratio_{r}", "ratio", mass_ratio(r), 200))
    for n in (10, 50) if quick else (10, 50, 100, 200, 400):
        # Every bin over the same 200 steps (the fall and the landing): the fitted exponent then
        # compares like with like (the large bins' first 10 or 40 steps, free fall only, had
        # made it near zero for both engines).
        out.append((f"bin_{n}", "bin", bin_scene(n), 200))
    out.append(("chain_30", "chain", chain(30), 200))
    out.append(("gripper_box", "gripper", HERE / "scenes/gripper_box.xml", 200))
    out.append(("humanoid", "robot", REPO / "models/mjcf/humanoid/humanoid.xml", 200))
    out.append(("go1", "robot", REPO / "models/mjcf/unitree_go1/scene.xml", 200))
    return out


# Scenes that start from a keyframe (with its controls) instead of qpos0 at rest.
KEYFRAME = {"gripper_box": "hold"}
# Scenes with a closed-form rest state: (free body index, centre height) per body.
def closed_form(name: str) -> list[tuple[int, float]] | None:
    kind, _, arg = name.partition("_")
    if kind == "stack":
        return [(k, 0.05 + 0.1 * k) for k in range(int(arg))]
    if kind == "ratio":
        return [(0, 0.05), (1, 0.15)]
    return None


def mujoco_step_us(mj, path: Path, steps: int) -> float:
    m = mj.MjModel.from_xml_path(str(path))
    d = mj.MjData(m)
    best = math.inf
    for _ in range(3):
        mj.mj_resetData(m, d)
        mj.mj_step(m, d, nstep=steps)
        t = d.timer[int(mj.mjtTimer.mjTIMER_STEP)]
        best = min(best, t.duration / t.number)
    return best


def lagrange_step_us(binary: Path, path: Path, q0: list[float], steps: int, mode: str,
                     runs: int = 3) -> tuple[float, str]:
    """The best of `runs` runs of `steps` steps in `mode` (µs per step), or NaN and the failure."""
    try:
        out = lagrange_eval_json(binary, path, [{"q": q0}] * runs,
                                 ["--step", str(steps), "--constraints", mode], timeout=900, state_errors=True)
    except (RuntimeError, Exception) as e:  # a timeout or a refusal: reported, never hidden
        return math.nan, str(e).splitlines()[0][:120]
    good = [r for r in out["results"] if "step_us" in r]
    if not good:
        return math.nan, str(out["results"][0].get("error", "failed"))[:120]
    finite = all(all(math.isfinite(x) for x in r["qpos"]) for r in good)
    return min(r["step_us"] for r in good), "" if finite else "non-finite state"


def lagrange_quality(binary: Path, path: Path, mode: str, duration: float, keyframe: str | None) -> dict:
    """`lagrange simulate` for `duration` s in `mode`: its JSON summary (final q, max penetration,
    unconverged solves, warnings) and, from the per-step CSV, the largest rise of the total energy
    above its initial value; {"error": ...} when the run fails."""
    with tempfile.TemporaryDirectory() as tmp:
        csv_path = Path(tmp) / "run.csv"
        cmd = [str(binary), "simulate", str(path), "--duration", f"{duration}", "--constraints", mode, "--json",
               "--out", str(csv_path)]
        if keyframe:
            cmd += ["--keyframe", keyframe]
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        except subprocess.TimeoutExpired:
            return {"error": "no result within 600 s"}
        if p.returncode != 0:
            return {"error": (p.stderr or p.stdout).strip().splitlines()[-1][:160] if (p.stderr or p.stdout) else
                    f"exit {p.returncode}"}
        out = json.loads(p.stdout)
        energy = np.genfromtxt(csv_path, delimiter=",", names=True, usecols=("energy",))["energy"]
    finite = all(math.isfinite(x) for x in out["q"]) and bool(np.all(np.isfinite(energy)))
    return {"q": out["q"], "penetration": out["max_penetration"], "unconverged": out["solver"]["unconverged"],
            "energy0": float(energy[0]), "rise": float(np.max(energy - energy[0])), "finite": finite,
            "steps": out["steps"], "dropped": int(out.get("contacts_dropped", 0))}


def mujoco_final(mj, path: Path, steps: int, keyframe: str | None):
    """MuJoCo's model and data after `steps` mj_step from the scene's start, its body poses at the
    final qpos: mj_step forms `xpos` before it integrates, so after it they are the poses of the
    step before (a body moving at 1 m/s sits 2 mm from them)."""
    m = mj.MjModel.from_xml_path(str(path))
    d = mj.MjData(m)
    if keyframe:
        mj.mj_resetDataKeyframe(m, d, mj.mj_name2id(m, mj.mjtObj.mjOBJ_KEY, keyframe))
    mj.mj_step(m, d, nstep=steps)
    mj.mj_kinematics(m, d)
    return m, d


def body_gap(mj, m, d_ref, q) -> float:
    """The largest distance (m) between a body's position at lagrange's `q` and in MuJoCo's data."""
    d = mj.MjData(m)
    d.qpos[:] = q
    mj.mj_kinematics(m, d)
    return float(np.max(np.linalg.norm(d.xpos[1:] - d_ref.xpos[1:], axis=1))) if m.nbody > 1 else 0.0


def closed_form_gap(name: str, q) -> float:
    """The largest distance (m) of a stacked box's centre height from its closed form."""
    bodies = closed_form(name)
    return max(abs(q[7 * k + 2] - z) for k, z in bodies) if bodies else math.nan


def fit_exponent(ns: list[int], ts: list[float]) -> float:
    pts = [(math.log(n), math.log(t)) for n, t in zip(ns, ts) if math.isfinite(t) and t > 0]
    if len(pts) < 2:
        return math.nan
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--binary", type=Path, default=REPO / "target/release/lagrange")
    ap.add_argument("--quick", action="store_true", help="the small scenes only")
    ap.add_argument("--no-write", action="store_true", help="print, do not write validation/bench.md")
    ap.add_argument("--soft-only-above", type=int, default=None, metavar="N",
                    help="bins of more than N primitives: soft mode only, exact reported as not run")
    ap.add_argument("--settle", type=float, default=1.0,
                    help="seconds simulated from the start for the rest state, energy and penetration (default 1)")
    args = ap.parse_args()
    import mujoco as mj

    # MuJoCo's timers call mjcb_time directly: a C clock (µs), never a Python callable, whose
    # own call cost (≈ 5 µs per humanoid step) would be counted in MuJoCo's step time.
    from crossval_sensors import timer_callback

    clock = timer_callback()
    if clock is None:
        sys.exit("bench_contact_rich: no C compiler for the clock MuJoCo's timers call (cc)")
    mj.set_mjcb_time(clock)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, group, scene, steps in scenes(args.quick):
            path = scene if isinstance(scene, Path) else Path(tmp) / f"{name}.xml"
            if not isinstance(scene, Path):
                path.write_text(scene)
            m = mj.MjModel.from_xml_path(str(path))
            q0 = [float(x) for x in m.qpos0]
            # Interleaved rounds (MuJoCo, soft, exact; each the best of its 3 runs), the best over
            # the rounds: a shared machine's speed drifts by tens of percent from one second to
            # the next, and alternating keeps a slow spell from landing on one engine only.
            mj_us, soft, exact, soft_err, exact_err = math.inf, math.inf, math.inf, "", ""
            skip_exact = (group == "bin" and args.soft_only_above is not None
                          and int(name.split("_")[1]) > args.soft_only_above)
            for _ in range(ROUNDS):
                mj_us = min(mj_us, mujoco_step_us(mj, path, steps))
                s, soft_err = lagrange_step_us(args.binary, path, q0, steps, "soft")
                if skip_exact:
                    e, exact_err = math.nan, ""
                elif SLOW_STEP_US < exact < math.inf:
                    # Timed once already: at hundreds of times MuJoCo's step a few per cent of
                    # timing noise change nothing, and each further run takes minutes.
                    e = exact
                else:
                    # The first round probes with one run; a scene slower than SLOW_STEP_US
                    # keeps that figure, the others get their 3 runs per round.
                    e, exact_err = lagrange_step_us(args.binary, path, q0, steps, "exact",
                                                    runs=1 if math.isinf(exact) else 3)
                    if math.isinf(exact) and not exact_err and e <= SLOW_STEP_US:
                        e3, exact_err = lagrange_step_us(args.binary, path, q0, steps, "exact")
                        e = min(e, e3)
                soft, exact = min(soft, s), min(exact, e)
                if soft_err or exact_err or not (math.isfinite(s) and (skip_exact or math.isfinite(e))):
                    break
            if skip_exact:
                exact_err = f"not run (--soft-only-above {args.soft_only_above}: exact mode's settling takes minutes here)"
            soft = soft if math.isfinite(soft) else math.nan
            exact = exact if math.isfinite(exact) else math.nan
            rows.append(dict(name=name, group=group, nv=m.nv, ngeom=m.ngeom, steps=steps, mj=mj_us, soft=soft,
                             exact=exact, soft_err=soft_err, exact_err=exact_err))
            r = rows[-1]
            print(f"{name:10s} nv {m.nv:5d}  mj_step {mj_us:10.1f} µs  soft {soft:12.1f} µs ({soft / mj_us:7.2f}×) "
                  f"exact {exact:12.1f} µs ({exact / mj_us:7.2f}×) {soft_err} {exact_err}", flush=True)
            key = KEYFRAME.get(name)
            settle_steps = round(args.settle / m.opt.timestep)
            m_ref, d_ref = mujoco_final(mj, path, settle_steps, key)
            # Passive: no actuator, or only motors (no bias) left at zero control from qpos0.
            r["passive"] = key is None and bool(np.all(m.actuator_biastype == 0)) and not np.any(m.actuator_gainprm[:, 0] != 1)
            for mode in ("soft", "exact"):
                if mode == "exact" and skip_exact:
                    r["exact_quality"] = {"error": exact_err}
                    print(f"    exact: {exact_err}", flush=True)
                    continue
                qual = lagrange_quality(args.binary, path, mode, args.settle, key)
                if "q" in qual:
                    qual["vs_mujoco"] = body_gap(mj, m_ref, d_ref, qual["q"]) if qual["finite"] else math.nan
                    qual["vs_closed"] = closed_form_gap(name, qual["q"]) if qual["finite"] else math.nan
                r[f"{mode}_quality"] = qual
                print(f"    {mode}: {quality_cells(qual)}", flush=True)
    text = report(rows, args.settle)
    print(text)
    if not args.no_write:
        replace_section(HERE / "bench.md", SECTION, text)
    return 0


def ratio(a: float, b: float) -> str:
    return f"{a / b:.2f}" if math.isfinite(a) and math.isfinite(b) and b > 0 else "—"


def report(rows, settle: float) -> str:
    import mujoco as mj

    bins = [r for r in rows if r["group"] == "bin"]
    ns = [int(r["name"].split("_")[1]) for r in bins]
    k = {key: fit_exponent(ns, [r[key] for r in bins]) for key in ("mj", "soft", "exact")}
    # The exact mode's exponent over the bins it ran on (`--soft-only-above`), said so.
    ns_exact = [n for n, r in zip(ns, bins) if math.isfinite(r["exact"])]
    exact_over = "" if ns_exact == ns else f" (over N = {', '.join(map(str, ns_exact))} only)"
    med = {key: float(np.nanmedian([r[key] / r["mj"] for r in rows if r["group"] != "robot"])) for key in ("soft", "exact")}
    lines = [
        SECTION, "",
        f"Written by `validation/bench_contact_rich.py` on {time.strftime('%Y-%m-%d', time.gmtime())} (UTC), lagrange "
        f"{commit()}, MuJoCo {mj.__version__}, {platform.machine()}, load average "
        f"{' '.join(f'{x:.2f}' for x in __import__('os').getloadavg())} on {__import__('os').cpu_count()} CPUs "
        "(not pinned: with more runnable processes than CPUs figures move by 2×). Report only. Each scene "
        "from rest, Euler 2 ms, Newton, pyramidal cones; per-step µs over the steps shown, the best of 3 runs in "
        f"each of {ROUNDS} rounds alternating the engines (an exact step over {SLOW_STEP_US / 1e3:g} ms: one run), MuJoCo's `mjTIMER_STEP` (a C clock) against lagrange's "
        "`eval --step` in soft and exact mode. Ratios: lagrange / MuJoCo.",
        "",
        f"Median ratio of the contact-rich scenes (robots excluded): soft {med['soft']:.2f}, exact {med['exact']:.2f}. "
        f"Bins, time ∝ Nᵏ fitted over N = {', '.join(map(str, ns))}: MuJoCo k = {k['mj']:.2f}, lagrange soft "
        f"k = {k['soft']:.2f}, exact k = {k['exact']:.2f}{exact_over} (the goal: soft ≤ MuJoCo's + 0.1).",
        "",
        "| scene | nv | geoms | steps | mj_step µs | soft µs | soft ratio | exact µs | exact ratio | failures |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        fail = "; ".join(f"{m}: {e}" for m, e in (("soft", r["soft_err"]), ("exact", r["exact_err"])) if e)
        lines.append(f"| {r['name']} | {r['nv']} | {r['ngeom']} | {r['steps']} | {r['mj']:.1f} | {r['soft']:.1f} | "
                     f"{ratio(r['soft'], r['mj'])} | {r['exact']:.1f} | {ratio(r['exact'], r['mj'])} | {fail} |")
    lines += [
        "",
        f"Quality, each scene simulated {settle:g} s from its start in both modes (`lagrange simulate --json --out`): "
        "the deepest penetration, the largest rise of the total energy above its initial value (J; on passive "
        "scenes, marked *, it must stay within the solver's tolerance), the unconverged solves, and the rest state: "
        "the largest distance of a body from its place in MuJoCo's run of as many steps (soft; MuJoCo's body "
        "poses at its final qpos; the goal: 1 mm) and, for the stacks and mass ratios, of a box centre from its "
        "closed-form height (exact).",
        "",
        "| scene | soft: penetration mm | soft: energy rise J | soft: unconverged | soft: Δ MuJoCo mm | "
        "exact: penetration mm | exact: energy rise J | exact: unconverged | exact: Δ closed form mm |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        s, e = r.get("soft_quality", {}), r.get("exact_quality", {})
        lines.append(f"| {r['name']}{' *' if r.get('passive') else ''} | {quality_cells(s, 'vs_mujoco')} | "
                     f"{quality_cells(e, 'vs_closed')} |")
    return "\n".join(lines) + "\n"


def quality_cells(q: dict, gap: str | None = None) -> str:
    """Table cells of one quality run (all four, or the error across them)."""
    if not q:
        return "— | — | — | —" if gap else "—"
    if "error" in q:
        # A mode left out on purpose (`--soft-only-above`) is said so, not counted as a failure.
        what = q["error"] if q["error"].startswith("not run") else f"failed: {q['error']}"
        return f"{what[:98]} | | |" if gap else what
    mm = lambda x: "—" if not math.isfinite(x) else f"{1e3 * x:.3g}"
    # Contacts a pass had to drop (the contact budget: 500 where a solver forms rows × rows
    # matrices) are said beside the penetration they cause.
    dropped = f" ({q['dropped']} contacts dropped)" if q.get("dropped") else ""
    cells = [mm(q["penetration"]) + dropped, f"{q['rise']:.2e}", str(q["unconverged"])]
    if gap:
        cells.append(mm(q[gap]))
        return " | ".join(cells) + ("" if q["finite"] else " (non-finite state)")
    return (f"penetration {mm(q['penetration'])} mm, energy rise {q['rise']:.2e} J (E0 {q['energy0']:.3g}), "
            f"unconverged {q['unconverged']}, Δ MuJoCo {mm(q.get('vs_mujoco', math.nan))} mm, "
            f"Δ closed form {mm(q.get('vs_closed', math.nan))} mm{'' if q['finite'] else ', NON-FINITE'}")


if __name__ == "__main__":
    sys.exit(main())
