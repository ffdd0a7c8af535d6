#!/usr/bin/env python3
"""Live cross-validation of lagrange against MuJoCo and Pinocchio on real robot models.

Run it through the wrapper, which builds the venv and the release binary first:

    validation/crossval                    # the whole corpus; writes validation/report.{md,csv}
    validation/crossval --filter ur5       # a subset (regex on the model name); no report written
    validation/crossval --write-golden     # regenerate tests/data/ (the offline reference data)

For every model of the corpus (crossval_corpus.py) it draws N random states (joint ranges, unit
quaternions), evaluates them with ONE `lagrange eval` process and with each reference that loads
the model, and compares M, bias, ABA, every body pose, end-frame Jacobians, total mass, centre of
mass, kinetic and potential energy. Exit status 1 when a model a reference loads does not load in
lagrange or differs by more than the tolerance (1e-9 relative unless the model has a measured,
written reason in LOOSER below). See validation/README.md, "Cross-validation".
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import math
import os
import re
import subprocess
import sys
import time
import traceback
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from crossval_common import QUANTITY_KEYS, REF_REL, EngineRun, model_rng, random_states, rel_err  # noqa: E402
from crossval_corpus import REPO, Entry, corpus  # noqa: E402
from crossval_engines import Lagrange, MuJoCo, Pinocchio, UrdfInfo  # noqa: E402
import crossval_report  # noqa: E402

SEED = 20261121
N_STATES = 5
MAX_JAC_FRAMES = 4

# Per-model tolerances looser than REF_REL. Each needs a written reason; the report prints it
# beside the measured quantity it rests on (cond(M) of the reference, measured in this run).
# key: regex on the model id; value: {quantity: (tolerance, reason)}.
LOOSER: dict[str, dict[str, tuple[float, str]]] = {
    r"icub_description/robots/icub\.urdf@floating": {
        "qacc": (1e-6, "link l_ankle_2 has a zero inertia tensor (principal moments ±1.4e-20 kg·m²), "
                       "so M is nearly singular: cond(M) up to 7.9e11 measured with Pinocchio over 20 "
                       "random states; a backward-stable solve then guarantees only ε·cond(M) ≈ 2e-4 "
                       "relative; observed 4.8e-9"),
    },
}

REFERENCES = ("mujoco", "pinocchio")
REF_NAMES = {"mujoco": "MuJoCo", "pinocchio": "Pinocchio"}

EPS = 2.220446049250313e-16
#: M counts as singular when ε·cond(M) reaches this (cond(M) ≳ 4.5e12): a backward-stable solve
#: then guarantees no correct digit beyond the third.
SINGULAR_EPS_COND = 1e-3


# ---------------------------------------------------------------------------------------------
# Comparison
# ---------------------------------------------------------------------------------------------


def compare(a: EngineRun, b: EngineRun) -> tuple[dict[str, float], dict[str, str]]:
    """Max over states of the relative error of each quantity, a against b, and where it is."""
    errs = {q: 0.0 for q in QUANTITY_KEYS}
    where = {q: "" for q in QUANTITY_KEYS}

    def upd(q, e, at):
        # NaN wins (it is reported as a failure); otherwise keep the largest
        if math.isnan(errs[q]):
            return
        if math.isnan(e) or e > errs[q]:
            errs[q], where[q] = e, at

    for k, (ra, rb) in enumerate(zip(a.results, b.results)):
        upd("M", rel_err(ra.M, rb.M), "state %d" % k)
        upd("bias", rel_err(ra.bias, rb.bias), "state %d" % k)
        upd("qacc", rel_err(ra.qacc, rb.qacc), "state %d" % k)
        names = [n for n in rb.poses if n in ra.poses]
        if names:
            va = np.concatenate([np.concatenate([ra.poses[n][0], ra.poses[n][1].ravel()]) for n in names])
            vb = np.concatenate([np.concatenate([rb.poses[n][0], rb.poses[n][1].ravel()]) for n in names])
            e = rel_err(va, vb)
            d = np.abs(va - vb).reshape(len(names), 12).max(axis=1)
            upd("pose", e, "state %d, body '%s'" % (k, names[int(np.nanargmax(d))] if not np.isnan(d).all() else "?"))
        frames = [f for f in rb.jac if f in ra.jac]
        if frames:
            e = rel_err(np.concatenate([ra.jac[f] for f in frames], axis=1),
                        np.concatenate([rb.jac[f] for f in frames], axis=1))
            upd("jac", e, "state %d, frames %s" % (k, ", ".join(frames)))
        upd("mass", rel_err(ra.mass, rb.mass), "")
        if rb.mass > 0:  # (the centre of mass of nothing is undefined: Pinocchio gives NaN)
            upd("com", rel_err(ra.com, rb.com), "state %d" % k)
        upd("kinetic", rel_err(ra.kinetic, rb.kinetic), "state %d" % k)
        upd("potential", rel_err(ra.potential, rb.potential), "state %d" % k)
    return errs, where


def within(err: float, tol: float) -> bool:
    """err ≤ tol; a quantity with an infinite tolerance is not compared (NaN included)."""
    return math.isinf(tol) or err <= tol


def tolerances(entry: Entry) -> tuple[dict[str, float], list[str]]:
    tol = {q: REF_REL for q in QUANTITY_KEYS}
    reasons = []
    for pat, over in LOOSER.items():
        if re.search(pat, entry.id):
            for q, (t, why) in over.items():
                tol[q] = t
                reasons.append("%s tolerance %.0e: %s" % (q, t, why))
    return tol, reasons


def jacobian_frames(entry: Entry, urdf: UrdfInfo | None, mj: EngineRun) -> list[str]:
    """Up to MAX_JAC_FRAMES end frames (leaf bodies), the deepest first."""
    if urdf is not None:
        leaves = sorted(urdf.leaves, key=lambda l: -urdf.depth(l))
    elif mj.status == "ok":
        leaves = list(mj.leaves)  # already deepest first
    else:
        leaves = []
    return leaves[:MAX_JAC_FRAMES]


# ---------------------------------------------------------------------------------------------
# One model
# ---------------------------------------------------------------------------------------------


def phase(text: str) -> None:
    """Tells the parent process what the worker is doing, so that a crash can be attributed."""
    print("PHASE " + text, file=sys.stderr, flush=True)


def process(entry: Entry, cfg: dict) -> dict:
    t0 = time.perf_counter()
    try:
        row = _process(entry, cfg)
    except Exception as e:  # a harness bug must show up as a failing row, not kill the run
        row = base_row(entry)
        row["result"] = "FAIL"
        row["notes"].append("harness error: %s" % "".join(traceback.format_exception_only(type(e), e)).strip())
        row["notes"].append(traceback.format_exc().strip().splitlines()[-3])
    row["seconds"] = time.perf_counter() - t0
    return row


def base_row(entry: Entry) -> dict:
    return {
        "id": entry.id, "name": entry.name, "source": entry.source, "fmt": entry.fmt,
        "floating": entry.floating, "extra": entry.extra, "primary": entry.primary,
        "nq": None, "nv": None,
        "load": {"lagrange": "not run", "mujoco": "not run", "pinocchio": "not run"},
        "load_detail": {},
        "status": {},  # reference -> ok | load-error | incomparable | disagrees | ...
        "errors": {},  # reference -> {quantity: max rel err}
        "where": {},
        "ref_vs_ref": None,
        "tol": {q: REF_REL for q in QUANTITY_KEYS},
        "tol_reasons": [],
        "cond_M": {},
        "notes": [],
        "result": "",
        "jac_frames": [],
        "bodies_compared": 0,
    }


def _process(entry: Entry, cfg: dict) -> dict:
    row = base_row(entry)
    crashed = cfg.get("crashed", {})  # engine -> what it crashed in, from earlier attempts
    lagrange = Lagrange(cfg["lagrange"], cfg["timeout"])
    phase("lagrange load")
    lag = lagrange.info(entry)
    if lag.note:
        row["notes"].append(lag.note)
    mjengine, pinengine = MuJoCo(), Pinocchio()
    runs = {"lagrange": lag}
    for name, eng in (("mujoco", mjengine), ("pinocchio", pinengine)):
        if name in crashed:
            runs[name] = EngineRun(name, "crash", "crashed (%s), not used" % crashed[name])
        else:
            phase("%s load" % name)
            runs[name] = eng.load(entry)
    for k, r in runs.items():
        row["load"][k] = {"ok": "yes", "load-error": "no", "crash": "crash"}.get(r.status, "partial")
        if r.detail:
            row["load_detail"][k] = r.detail

    urdf = UrdfInfo(entry.path, entry.floating) if entry.fmt == "urdf" else None
    mj = runs["mujoco"]
    # canonical layout: lagrange's; if lagrange cannot load, lagrange's documented order
    # (URDF: depth-first file order; MJCF: MuJoCo's) so the references still meet each other
    if lag.status == "ok":
        canon = lag.layout
    elif urdf is not None and urdf.root is not None:
        canon = urdf.layout
    elif mj.status == "ok":
        canon = mj.layout
    else:
        canon = None
    if canon is not None:
        row["nq"], row["nv"] = canon.nq, canon.nv
    if urdf is not None:
        ranges = urdf.ranges
        required = list(urdf.links)
    else:
        ranges = {s.name: s.range for s in mj.layout.slots if s.range} if mj.status == "ok" else {}
        required = list(mj.bodies) + list(mj.sites) if mj.status == "ok" else []
    tol, reasons = tolerances(entry)
    row["tol"], row["tol_reasons"] = tol, reasons

    if canon is not None:
        states = random_states(model_rng(cfg["seed"], entry.id), canon, ranges, cfg["n_states"])
        frames = jacobian_frames(entry, urdf, mj)
        row["jac_frames"] = frames
        if lag.status == "ok":
            phase("lagrange evaluate")
            lagrange.evaluate(entry, lag, states, frames)
            if lag.status != "ok":
                row["load"]["lagrange"] = "eval error"
                row["load_detail"]["lagrange"] = lag.detail
        joint_body = {s.name: s.body for s in mj.layout.slots} if mj.status == "ok" else None
        for name, eng in (("mujoco", mjengine), ("pinocchio", pinengine)):
            r = runs[name]
            if r.status == "ok":
                phase("%s evaluate" % name)
                if name == "pinocchio":
                    eng.evaluate(r, canon, states, frames, joint_body)
                else:
                    eng.evaluate(r, canon, states, frames)
                if r.status != "ok":
                    row["load"][name] = "partial"
                    row["load_detail"][name] = r.detail
    for name in REFERENCES:
        r = runs[name]
        row["status"][name] = r.status
        if not math.isnan(r.cond_M):
            row["cond_M"][name] = r.cond_M

    # A reference M singular to working precision (massless moving bodies, point masses on a
    # floating base): forward dynamics is undefined, so ABA is not compared (reported).
    for name in REFERENCES:
        c = row["cond_M"].get(name)
        if c is not None and c * EPS >= SINGULAR_EPS_COND and not math.isinf(tol["qacc"]):
            tol["qacc"] = math.inf
            reasons.append("ABA not compared: M is singular to working precision, cond(M) = %.1e measured by %s "
                           "(ε·cond(M) = %.0e ≥ %.0e), so M⁻¹(τ − bias) is undefined" % (
                               c, name, c * EPS, SINGULAR_EPS_COND))

    # Which references count: the one whose own format this is (primary), and the other when it
    # agrees with the primary (Pinocchio's MJCF reader and MuJoCo's URDF import are partial).
    primary = entry.primary
    secondary = "mujoco" if primary == "pinocchio" else "pinocchio"
    valid = []
    if runs[primary].status == "ok":
        valid.append(primary)
    if runs[secondary].status == "ok":
        if runs[primary].status == "ok":
            e, w = compare(runs[secondary], runs[primary])
            row["ref_vs_ref"] = e
            bad = [q for q in QUANTITY_KEYS if not within(e[q], tol[q])]
            if bad:
                runs[secondary].status = "disagrees"
                row["status"][secondary] = "disagrees"
                row["notes"].append(
                    "%s disagrees with %s (%s), not used: %s" % (
                        secondary, primary,
                        "; ".join("%s %.1e at %s" % (q, e[q], w[q]) for q in bad[:3]),
                        "its %s reader is partial" % ("MJCF" if entry.fmt == "mjcf" else "URDF"),
                    )
                )
            else:
                valid.append(secondary)
        else:
            valid.append(secondary)

    fails = []
    if lag.status == "ok":
        lag_frames = set(lag.bodies)
        missing = [b for b in required if b not in lag_frames]
        if missing and valid:
            fails.append("lagrange has no frame for %d bodies: %s" % (
                len(missing), ", ".join("'%s'" % m for m in missing[:5]) + (" …" if len(missing) > 5 else "")))
        for ref in valid:
            e, w = compare(lag, runs[ref])
            row["errors"][ref] = e
            row["where"][ref] = w
            for q in QUANTITY_KEYS:
                if not within(e[q], tol[q]):
                    fails.append("%s vs %s: %.2e > %.0e (%s)" % (q, ref, e[q], tol[q], w[q]))
        if valid:
            row["bodies_compared"] = len([n for n in lag.results[0].poses if n in runs[valid[0]].results[0].poses]) \
                if lag.results and runs[valid[0]].results else 0
    if runs[primary].status == "incomparable" and lag.status == "ok":
        fails.append("%s: %s" % (primary, runs[primary].detail))
    # lagrange must load what the reference of the file's own format loads; when that reference
    # rejects the file (ur3.urdf has no links, which MuJoCo's URDF import turns into an empty
    # world), lagrange rejecting it too is reported, not failed
    primary_loads = runs[primary].status not in ("load-error", "crash")
    # A URDF whose mimics Pinocchio's mimic support refuses: lagrange enforces mimics, so it is
    # measured against that refusal.
    mimic_refusal = runs.get("pinocchio").mimic_refusal if runs.get("pinocchio") else ""
    if mimic_refusal and lag.status != "ok":
        primary_loads = False
        row["notes"].append("Pinocchio with its mimic support on (mimic=True) refuses the file: " + mimic_refusal)
    rejected = valid and lag.status != "ok" and row["load"]["lagrange"] == "no" and not primary_loads
    if valid and lag.status != "ok" and not rejected:
        fails.append("lagrange loads it but `eval` fails" if row["load"]["lagrange"] == "eval error"
                     else "a reference loads it but lagrange does not")
    if rejected:
        row["notes"].append("%s, the reference of this format, rejects the file, and so does lagrange" %
                            REF_NAMES[primary])

    if fails:
        row["result"] = "FAIL"
        row["notes"] = fails + row["notes"]
    elif rejected:
        row["result"] = "rejected"
    elif valid:
        row["result"] = "PASS"
    elif lag.status == "ok":
        row["result"] = "no reference"
    else:
        row["result"] = "nobody loads"
    if row["result"] == "PASS" and reasons:
        for ref in valid:
            if ref in row["cond_M"]:
                row["notes"].append("cond(M) measured by %s: %.2e" % (ref, row["cond_M"][ref]))
    return row


# ---------------------------------------------------------------------------------------------


def run_worker(entry: Entry, cfg: dict, extra: bool) -> dict:
    """Evaluates one model in a child process (a reference that crashes on a model must not take
    the run down). On a crash, the model is retried without the engine that crashed."""
    crashed: dict[str, str] = {}
    t0 = time.perf_counter()
    for attempt in range(3):
        cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", entry.id,
               "--states", str(cfg["n_states"]), "--seed", str(cfg["seed"]), "--lagrange", str(cfg["lagrange"]),
               "--timeout", str(cfg["timeout"])]
        for eng, why in crashed.items():
            cmd += ["--crashed", "%s=%s" % (eng, why)]
        if extra:
            cmd.append("--extra")
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=cfg["timeout"] * 3 + 300, cwd=REPO)
        except subprocess.TimeoutExpired as e:
            err = e.stderr.decode() if isinstance(e.stderr, bytes) else (e.stderr or "")
            p = subprocess.CompletedProcess(cmd, -9, "", err)
        for line in p.stdout.splitlines():
            if line.startswith("ROW "):
                row = json.loads(line[4:])
                row["seconds"] = time.perf_counter() - t0
                return row
        phases = [l[6:] for l in p.stderr.splitlines() if l.startswith("PHASE ")]
        last = phases[-1] if phases else "start-up"
        engine = last.split()[0]
        why = "signal %d in %s" % (-p.returncode, last) if p.returncode < 0 else "exit %d in %s: %s" % (
            p.returncode, last, first_line_of(p.stderr))
        if engine in ("mujoco", "pinocchio") and engine not in crashed:
            crashed[engine] = why
            continue
        break
    row = base_row(entry)
    row["result"] = "FAIL"
    row["notes"].append("harness worker failed: %s" % why)
    row["seconds"] = time.perf_counter() - t0
    return row


def first_line_of(text: str) -> str:
    lines = [l for l in text.strip().splitlines() if l.strip() and not l.startswith("PHASE ")]
    return lines[-1][:300] if lines else ""


def write_golden(python: str) -> int:
    """Runs every validation/*_golden.py (pinocchio_golden.py, mujoco_golden.py, ...): each
    rewrites its part of tests/data/, which `cargo test` compares against offline."""
    here = REPO / "validation"
    scripts = sorted(here.glob("*_golden.py"), key=lambda p: (p.name != "pinocchio_golden.py", p.name))
    rc = 0
    for s in scripts:
        print("== %s" % s.relative_to(REPO), flush=True)
        rc |= subprocess.call([python, str(s)], cwd=REPO)
    subprocess.call(["git", "--no-pager", "diff", "--stat", "--", "tests/data"], cwd=REPO)
    return rc


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--states", type=int, default=N_STATES, help="random states per model (default %(default)s)")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2, help="models evaluated in parallel")
    ap.add_argument("--filter", help="only models whose name matches this regex (no report is written)")
    ap.add_argument("--extra", action="store_true", help="add the optional extra group (MyoSuite); never fails the run")
    ap.add_argument("--lagrange", type=Path, default=REPO / "target" / "release" / "lagrange")
    ap.add_argument("--report", type=Path, help="Markdown report (default validation/report.md on a full run)")
    ap.add_argument("--csv", type=Path, help="CSV report (default validation/report.csv on a full run)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per lagrange process")
    ap.add_argument("--seed", type=int, default=SEED)
    ap.add_argument("--write-golden", action="store_true",
                    help="regenerate the reference data cargo test reads (tests/data/) and exit")
    ap.add_argument("--list", action="store_true", help="print the corpus and exit")
    ap.add_argument("--worker", metavar="ID", help=argparse.SUPPRESS)  # internal: one model, JSON out
    ap.add_argument("--crashed", action="append", default=[], help=argparse.SUPPRESS)
    args = ap.parse_args()

    if args.write_golden:
        return write_golden(sys.executable)

    if args.worker:
        entry = next(e for e in corpus(extra=args.extra) if e.id == args.worker)
        cfg = {"lagrange": args.lagrange.resolve(), "timeout": args.timeout, "seed": args.seed,
               "n_states": args.states, "crashed": dict(c.split("=", 1) for c in args.crashed)}
        row = process(entry, cfg)
        print("ROW " + json.dumps(row), flush=True)
        return 0

    entries = corpus(extra=args.extra)
    if args.filter:
        entries = [e for e in entries if re.search(args.filter, e.name)]
    if args.list:
        for e in entries:
            print("%-10s %-5s %s" % (e.source.split()[0], e.fmt, e.name))
        print("%d models" % len(entries))
        return 0
    if not args.lagrange.exists():
        print("crossval: %s does not exist (cargo build --release)" % args.lagrange, file=sys.stderr)
        return 2
    full = not args.filter
    report = args.report or (REPO / "validation" / "report.md" if full else None)
    csv = args.csv or (REPO / "validation" / "report.csv" if full else None)

    import mujoco
    import pinocchio

    cfg = {"lagrange": args.lagrange.resolve(), "timeout": args.timeout, "seed": args.seed, "n_states": args.states}
    meta = {
        "mujoco": mujoco.__version__,
        "pinocchio": pinocchio.__version__,
        "lagrange": subprocess.run([str(args.lagrange), "--version"], capture_output=True, text=True).stdout.strip(),
        "commit": subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True).stdout.strip(),
        "dirty": bool(subprocess.run(["git", "status", "--porcelain", "--", "src", "Cargo.toml"], cwd=REPO,
                                     capture_output=True, text=True).stdout.strip()),
        "states": args.states,
        "seed": args.seed,
        "jobs": args.jobs,
    }
    print("cross-validation: %d models, %d states each, lagrange %s, MuJoCo %s, Pinocchio %s, %d jobs" % (
        len(entries), args.states, meta["commit"], meta["mujoco"], meta["pinocchio"], args.jobs), flush=True)

    t0 = time.perf_counter()
    rows = []
    # slow models (large Menagerie humanoids) first, so the two workers finish together
    order = sorted(entries, key=lambda e: (0 if "menagerie" in e.id else 1))
    with cf.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futs = {pool.submit(run_worker, e, cfg, args.extra): e for e in order}
        for i, f in enumerate(cf.as_completed(futs), 1):
            row = f.result()
            rows.append(row)
            print("[%3d/%d] %-12s %5.1fs  %s%s" % (
                i, len(entries), row["result"], row["seconds"], row["name"],
                ("  — " + row["notes"][0]) if row["result"] == "FAIL" and row["notes"] else ""), flush=True)
    meta["seconds"] = time.perf_counter() - t0
    index = {e.id: k for k, e in enumerate(entries)}
    rows.sort(key=lambda r: index[r["id"]])

    text = crossval_report.render_text(rows, meta)
    print(text)
    if report:
        report.write_text(crossval_report.render_markdown(rows, meta))
        print("wrote %s" % report.relative_to(REPO) if report.is_relative_to(REPO) else report)
    if csv:
        crossval_report.write_csv(rows, csv)
        print("wrote %s" % csv.relative_to(REPO) if csv.is_relative_to(REPO) else csv)
    core_rows = [r for r in rows if not r["extra"]]
    failed = [r for r in core_rows if r["result"] == "FAIL"]
    passed = [r for r in core_rows if r["result"] == "PASS"]
    # the closing line CI reads: models matched, models failed, models without a reference
    print("crossval: %d passed, %d failed, %d skipped" % (len(passed), len(failed), len(core_rows) - len(passed) - len(failed)))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
