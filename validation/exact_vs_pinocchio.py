"""The exact mode's contact solver beside Pinocchio's ADMM and PGS constraint solvers on the same
problems: the constraint problems lagrange's exact mode solves in real contact scenes (those of
validation/bench_contact_rich.py: a box stack, a mass-ratio stack, bins of mixed primitives, the
gripper holding a box, the dm_control humanoid and go1 on the floor), taken out with
`lagrange eval --step S --constraints exact --dump-contact-problem FILE` at a few steps per scene
with at least 4 contacts, each solved by

- lagrange's projected Gauss–Seidel with its polish (the exact mode's default) and its ADMM, from a
  cold start, timed in Rust around the solve alone (the best of 10, `eval` prints it);
- Pinocchio's `ADMMConstraintSolver` and `PGSConstraintSolver` (Pinocchio 4.1's names of its
  contact solvers, `ADMMContactSolver`/`PGSContactSolver` before) on `DelassusOperatorDense(G)`, g
  and one constraint model per block, timed in Python around `solve` alone (the best of 10, a fresh solver, result and
  operator each time, made outside the timer),

and reports per problem the time, iterations, the residual of every solution by one function here
(`residual`, the definition of `ContactProblem::residual` in src/constraint/contact_problem.rs,
checked against lagrange's own figure), and the distance between the solutions (forces, and the
row accelerations G λ + g they give: with redundant contacts the forces are not unique, the motion
is).

The problem (docs/constraints.md, "Exporting the exact mode's problem"): σ = G λ + g, per contact
at rest λ in the Coulomb cone with the De Saxcé correction — Pinocchio's `CoulombFrictionCone`, the
normal last of its 3 rows (lagrange's first: permuted here) — per joint limit or frictionless
contact λ ≥ 0 ⊥ σ ≥ 0 (Pinocchio: a `JointLimitConstraintModel` row, `NonNegativeOrthantCone`), per
dof friction loss a box (a `JointFrictionConstraintModel` row, `BoxSet`), all on a stand-in
Pinocchio model of one hinge per such row (only its constraint sets are read: G and g are given).
lagrange's exact mode always uses elliptic cones (MJCF's `cone` is the soft mode's), so no option
is needed. Rows lagrange leaves out (separating, round-off) are left out for Pinocchio too. Problems
with a slipping contact (lagrange's sliding law, friction on the ray against the slip, which is not
a cone problem) or with equality rows are not given to Pinocchio: the steps are picked to avoid
them, and a problem that has them is reported with lagrange's figures only.

    validation/.venv/bin/python validation/exact_vs_pinocchio.py [--binary target/release/lagrange] [--write]

Prints the report; `--write` also writes the section "## Exact contact solver beside Pinocchio's
ADMM and PGS" of validation/bench.md. Exits 1 when a problem cannot be exported or a solver fails
(an exception, a non-finite λ); slow or unconverged solves are reported, never failed.
"""

from __future__ import annotations

import argparse
import json
import math
import os
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
from bench_contact_rich import bin_scene, mass_ratio, stack  # noqa: E402
from crossval_scenes import commit, replace_section  # noqa: E402

SECTION = "## Exact contact solver beside Pinocchio's ADMM and PGS"
REPEATS = 10
MIN_CONTACTS = 4
# Pinocchio's solvers: iteration limit, and the absolute tolerance on feasibility and
# complementarity relative to 1 + ‖g‖∞ (lagrange's ADMM stops at 1e-8 of 1 + ‖b‖∞).
MAX_ITERATIONS = 5000
TOLERANCE = 1e-8


def scenes() -> list[tuple[str, object, str | None, list[int]]]:
    """(name, MJCF text or path, keyframe, candidate steps): the first steps of one run with at
    least MIN_CONTACTS contacts and no slipping contact are kept, up to 3 per scene (when none is,
    the first with enough contacts is reported with lagrange's figures only)."""
    return [
        ("stack_5", stack(5), None, [5, 50, 150]),
        ("ratio_100", mass_ratio(100), None, [5, 50, 150]),
        ("bin_10", bin_scene(10), None, [100, 150, 200, 300, 500]),
        ("bin_50", bin_scene(50), None, [200, 300]),
        ("gripper_box", HERE / "scenes/gripper_box.xml", "hold", [5, 50, 150]),
        ("humanoid", REPO / "models/mjcf/humanoid/humanoid.xml", None, [150, 200, 250, 300]),
        ("go1", REPO / "models/mjcf/unitree_go1/scene.xml", None, [100, 200, 400, 500, 600]),
    ]


def start_state(mj, path: Path, key: str | None) -> dict:
    m = mj.MjModel.from_xml_path(str(path))
    if key is None:
        return {"q": [float(x) for x in m.qpos0]}
    k = mj.mj_name2id(m, mj.mjtObj.mjOBJ_KEY, key)
    return {"q": [float(x) for x in m.key_qpos[k]], "ctrl": [float(x) for x in m.key_ctrl[k]]}


def dump(binary: Path, path: Path, state: dict, steps: int, tmp: Path) -> tuple[dict, dict]:
    """lagrange's problem at the state after `steps` steps from `state` (`eval --step
    --dump-contact-problem`), and that state (to go on from)."""
    states, out = tmp / "states.json", tmp / "problem.json"
    states.write_text(json.dumps({"states": [state]}))
    p = subprocess.run([str(binary), "eval", str(path), "--states", str(states), "--step", str(steps),
                        "--constraints", "exact", "--dump-contact-problem", str(out)],
                       capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        raise RuntimeError(f"{path.name}: lagrange eval failed: {(p.stderr or p.stdout)[:400]}")
    r = json.loads(p.stdout)["results"][0]
    after = {"q": r["qpos"], "v": r["qvel"], "act": r["act"], "time": r["time"]}
    if "ctrl" in state:
        after["ctrl"] = state["ctrl"]
    return json.loads(out.read_text())["problems"][0], after


# ---------------------------------------------------------------------------------------------
# The residual, one definition for every solution (that of ContactProblem::residual).

def soc_distance(xn: float, xt: float) -> float:
    """Distance of (xn, x_t), ‖x_t‖ = xt, to the unit second-order cone ‖x_t‖ ≤ xn."""
    if xt <= xn:
        return 0.0
    if xt <= -xn:
        return math.hypot(xn, xt)
    return (xt - xn) / math.sqrt(2.0)


def residual(problem: dict, lam: np.ndarray) -> dict:
    """Primal feasibility (λ in its set), dual feasibility (σ = Gλ + g, with the De Saxcé
    correction, in the dual set), complementarity, the largest over the blocks, and `relative`:
    max(primal / (1 + ‖λ‖∞), dual / (1 + ‖g‖∞), compl. / ((1 + ‖λ‖∞)(1 + ‖g‖∞))). Contacts in the
    scaled variables λ̂_k = λ_k/μ_k, σ̂_k = μ_k σ_k of the unit second-order cone."""
    G, g = problem["_G"], problem["_g"]
    sigma = G @ lam + g
    primal = dual = comp = 0.0
    for b in problem["blocks"]:
        i, n, law = b["first"], b["len"], b["law"]
        l, s = lam[i:i + n], sigma[i:i + n]
        if law == "equality":
            p, d, c = 0.0, abs(s[0]), 0.0
        elif law == "unilateral":
            p, d, c = max(0.0, -l[0]), max(0.0, -s[0]), abs(l[0] * s[0])
        elif law == "box":
            lo, hi = b.get("lo", -math.inf), b.get("hi", math.inf)
            p = max(lo - l[0], l[0] - hi, 0.0)
            d = 0.0
            c = max(max(s[0], 0.0) * (l[0] - lo), max(-s[0], 0.0) * (hi - l[0]), 0.0)
        elif law == "inactive":
            p, d, c = float(np.max(np.abs(l))), 0.0, 0.0
        elif law == "sliding":
            ray = max((abs(l[k] - max(l[0], 0.0) * b["direction"][k - 1]) for k in range(1, n)), default=0.0)
            p, d, c = max(-l[0], 0.0, ray), max(0.0, -s[0]), abs(l[0] * s[0])
        elif law == "cone":
            mu = b["friction"]
            lt = st = 0.0
            dot = l[0] * s[0]
            zero = 0.0
            for k in range(1, n):
                if mu[k - 1] > 0:
                    lt += (l[k] / mu[k - 1]) ** 2
                    st += (mu[k - 1] * s[k]) ** 2
                    dot += l[k] * s[k]
                else:
                    zero = max(zero, abs(l[k]))
            lt, st = math.sqrt(lt), math.sqrt(st)
            p = max(soc_distance(l[0], lt), zero)
            d = soc_distance(s[0] + st, st)
            c = abs(dot + l[0] * st)
        else:
            raise ValueError(f"unknown law {law}")
        primal, dual, comp = max(primal, p), max(dual, d), max(comp, c)
    lmax = float(np.max(np.abs(lam))) if len(lam) else 0.0
    gmax = float(np.max(np.abs(g))) if len(g) else 0.0
    rel = max(primal / (1 + lmax), dual / (1 + gmax), comp / ((1 + lmax) * (1 + gmax)))
    return {"primal": primal, "dual": dual, "complementarity": comp, "relative": rel}


# ---------------------------------------------------------------------------------------------
# Pinocchio

def pinocchio_problem(pin, problem: dict):
    """(rows, perm, models, datas) of the Pinocchio problem: `rows` the lagrange rows it keeps, in
    Pinocchio's order (`perm`: Pinocchio's row k is lagrange's row rows[k]), one constraint model
    per block on a stand-in model; None with the reason when a block has no Pinocchio counterpart."""
    blocks = [b for b in problem["blocks"] if b["law"] != "inactive"]
    for b in blocks:
        if b["law"] in ("sliding", "equality"):
            return None, f"a {b['law']} block ({b['kind']} {b['id']})"
        if b["law"] == "cone" and (b["len"] != 3 or b["friction"][0] != b["friction"][1]):
            return None, f"a contact of {b['len']} rows or anisotropic friction"
    scalar = [b for b in blocks if b["law"] in ("unilateral", "box")]
    model = pin.Model()
    joints = []
    for k in range(max(1, len(scalar))):
        j = model.addJoint(0, pin.JointModelRX(), pin.SE3.Identity(), f"row{k}")
        model.appendBodyToJoint(j, pin.Inertia.FromSphere(1.0, 0.1), pin.SE3.Identity())
        joints.append(j)
    models = pin.StdVec_ConstraintModel()
    rows: list[int] = []
    k = 0
    for b in blocks:
        i = b["first"]
        if b["law"] == "cone":
            c = pin.PointContactConstraintModel(model, joints[0])
            c.setFriction(float(b["friction"][0]))
            rows += [i + 1, i + 2, i]  # Pinocchio: tangents, then the normal
        elif b["law"] == "unilateral":
            lb = np.full(model.nq, -np.inf)
            lb[k] = 0.0
            c = pin.JointLimitConstraintModel(model, pin.StdVec_Index([joints[k]]), lb, np.full(model.nq, np.inf))
            rows.append(i)
            k += 1
        else:  # box
            lo, hi = np.zeros(model.nv), np.zeros(model.nv)
            lo[k], hi[k] = b["lo"], b["hi"]
            c = pin.JointFrictionConstraintModel(model, pin.StdVec_Index([joints[k]]), lo, hi)
            rows.append(i)
            k += 1
        if c.residualSize() != (3 if b["law"] == "cone" else 1):
            raise RuntimeError(f"Pinocchio's {c.shortname()} has {c.residualSize()} rows")
        models.append(pin.ConstraintModel(c))
    datas = pin.StdVec_ConstraintData()
    for c in models:
        datas.append(c.createData())
    return (np.array(rows, dtype=int), models, datas), ""


def pinocchio_solve(pin, kind: str, problem: dict, setup) -> dict:
    rows, models, datas = setup
    G = np.ascontiguousarray(problem["_G"][np.ix_(rows, rows)])
    g = np.ascontiguousarray(problem["_g"][rows])
    tol = TOLERANCE * (1.0 + float(np.max(np.abs(g))) if len(g) else 1.0)
    Solver, Settings, Result = {
        "admm": (pin.ADMMConstraintSolver, pin.ADMMSolverSettings, pin.ADMMSolverResult),
        "pgs": (pin.PGSConstraintSolver, pin.PGSSolverSettings, pin.PGSSolverResult),
    }[kind]
    best = math.inf
    for _ in range(REPEATS):
        solver, settings, result, op = Solver(len(rows)), Settings(), Result(), pin.DelassusOperatorDense(G)
        settings.max_iterations = MAX_ITERATIONS
        settings.absolute_feasibility_tol = tol
        settings.absolute_complementarity_tol = tol
        settings.relative_feasibility_tol = 0.0
        settings.relative_complementarity_tol = 0.0
        t0 = time.perf_counter()
        solver.solve(op, g, models, datas, settings, result)
        best = min(best, (time.perf_counter() - t0) * 1e6)
    lam = np.zeros(len(problem["_g"]))
    lam[rows] = result.retrieveConstraintImpulses()
    if not np.all(np.isfinite(lam)):
        raise RuntimeError(f"Pinocchio {kind}: non-finite λ")
    return {"lambda": lam, "iterations": int(result.iterations), "converged": bool(result.converged),
            "solve_us": best}


# ---------------------------------------------------------------------------------------------

def contacts_of(problem: dict) -> int:
    return sum(1 for b in problem["blocks"] if b["kind"].startswith("contact") and b["law"] != "inactive")


def sliding_of(problem: dict) -> int:
    return sum(1 for b in problem["blocks"] if b["law"] == "sliding")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--binary", type=Path, default=REPO / "target/release/lagrange")
    ap.add_argument("--write", action="store_true", help="write the section of validation/bench.md")
    ap.add_argument("--only", help="scenes whose name contains this")
    args = ap.parse_args()
    import mujoco as mj
    import pinocchio as pin

    started = time.time()
    results = []
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        for name, scene, key, candidates in scenes():
            if args.only and args.only not in name:
                continue
            path = scene if isinstance(scene, Path) else tmp / f"{name}.xml"
            if not isinstance(scene, Path):
                path.write_text(scene)
            state = start_state(mj, path, key)
            kept = 0
            fallback = None
            done = 0
            for step in candidates:
                if kept == 3:
                    break
                # One run, read on the way: each candidate goes on from the last one's state.
                problem, state = dump(args.binary, path, state, step - done, tmp)
                problem["step"] = done = step
                if contacts_of(problem) < MIN_CONTACTS or sliding_of(problem):
                    print(f"{name:12s} step {step:4d}: {contacts_of(problem)} contacts, {sliding_of(problem)} slipping: "
                          "not kept", flush=True)
                if contacts_of(problem) < MIN_CONTACTS:
                    continue
                if sliding_of(problem) and fallback is None:
                    fallback = problem
                if sliding_of(problem):
                    continue
                results.append(compare(pin, name, problem))
                kept += 1
            if kept == 0 and fallback is not None:
                results.append(compare(pin, name, fallback))
            if kept == 0 and fallback is None:
                print(f"{name}: no step of {candidates} has {MIN_CONTACTS} contacts", flush=True)
    text = report(results, time.time() - started)
    print(text)
    if args.write:
        replace_section(HERE / "bench.md", SECTION, text)
    return 0


def compare(pin, name: str, problem: dict) -> dict:
    problem["_G"] = np.array(problem["G"], dtype=float).reshape(problem["nefc"], problem["nefc"])
    problem["_g"] = np.array(problem["g"], dtype=float)
    row = {"scene": name, "step": problem["step"], "rows": problem["nefc"], "contacts": contacts_of(problem),
           "sliding": sliding_of(problem), "solvers": {}, "note": ""}
    for kind in ("pgs", "admm"):
        s = problem[kind]
        lam = np.array(s["lambda"], dtype=float)
        r = residual(problem, lam)
        # One definition, two implementations: lagrange's own figure must agree.
        theirs = s["ccp_residual"]["relative"]
        if abs(r["relative"] - theirs) > 1e-9 * (1 + abs(theirs)) + 1e-14:
            raise RuntimeError(f"{name} step {problem['step']}: residual here {r['relative']:.3e}, lagrange's {theirs:.3e}")
        row["solvers"][f"lagrange {kind}"] = {"lambda": lam, "iterations": s["iterations"], "converged": s["converged"],
                                              "solve_us": s["solve_us"], "residual": r}
    setup, why = pinocchio_problem(pin, problem)
    if setup is None:
        row["note"] = f"not given to Pinocchio: {why}"
    else:
        for kind in ("admm", "pgs"):
            s = pinocchio_solve(pin, kind, problem, setup)
            s["residual"] = residual(problem, s["lambda"])
            row["solvers"][f"Pinocchio {kind}"] = s
    f = problem["forward"]
    row["warm"] = {"iterations": f["iterations"], "converged": f["converged"],
                   "residual": residual(problem, np.array(f["lambda"], dtype=float))}
    ref = row["solvers"]["lagrange pgs"]["lambda"]
    G, g = problem["_G"], problem["_g"]
    for s in row["solvers"].values():
        s["dlambda"] = float(np.max(np.abs(s["lambda"] - ref))) / (1 + float(np.max(np.abs(ref))))
        s["dsigma"] = float(np.max(np.abs(G @ (s["lambda"] - ref)))) / (1 + float(np.max(np.abs(g))))
    print(f"{name:12s} step {problem['step']:4d}  {problem['nefc']:4d} rows {row['contacts']:3d} contacts  " + "  ".join(
        f"{k}: {s['solve_us']:9.1f} µs {s['iterations']:5d} it res {s['residual']['relative']:.1e}"
        for k, s in row["solvers"].items()) + (f"  ({row['note']})" if row["note"] else ""), flush=True)
    return row


def cell(s: dict | None) -> str:
    if s is None:
        return "—"
    flag = "" if s["converged"] else " (not converged)"
    return f"{s['solve_us']:.0f} µs, {s['iterations']} it, {s['residual']['relative']:.0e}{flag}"


def summary(results: list[dict]) -> str:
    """One line: per solver, the problems it converged on and the median time against lagrange's
    Gauss–Seidel on the problems all four solved."""
    names = ["lagrange pgs", "lagrange admm", "Pinocchio admm", "Pinocchio pgs"]
    both = [r for r in results if all(k in r["solvers"] for k in names)]
    parts = []
    for k in names:
        conv = sum(1 for r in both if r["solvers"][k]["converged"])
        ratio = float(np.median([r["solvers"][k]["solve_us"] / r["solvers"]["lagrange pgs"]["solve_us"] for r in both])) \
            if both else math.nan
        worst = max((r["solvers"][k]["residual"]["relative"] for r in both), default=math.nan)
        parts.append(f"{k} converged on {conv}, median time {ratio:.2f}× lagrange pgs, worst residual {worst:.0e}")
    return (f"Summary over the {len(both)} problems of {len(results)} given to Pinocchio: " + "; ".join(parts) + ".")


def warm_cell(w: dict) -> str:
    flag = "" if w["converged"] else " (not converged)"
    return f"{w['iterations']} it, {w['residual']['relative']:.0e}{flag}"


def report(results: list[dict], seconds: float) -> str:
    import pinocchio as pin

    names = ["lagrange pgs", "lagrange admm", "Pinocchio admm", "Pinocchio pgs"]
    lines = [
        SECTION, "",
        f"Written by `validation/exact_vs_pinocchio.py` on {time.strftime('%Y-%m-%d', time.gmtime())} (UTC), lagrange "
        f"{commit()}, Pinocchio {pin.__version__}, {platform.machine()}, load average "
        f"{' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} CPUs, {seconds:.0f} s. Report only.",
        "",
        "What is compared: the constraint problems lagrange's exact mode solves at a few steps of the contact-rich "
        "scenes (from rest, the gripper from its `hold` keyframe; steps with at least "
        f"{MIN_CONTACTS} contacts and none slipping), taken out with `lagrange eval --step S --constraints exact "
        "--dump-contact-problem` — the Delassus matrix G = J M⁻¹ Jᵀ and free row accelerations g, σ = G λ + g, "
        "Coulomb cones (elliptic, the exact mode's only cone) with the De Saxcé correction, limits and frictionless "
        "contacts λ ≥ 0 ⊥ σ ≥ 0, friction loss in a box — and solved from a cold start by lagrange's projected "
        "Gauss–Seidel with polish (its default), lagrange's ADMM, and Pinocchio's `ADMMConstraintSolver` and "
        "`PGSConstraintSolver` given `DelassusOperatorDense(G)`, g and one constraint set per block "
        f"(`CoulombFrictionCone`, `NonNegativeOrthantCone`, `BoxSet`; Pinocchio's default settings — the NCP with "
        f"the De Saxcé correction, `solve_ncp`, ADMM's OSQP ρ rule — but at most {MAX_ITERATIONS} iterations, absolute "
        f"tolerances {TOLERANCE:g}·(1 + ‖g‖∞) and relative ones off). Times: the best of {REPEATS} solves, lagrange's "
        "measured in Rust around its solve alone, Pinocchio's in Python around the `solve` call alone (a Python "
        "call adds about a µs). Each cell: time, iterations, and the relative residual of the solution by one "
        "function (validation/exact_vs_pinocchio.py `residual`, = `ContactProblem::residual`: max of primal "
        "feasibility / (1 + ‖λ‖∞), dual feasibility / (1 + ‖g‖∞), complementarity / ((1 + ‖λ‖∞)(1 + ‖g‖∞))). "
        "Δλ, Δσ: the largest difference from lagrange's Gauss–Seidel solution of the forces (/ (1 + ‖λ‖∞)) and of "
        "the row accelerations G λ + g they give (/ (1 + ‖g‖∞)); with redundant contacts (a box's four corners) the "
        "forces are not unique, the accelerations are. \"In its step\": the iterations and residual of the solve "
        "`forward` made at that state, warm-started from the step before (the default solver; the polish makes a "
        "converged solve exact to round-off). Problems with a slipping contact are not cone problems (lagrange's "
        "friction then lies on the ray against the slip, a non-symmetric law) and are not given to Pinocchio "
        "(the note says so).",
        "",
        summary(results),
        "",
        "| scene | step | rows | contacts | " + " | ".join(names) + " | lagrange in its step (warm start) "
        "| Δλ, Δσ lagrange admm | Δλ, Δσ Pinocchio admm | Δλ, Δσ Pinocchio pgs | note |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        s = r["solvers"]
        d = [f"{s[k]['dlambda']:.0e}, {s[k]['dsigma']:.0e}" if k in s else "—" for k in names[1:]]
        lines.append(f"| {r['scene']} | {r['step']} | {r['rows']} | {r['contacts']} | "
                     + " | ".join(cell(s.get(k)) for k in names) + f" | {warm_cell(r['warm'])} | " + " | ".join(d)
                     + f" | {r['note']} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
