"""The three engines of the cross-validation harness, each evaluating a batch of canonical states
(see crossval_common.py): lagrange (one `lagrange eval` process per model), MuJoCo and Pinocchio
(Python bindings). Every conversion between an engine's coordinates and the canonical ones lives
here; validation/README.md ("Cross-validation") states them.
"""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from crossval_common import (
    KIND_DIMS,
    EngineRun,
    Layout,
    Result,
    Slot,
    State,
    layout_from_slots,
    quat_wxyz_to_mat,
)

GRAVITY_URDF = np.array([0.0, 0.0, -9.81])


def first_line(text: str, limit: int = 400) -> str:
    lines = [l.strip() for l in str(text).strip().splitlines() if l.strip()]
    # MuJoCo and lagrange put the useful part first; Pinocchio's C++ exceptions start with
    # "From file: ...", "in function: ...", "at line: ...", then "message:" and the message.
    if "message:" in lines:
        lines = lines[lines.index("message:") + 1 :] or lines
    useful = [l for l in lines if not l.lower().startswith(("from file", "in function", "at line"))]
    line = " | ".join((useful or lines)[:2]) if lines else repr(text)
    return line if len(line) <= limit else line[: limit - 1] + "…"


# ---------------------------------------------------------------------------------------------
# URDF text helpers (layout in lagrange's documented order, ranges, leaves)
# ---------------------------------------------------------------------------------------------


class UrdfInfo:
    """Links, joints and the depth-first file-order joint layout of a URDF (lagrange's order),
    parsed with ElementTree independently of every engine."""

    def __init__(self, path: Path, floating: bool):
        root = ET.parse(path).getroot()
        self.links = [l.get("name") for l in root.findall("link")]
        joints = root.findall("joint")
        children: dict[str, list[ET.Element]] = {}
        child_links = set()
        self.ranges: dict[str, tuple[float, float]] = {}
        for j in joints:
            parent = j.find("parent").get("link")
            child = j.find("child").get("link")
            children.setdefault(parent, []).append(j)
            child_links.add(child)
            lim = j.find("limit")
            if j.get("type") in ("revolute", "prismatic") and lim is not None:
                try:
                    lo, hi = float(lim.get("lower", "nan")), float(lim.get("upper", "nan"))
                    if lo < hi:
                        self.ranges[j.get("name")] = (lo, hi)
                except ValueError:
                    pass
        self.parent = {j.find("child").get("link"): j.find("parent").get("link") for j in joints}
        roots = [l for l in self.links if l not in child_links]
        self.root = roots[0] if len(roots) == 1 else None
        self.leaves = [l for l in self.links if l not in children]
        slots: list[Slot] = []
        qa = va = 0

        def add(name, kind, body):
            nonlocal qa, va
            nq, nv = KIND_DIMS[kind]
            slots.append(Slot(name, kind, body, qa, va, nq, nv, self.ranges.get(name)))
            qa += nq
            va += nv

        if self.root is not None:
            if floating:
                add("root_joint", "free", self.root)
            kinds = {"revolute": "hinge", "continuous": "hinge", "prismatic": "slide",
                     "floating": "free", "planar": "planar"}

            def visit(link, depth=0):
                if depth > 1000:
                    raise ValueError("URDF tree too deep (cycle?)")
                for j in children.get(link, []):
                    t = j.get("type")
                    if t in kinds:
                        add(j.get("name"), kinds[t], j.find("child").get("link"))
                    visit(j.find("child").get("link"), depth + 1)

            visit(self.root)
        self.layout = layout_from_slots(slots, "URDF file order")

    def depth(self, link: str) -> int:
        d = 0
        while link in self.parent and d <= len(self.links):
            link, d = self.parent[link], d + 1
        return d


# ---------------------------------------------------------------------------------------------
# lagrange
# ---------------------------------------------------------------------------------------------

LAGRANGE_KINDS = {"revolute": "hinge", "continuous": "hinge", "prismatic": "slide", "free": "free",
                  "ball": "ball", "planar": "planar"}


class Lagrange:
    def __init__(self, binary: Path, timeout: float):
        self.binary = binary
        self.timeout = timeout
        # Models lagrange refuses for non-physical inertia load with the documented opt-in flag
        # (`--accept-nonphysical-inertia`, Pinocchio's behaviour); the report says which.
        self.accepting: set[str] = set()

    def _args(self, entry) -> list[str]:
        args = []
        for d in entry.package_dirs:
            args += ["--package-dir", str(d)]
        if entry.floating:
            args.append("--floating")
        if str(entry.path) in self.accepting:
            args.append("--accept-nonphysical-inertia")
        return args

    def _run(self, args: list[str]) -> subprocess.CompletedProcess:
        return subprocess.run(
            [str(self.binary), *args], capture_output=True, text=True, timeout=self.timeout
        )

    def info(self, entry) -> EngineRun:
        run = EngineRun("lagrange", "not-run")
        t0 = time.perf_counter()
        try:
            p = self._run(["info", str(entry.path), "--json", *self._args(entry)])
        except subprocess.TimeoutExpired:
            run.status, run.detail = "load-error", "info timed out after %gs" % self.timeout
            return run
        run.seconds = time.perf_counter() - t0
        if p.returncode != 0 and "--accept-nonphysical-inertia" in p.stderr and str(entry.path) not in self.accepting:
            self.accepting.add(str(entry.path))
            retry = self.info(entry)
            if retry.status == "ok":
                retry.note = ("loaded with --accept-nonphysical-inertia (lagrange refuses it by default): "
                              + re.sub(r"/\S*?/site-packages/", "site-packages/", first_line(p.stderr)))
            return retry
        if p.returncode != 0:
            run.status = "load-error"
            msg = first_line(p.stderr or p.stdout)
            msg = msg.replace(str(entry.path), entry.path.name)
            msg = re.sub(r"/\S*?/site-packages/", "site-packages/", msg)
            run.detail = re.sub(r"^error:\s*", "", msg)
            return run
        try:
            info = json.loads(p.stdout)
        except json.JSONDecodeError as e:
            run.status, run.detail = "load-error", "info --json printed invalid JSON: %s" % e
            return run
        slots = []
        for j in info["joints"]:
            kind = LAGRANGE_KINDS.get(j["type"])
            if kind is None:
                run.status, run.detail = "incomparable", "unknown joint type %r" % j["type"]
                return run
            slots.append(Slot(j["name"], kind, j.get("child", ""), j["qposadr"], j["dofadr"], j["nq"], j["nv"]))
        run.layout = Layout(slots, info["nq"], info["nv"], "lagrange")
        run.status = "ok"
        run.info = info  # type: ignore[attr-defined]
        return run

    def evaluate(self, entry, run: EngineRun, states: list[State], jac_frames: list[str]) -> None:
        """Runs ONE `lagrange eval` process for all states; fills run.results."""
        doc = {"states": [{"q": s.q.tolist(), "v": s.v.tolist(), "tau": s.tau.tolist()} for s in states]}
        with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
            json.dump(doc, f)
            states_file = f.name
        t0 = time.perf_counter()
        try:
            frames = list(jac_frames)
            for attempt in range(2):
                # The corpus comparison is of smooth dynamics (M, bias, ABA, poses, Jacobians) at
                # random, often self-penetrating states: contacts are off, as on MuJoCo's side, and
                # the pipeline is not evaluated (--kernels-only: models accepted with non-physical
                # inertia have kernels to compare but no finite pipeline).
                args = ["eval", str(entry.path), "--states", states_file, "--json", "--disable", "contact",
                        "--kernels-only", *self._args(entry)]
                for fr in frames:
                    args += ["--jacobian", fr]
                try:
                    p = self._run(args)
                except subprocess.TimeoutExpired:
                    run.status, run.detail = "eval-error", "eval timed out after %gs" % self.timeout
                    return
                if p.returncode == 0:
                    break
                m = re.search(r"--jacobian (.+?): the model has no frame", p.stderr)
                if m and attempt == 0:
                    # a leaf body the reference has but lagrange does not: reported by the pose
                    # comparison; evaluate the Jacobians of the others
                    frames = [fr for fr in frames if fr != m.group(1)]
                    continue
                run.status, run.detail = "eval-error", first_line(p.stderr or p.stdout)
                return
        finally:
            os.unlink(states_file)
        run.seconds += time.perf_counter() - t0
        try:
            out = json.loads(p.stdout)["results"]
        except (json.JSONDecodeError, KeyError) as e:
            run.status, run.detail = "eval-error", "eval printed invalid JSON: %s" % e
            return
        mass = float(run.info["total_mass"])  # type: ignore[attr-defined]
        nv = run.layout.nv
        for r in out:
            poses = {
                name: (np.array(p_["pos"], dtype=float), quat_wxyz_to_mat(p_["quat"]))
                for name, p_ in r["poses"].items()
            }
            # MJCF sites have their own namespace: keyed "site:<name>" as in MuJoCo's results
            for name, p_ in r.get("sites", {}).items():
                poses["site:" + name] = (np.array(p_["pos"], dtype=float), quat_wxyz_to_mat(p_["quat"]))
            jac = {name: np.array(J, dtype=float).reshape(6, nv) for name, J in r.get("jacobians", {}).items()}
            run.results.append(
                Result(
                    M=np.array(r["M"], dtype=float).reshape(nv, nv),
                    bias=np.array(r["bias"], dtype=float),
                    # Left out where M is singular at the state (`qacc_error`): NaN, as the
                    # references' undefined M⁻¹(τ − bias), which the ABA comparison then skips.
                    qacc=np.array(r["qacc"], dtype=float) if "qacc" in r else np.full(nv, np.nan),
                    poses=poses,
                    jac=jac,
                    kinetic=float(r["kinetic"]),
                    potential=float(r["potential"]),
                    com=np.array(r["com"], dtype=float),
                    mass=mass,
                )
            )
        if run.results:
            run.bodies = sorted(run.results[0].poses)


# ---------------------------------------------------------------------------------------------
# Name matching between the canonical layout and a reference
# ---------------------------------------------------------------------------------------------


def index_maps(canon: Layout, mapping: dict[str, Slot]) -> tuple[np.ndarray, np.ndarray]:
    """Canonical q and v indices → the other engine's, from the slot mapping of `match_slots`."""
    qmap = np.zeros(canon.nq, dtype=int)
    vmap = np.zeros(canon.nv, dtype=int)
    for c in canon.slots:
        r = mapping[c.name]
        qmap[c.qadr : c.qadr + c.nq] = range(r.qadr, r.qadr + r.nq)
        vmap[c.vadr : c.vadr + c.nv] = range(r.vadr, r.vadr + r.nv)
    return qmap, vmap


def match_slots(canon: Layout, ref_slots: list[Slot], aliases=None) -> tuple[dict[str, Slot], str]:
    """Maps each canonical joint to the reference joint of the same name (or an alias) and kind.
    Returns the map and, if the joint sets differ, a description of the difference."""
    by_name = {s.name: s for s in ref_slots}
    out: dict[str, Slot] = {}
    problems = []
    used = set()
    for c in canon.slots:
        r = by_name.get(c.name)
        if r is None and aliases is not None:
            r = aliases(c, by_name)
        if r is None:
            problems.append("no joint '%s'" % c.name)
            continue
        if r.kind != c.kind:
            problems.append("joint '%s' is %s, not %s" % (c.name, r.kind, c.kind))
            continue
        out[c.name] = r
        used.add(r.name)
    extra = [s.name for s in ref_slots if s.name not in used]
    if extra:
        problems.append("extra joints %s" % ", ".join("'%s'" % e for e in extra[:6]) + (" …" if len(extra) > 6 else ""))
    if problems:
        return out, "; ".join(problems[:4]) + (" (+%d more)" % (len(problems) - 4) if len(problems) > 4 else "")
    return out, ""


# ---------------------------------------------------------------------------------------------
# MuJoCo
# ---------------------------------------------------------------------------------------------


def urdf_for_mujoco(path: Path, package_dirs: list[Path]) -> str:
    """The URDF text MuJoCo is given: `package://` URIs rewritten to absolute paths, every
    <visual>/<collision> removed (MuJoCo does not decode .dae meshes, and geometry does not enter
    M, bias or ABA once inertia comes from <inertial> only), and a <mujoco><compiler> block that
    keeps every link as a body (fusestatic="false"), takes inertia from <inertial> only
    (inertiafromgeom="false") and leaves inertias untouched (balanceinertia="false")."""
    text = path.read_text()

    def resolve(m):
        rel = m.group(1).lstrip("/")
        pkg, _, rest = rel.partition("/")
        for d in package_dirs:
            for cand in (Path(d) / pkg / rest, Path(d) / rest if Path(d).name == pkg else None):
                if cand is not None and cand.exists():
                    return str(cand)
        return m.group(0)

    text = re.sub(r"package://([^\"'<>\s]+)", resolve, text)
    root = ET.fromstring(text)
    for link in root.findall("link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
    for e in root.findall("mujoco"):
        root.remove(e)
    mj = ET.SubElement(root, "mujoco")
    ET.SubElement(mj, "compiler", fusestatic="false", inertiafromgeom="false", balanceinertia="false",
                  discardvisual="false", strippath="false")
    return ET.tostring(root, encoding="unicode")


MJ_KINDS = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}


class MuJoCo:
    name = "mujoco"

    def __init__(self):
        import mujoco

        self.mj = mujoco
        self.version = mujoco.__version__

    def load(self, entry) -> EngineRun:
        mj = self.mj
        run = EngineRun("mujoco", "not-run")
        t0 = time.perf_counter()
        try:
            if entry.fmt == "urdf":
                urdf = UrdfInfo(entry.path, entry.floating)
                spec = mj.MjSpec.from_string(urdf_for_mujoco(entry.path, entry.package_dirs))
                if entry.floating:
                    if urdf.root == "world":
                        run.status = "incomparable"
                        run.detail = "the URDF root link is 'world', which MuJoCo makes its world body: it cannot float"
                        return run
                    roots = [b for b in spec.worldbody.bodies]
                    if len(roots) != 1:
                        run.status, run.detail = "incomparable", "URDF import gave %d root bodies" % len(roots)
                        return run
                    roots[0].add_freejoint(name="root_joint")
                m = spec.compile()
            else:
                m = mj.MjModel.from_xml_path(str(entry.path))
        except Exception as e:  # MuJoCo raises ValueError with the compiler's message
            run.status, run.detail = "load-error", first_line(e)
            run.seconds = time.perf_counter() - t0
            return run
        run.seconds = time.perf_counter() - t0
        # Pure rigid-body dynamics: no constraints, springs, dampers, actuators, fluid forces.
        D = mj.mjtDisableBit
        for bit in ("mjDSBL_CONSTRAINT", "mjDSBL_EQUALITY", "mjDSBL_FRICTIONLOSS", "mjDSBL_LIMIT",
                    "mjDSBL_CONTACT", "mjDSBL_SPRING", "mjDSBL_DAMPER", "mjDSBL_ACTUATION"):
            m.opt.disableflags |= int(getattr(D, bit))
        m.opt.enableflags |= int(mj.mjtEnableBit.mjENBL_ENERGY)
        m.opt.density = 0.0
        m.opt.viscosity = 0.0
        self.m = m
        self.d = mj.MjData(m)
        slots = []
        for j in range(m.njnt):
            kind = MJ_KINDS[int(m.jnt_type[j])]
            name = m.joint(j).name or "joint%d" % j
            bid = int(m.jnt_bodyid[j])
            rng = None
            if kind in ("hinge", "slide") and m.jnt_limited[j]:
                rng = (float(m.jnt_range[j][0]), float(m.jnt_range[j][1]))
            nq, nv = KIND_DIMS[kind]
            slots.append(Slot(name, kind, self.body_name(bid), int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j]), nq, nv, rng))
        run.layout = Layout(slots, m.nq, m.nv, "mujoco")
        run.bodies = [self.body_name(i) for i in range(m.nbody)]
        run.sites = ["site:" + m.site(i).name for i in range(m.nsite) if m.site(i).name]
        has_child = set(int(p) for p in m.body_parentid[1:])
        def depth(i):
            d = 0
            while i != 0:
                i, d = int(m.body_parentid[i]), d + 1
            return d

        # a body moves when it or an ancestor has degrees of freedom; the others (welded to the
        # world, and mocap bodies, which MuJoCo moves only kinematically) are static
        self.moving = np.zeros(m.nbody, dtype=bool)
        for i in range(1, m.nbody):
            self.moving[i] = int(m.body_dofnum[i]) > 0 or self.moving[int(m.body_parentid[i])]
        leaves = [i for i in range(1, m.nbody) if i not in has_child and self.moving[i]]
        run.leaves = [self.body_name(i) for i in sorted(leaves, key=lambda i: -depth(i))]
        run.status = "ok"
        return run

    def body_name(self, i: int) -> str:
        return self.m.body(i).name or "body%d" % i

    def evaluate(self, run: EngineRun, canon: Layout, states: list[State], jac_frames: list[str]) -> None:
        mj, m, d = self.mj, self.m, self.d
        mapping, problem = match_slots(canon, run.layout.slots)
        if problem:
            run.status, run.detail = "incomparable", "joints differ from lagrange's: " + problem
            return
        # canonical index -> MuJoCo index
        qmap, vmap = index_maps(canon, mapping)
        moving = self.moving
        static = [i for i in range(1, m.nbody) if not moving[i]]
        body_ids = {self.body_name(i): i for i in range(m.nbody)}
        site_ids = {m.site(i).name: i for i in range(m.nsite) if m.site(i).name}
        nv = m.nv
        for s in states:
            d.qpos[:] = m.qpos0
            d.qpos[qmap] = s.q
            d.qvel[:] = 0.0
            d.qvel[vmap] = s.v
            d.ctrl[:] = 0.0
            d.qfrc_applied[:] = 0.0
            d.xfrc_applied[:] = 0.0
            mj.mj_forward(m, d)
            M = np.zeros((nv, nv))
            mj.mj_fullM(m, d, M)
            bias = d.qfrc_bias.copy()
            tau = np.zeros(nv)
            tau[vmap] = s.tau
            qacc = np.zeros((1, nv))
            if nv:
                mj.mj_solveM(m, d, qacc, (tau - bias).reshape(1, nv).copy())
            poses = {}
            for name, i in body_ids.items():
                poses[name] = (d.xpos[i].copy(), d.xmat[i].reshape(3, 3).copy())
            for name, i in site_ids.items():
                poses["site:" + name] = (d.site_xpos[i].copy(), d.site_xmat[i].reshape(3, 3).copy())
            jac = {}
            for fr in jac_frames:
                jp = np.zeros((3, nv))
                jr = np.zeros((3, nv))
                if fr not in body_ids:
                    continue
                mj.mj_jacBody(m, d, jp, jr, body_ids[fr])
                jac[fr] = np.vstack([jp, jr])[:, vmap]
            # Moving bodies only (lagrange's and Pinocchio's convention): mj_energyPos and
            # subtree_com[0] also count bodies welded to the world; take those out.
            g = m.opt.gravity
            v_static = sum(-m.body_mass[i] * float(g @ d.xipos[i]) for i in static)
            mass = float(np.sum(m.body_mass[moving]))
            com = (m.body_mass[moving] @ d.xipos[moving]) / mass if mass > 0 else np.zeros(3)
            run.results.append(
                Result(
                    M=M[np.ix_(vmap, vmap)],
                    bias=bias[vmap],
                    qacc=qacc[0][vmap],
                    poses=poses,
                    jac=jac,
                    kinetic=float(d.energy[1]),
                    potential=float(d.energy[0] - v_static),
                    com=np.asarray(com),
                    mass=mass,
                )
            )
            if nv:
                run.cond_M = max(np.nan_to_num(run.cond_M, nan=0.0), float(np.linalg.cond(M)))


# ---------------------------------------------------------------------------------------------
# Pinocchio
# ---------------------------------------------------------------------------------------------


class Pinocchio:
    name = "pinocchio"

    def __init__(self):
        import pinocchio as pin

        self.pin = pin
        self.version = pin.__version__

    def load(self, entry) -> EngineRun:
        pin = self.pin
        run = EngineRun("pinocchio", "not-run")
        t0 = time.perf_counter()
        try:
            if entry.fmt == "urdf":
                if entry.floating:
                    model = pin.buildModelFromUrdf(str(entry.path), pin.JointModelFreeFlyer())
                else:
                    model = pin.buildModelFromUrdf(str(entry.path))
                model.gravity = pin.Motion(GRAVITY_URDF, np.zeros(3))
                # lagrange enforces <mimic> (a constraint row in full coordinates); the comparison
                # uses Pinocchio's full-coordinate model, and records whether Pinocchio's own mimic
                # support refuses the file (e.g. a mimic of an undefined joint).
                if b"<mimic" in entry.path.read_bytes():
                    try:
                        pin.buildModelFromUrdf(str(entry.path), mimic=True)
                    except Exception as e:
                        run.mimic_refusal = first_line(e) or type(e).__name__
            else:
                model = pin.buildModelFromMJCF(str(entry.path))
        except Exception as e:
            run.status, run.detail = "load-error", first_line(e) if str(e) else type(e).__name__
            run.seconds = time.perf_counter() - t0
            return run
        run.seconds = time.perf_counter() - t0
        self.model = model
        self.data = model.createData()
        self.armature = np.array(model.armature, dtype=float).reshape(model.nv)
        self.model_noarm = pin.Model(model)
        self.model_noarm.armature = np.zeros(model.nv)
        self.data_noarm = self.model_noarm.createData()
        # Pinocchio joints: (name, shortname, jid)
        self.joints = [(model.names[j], model.joints[j].shortname(), j) for j in range(1, model.njoints)]
        run.bodies = [f.name for f in model.frames if f.type == pin.FrameType.BODY]
        run.status = "ok"
        return run

    def coordinates(self, canon: Layout, joint_body: dict[str, str] | None = None):
        """Maps the canonical layout onto the loaded Pinocchio model. Returns ``(entries, vmap,
        problem)``: per canonical joint ``(slot, pin jid, idx_q, idx_v, pin nq, kind)``, the
        Pinocchio velocity index of each canonical velocity index, and a description of the
        difference when the joints do not match (then entries and vmap are not usable).
        ``joint_body`` maps joint names to their MJCF body (from MuJoCo): lagrange's layout names
        a multi-joint body's intermediate frames `<body>/<joint>` instead."""
        model = self.model
        canon_by_name = canon.by_name()
        body_of = {c.name: (joint_body or {}).get(c.name, c.body) for c in canon.slots}
        # Expand Pinocchio joints into per-coordinate entries: (canonical slot, pin jid, idx_q,
        # idx_v, pin nq, kind).
        entries = []
        problems = []
        used = set()
        for name, short, jid in self.joints:
            jm = model.joints[jid]
            short = short.replace("JointModel", "")
            if short == "Composite":
                # Pinocchio merges the joints of one MJCF body into `Composite_<first joint>`;
                # the sub-joints follow the file order of that body's joints.
                first = name[len("Composite_"):] if name.startswith("Composite_") else name
                c0 = canon_by_name.get(first)
                if c0 is None:
                    problems.append("composite '%s' matches no joint" % name)
                    continue
                subs = [c for c in canon.slots if body_of[c.name] == body_of[c0.name]]
                if sum(c.nv for c in subs) != jm.nv or any(c.kind not in ("hinge", "slide") for c in subs) \
                        or jm.nq != jm.nv:
                    problems.append("composite '%s' is not the hinge/slide joints of body '%s'" % (name, body_of[c0.name]))
                    continue
                for k, c in enumerate(subs):
                    entries.append((c, jid, jm.idx_q + k, jm.idx_v + k, 1, c.kind))
                    used.add(c.name)
                continue
            if short == "FreeFlyer":
                kind = "free"
            elif short == "Spherical":
                kind = "ball"
            elif short.startswith("RUB") or short == "RevoluteUnboundedUnaligned":
                kind = "hinge"  # nq = 2: [cos, sin]
            elif short.startswith("R") or short == "RevoluteUnaligned":
                kind = "hinge"
            elif short.startswith("P") and short != "Planar" or short == "PrismaticUnaligned":
                kind = "slide"
            else:
                problems.append("joint '%s' of type %s" % (name, short))
                continue
            c = canon_by_name.get(name)
            if c is None and kind == "free" and name.endswith("_free"):
                # Pinocchio names an unnamed MJCF free joint `<body>_free`
                cands = [s for s in canon.slots if s.kind == "free" and body_of[s.name] == name[: -len("_free")]]
                c = cands[0] if len(cands) == 1 else None
            if c is None:
                problems.append("extra joint '%s'" % name)
                continue
            if c.kind != kind:
                problems.append("joint '%s' is %s, not %s" % (name, kind, c.kind))
                continue
            entries.append((c, jid, jm.idx_q, jm.idx_v, jm.nq, kind))
            used.add(c.name)
        missing = [c.name for c in canon.slots if c.name not in used]
        if missing:
            problems.append("no joint %s" % ", ".join("'%s'" % n for n in missing[:6]) + (" …" if len(missing) > 6 else ""))
        if problems or model.nv != canon.nv:
            problem = "joints differ from lagrange's: " + "; ".join(problems[:4]) if problems else \
                "nv %d, lagrange %d" % (model.nv, canon.nv)
            return entries, None, problem
        vmap = np.zeros(model.nv, dtype=int)  # canonical velocity index -> Pinocchio velocity index
        for c, jid, iq, iv, nq, kind in entries:
            for k in range(c.nv):
                vmap[c.vadr + k] = iv + k
        return entries, vmap, ""

    def configuration(self, entries, q) -> tuple[np.ndarray, np.ndarray]:
        """Pinocchio's configuration for the canonical ``q``, and T = blockdiag(R, I) per free
        joint (Pinocchio's velocity order), with canonical v = T v_pin (after permutation)."""
        pin, model = self.pin, self.model
        qp = pin.neutral(model)
        T = np.eye(model.nv)
        for c, jid, iq, iv, nq, kind in entries:
            if kind == "free":
                p = q[c.qadr : c.qadr + 3]
                R = quat_wxyz_to_mat(q[c.qadr + 3 : c.qadr + 7])
                # MuJoCo's free q is the body's world pose; Pinocchio's is relative to the
                # joint placement.
                Mj = model.jointPlacements[jid].inverse() * pin.SE3(R, np.asarray(p))
                qp[iq : iq + 3] = Mj.translation
                qp[iq + 3 : iq + 7] = pin.Quaternion(Mj.rotation).coeffs()  # x y z w
                T[iv : iv + 3, iv : iv + 3] = R
            elif kind == "ball":
                w, x, y, z = q[c.qadr : c.qadr + 4]
                qp[iq : iq + 4] = [x, y, z, w]
            elif nq == 2:
                qp[iq], qp[iq + 1] = math.cos(q[c.qadr]), math.sin(q[c.qadr])
            else:
                qp[iq] = q[c.qadr]
        return qp, T

    @staticmethod
    def free_joint_drift(entries, T, v_pin) -> np.ndarray:
        """c = (dT/dt) v_pin = [R (ω × v_local); 0] per free joint: canonical qacc = T a_pin + c."""
        cvec = np.zeros(len(v_pin))
        for c, jid, iq, iv, nq, kind in entries:
            if kind == "free":
                cvec[iv : iv + 3] = T[iv : iv + 3, iv : iv + 3] @ np.cross(v_pin[iv + 3 : iv + 6], v_pin[iv : iv + 3])
        return cvec

    def evaluate(self, run: EngineRun, canon: Layout, states: list[State], jac_frames: list[str],
                 joint_body: dict[str, str] | None = None) -> None:
        """``joint_body`` maps joint names to their MJCF body (from MuJoCo): lagrange's layout
        names a multi-joint body's intermediate frames `<body>/<joint>` instead."""
        pin, model, data = self.pin, self.model, self.data
        entries, vmap, problem = self.coordinates(canon, joint_body)
        if problem:
            run.status = "incomparable"
            run.detail = problem
            return

        nv = model.nv
        frame_ids = {}
        for name in set(run.bodies) | set(jac_frames):
            if model.existFrame(name, pin.FrameType.BODY):
                frame_ids[name] = model.getFrameId(name, pin.FrameType.BODY)

        for s in states:
            qp, T = self.configuration(entries, s.q)
            Tinv = np.linalg.inv(T)
            v_o = np.zeros(nv)
            v_o[vmap] = s.v
            tau_o = np.zeros(nv)
            tau_o[vmap] = s.tau
            v_pin = Tinv @ v_o
            tau_pin = T.T @ tau_o
            M_pin = np.asarray(pin.crba(model, data, qp)).reshape(nv, nv).copy()
            M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
            b_pin = np.asarray(pin.rnea(model, data, qp, v_pin, np.zeros(nv))).reshape(nv).copy()
            a_pin = np.asarray(pin.aba(model, data, qp, v_pin, tau_pin)).reshape(nv).copy()
            # kinetic energy of the bodies (a copy of the model without armature: Pinocchio's
            # computeKineticEnergy adds the armature term for some joint types and not others)
            # plus the rotor term ½ Σ armature v², as in MuJoCo's ½ vᵀ M v
            kinetic = pin.computeKineticEnergy(self.model_noarm, self.data_noarm, qp, v_pin) + \
                0.5 * float(self.armature @ (v_pin * v_pin))
            potential = pin.computePotentialEnergy(model, data, qp)
            com = pin.centerOfMass(model, data, qp).copy()
            mass = float(data.mass[0])
            cvec = self.free_joint_drift(entries, T, v_pin)
            M_o = Tinv.T @ M_pin @ Tinv
            qacc_o = T @ a_pin + cvec
            bias_o = Tinv.T @ b_pin - M_o @ cvec
            pin.forwardKinematics(model, data, qp)
            pin.updateFramePlacements(model, data)
            poses = {}
            for name, fid in frame_ids.items():
                oMf = data.oMf[fid]
                poses[name] = (oMf.translation.copy(), oMf.rotation.copy())
            jac = {}
            if jac_frames and nv:  # (getFrameJacobian crashes on a model without coordinates)
                pin.computeJointJacobians(model, data, qp)
                for fr in jac_frames:
                    if fr in frame_ids:
                        J = pin.getFrameJacobian(model, data, frame_ids[fr], pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
                        jac[fr] = (np.asarray(J).reshape(6, nv) @ Tinv)[:, vmap]
            run.results.append(
                Result(
                    M=M_o[np.ix_(vmap, vmap)],
                    bias=bias_o[vmap],
                    qacc=qacc_o[vmap],
                    poses=poses,
                    jac=jac,
                    kinetic=float(kinetic),
                    potential=float(potential),
                    com=com,
                    mass=mass,
                )
            )
            if nv:
                run.cond_M = max(np.nan_to_num(run.cond_M, nan=0.0), float(np.linalg.cond(M_o)))
