"""Tables of the cross-validation run: text (stdout), Markdown (validation/report.md), CSV."""

from __future__ import annotations

import csv
import math
import re
import time
from collections import defaultdict
from pathlib import Path

from crossval_common import QUANTITIES, QUANTITY_KEYS, REF_REL

REF_SHORT = {"mujoco": "MJ", "pinocchio": "Pin"}
LOAD_MARK = {"yes": "✓", "no": "✗", "partial": "~", "eval error": "E", "not run": "·", "crash": "C"}


def fmt_err(e, tol=None) -> str:
    if e is None:
        return "–"
    if tol is not None and math.isinf(tol):
        return "n/c"
    if isinstance(e, float) and math.isnan(e):
        return "NaN"
    if e == 0:
        return "0"
    return "%.0e" % e


def loads(row) -> str:
    return "/".join(LOAD_MARK.get(row["load"][k], "?") for k in ("lagrange", "mujoco", "pinocchio"))


def nqnv(row) -> str:
    return "%s/%s" % (row["nq"], row["nv"]) if row["nq"] is not None else "–"


def core(rows):
    return [r for r in rows if not r["extra"]]


def summary(rows, meta) -> dict:
    rs = core(rows)
    s = {
        "models": len(rs),
        "files": len({(r["source"], r["id"].rsplit("@", 1)[0]) for r in rs}),
        "lagrange": sum(r["load"]["lagrange"] == "yes" for r in rs),
        "mujoco": sum(r["load"]["mujoco"] in ("yes",) for r in rs),
        "pinocchio": sum(r["load"]["pinocchio"] in ("yes",) for r in rs),
        "mujoco_any": sum(r["load"]["mujoco"] in ("yes", "partial") for r in rs),
        "pinocchio_any": sum(r["load"]["pinocchio"] in ("yes", "partial") for r in rs),
        "with_reference": sum(bool(r["errors"]) or (r["result"] == "FAIL" and any(
            st in ("ok",) for st in r["status"].values())) for r in rs),
        "compared": sum(bool(r["errors"]) for r in rs),
        "pass": sum(r["result"] == "PASS" for r in rs),
        "fail": sum(r["result"] == "FAIL" for r in rs),
        "no_reference": sum(r["result"] == "no reference" for r in rs),
        "nobody": sum(r["result"] == "nobody loads" for r in rs),
        "rejected": sum(r["result"] == "rejected" for r in rs),
    }
    worst = {}
    for q in QUANTITY_KEYS:
        best = None
        for r in rs:
            for ref, e in r["errors"].items():
                v = e.get(q)
                if v is None or math.isinf(r["tol"][q]):
                    continue
                key = math.inf if math.isnan(v) else v
                if best is None or key > best[0]:
                    best = (key, v, r["name"], ref)
        worst[q] = best
    s["worst"] = worst
    return s


def error_group(msg: str) -> str:
    """A load error without its file, line, names and numbers: groups equal causes."""
    m = msg
    m = re.sub(r"^\S+?:\d+:\s*", "", m)  # file:line:
    m = re.sub(r"'[^']*'", "'…'", m)
    m = re.sub(r"\[[^\]]*\]", "[…]", m)
    m = re.sub(r"\([^)]*\)", "(…)", m)
    m = re.sub(r"-?\d+(\.\d+)?(e-?\d+)?", "N", m)
    m = m.split(";")[0].split(" (")[0].strip()  # the cause, not the advice after it
    return m[:120]


def headline(rows, meta) -> list[str]:
    s = summary(rows, meta)
    lines = [
        "models in the corpus: %d (%d files; each URDF fixed-base and floating)" % (s["models"], s["files"]),
        "loaded by lagrange: %d, by MuJoCo: %d, by Pinocchio: %d (+ partial loads: MuJoCo %d, Pinocchio %d)" % (
            s["lagrange"], s["mujoco"], s["pinocchio"], s["mujoco_any"] - s["mujoco"], s["pinocchio_any"] - s["pinocchio"]),
        "compared with at least one reference: %d; matched within tolerance: %d; FAILED: %d; "
        "lagrange only (no reference loads it): %d; rejected by lagrange and by the reference of its "
        "format: %d; loaded by nobody: %d" % (
            s["compared"], s["pass"], s["fail"], s["no_reference"], s["rejected"], s["nobody"]),
    ]
    rr = [r for r in core(rows) if r["ref_vs_ref"]]
    agree = [r for r in rr if all(r["status"].get(k) == "ok" for k in ("mujoco", "pinocchio"))]
    if rr:
        def worst_rr(r):
            return max((v for q, v in r["ref_vs_ref"].items() if not math.isinf(r["tol"][q]) and not math.isnan(v)),
                       default=0.0)
        w = max(agree, key=worst_rr, default=None)
        lines.append(
            "the references against each other (harness check), where both load the model: agree within "
            "tolerance on %d of %d%s; the other %d are reader differences, listed in the notes" % (
                len(agree), len(rr), (" (worst %.0e, %s)" % (worst_rr(w), w["name"])) if w else "",
                len(rr) - len(agree)))
    worst = []
    for q, title in QUANTITIES:
        w = s["worst"][q]
        if w is not None:
            worst.append("%s %s (%s vs %s)" % (title, fmt_err(w[1]) if w[1] != 0 else "0", w[2], REF_REL_NAME(w[3])))
    lines.append("worst errors: " + "; ".join(worst))
    extra = [r for r in rows if r["extra"]]
    if extra:
        lines.append("extra group (not counted above, never fails the run): %d models, lagrange loads %d, "
                     "matched %d, differ or do not load %d" % (
                         len(extra), sum(r["load"]["lagrange"] == "yes" for r in extra),
                         sum(r["result"] == "PASS" for r in extra), sum(r["result"] == "FAIL" for r in extra)))
    lines.append("run time %.0f s with %d jobs" % (meta["seconds"], meta["jobs"]))
    return lines


def REF_REL_NAME(ref: str) -> str:
    return {"mujoco": "MuJoCo", "pinocchio": "Pinocchio"}.get(ref, ref)


def render_text(rows, meta) -> str:
    qs = [t for _, t in QUANTITIES]
    w = max(28, min(60, max((len(r["name"]) for r in rows), default=10)))
    head = "%-*s %-8s %-7s %-5s %-3s " % (w, "model", "fmt", "nq/nv", "L/M/P", "ref") + " ".join(
        "%-6s" % t for t in qs) + "  result"
    out = [head, "-" * len(head)]
    for r in rows:
        refs = [k for k in ("mujoco", "pinocchio") if k in r["errors"]] or [None]
        for i, ref in enumerate(refs):
            cells = " ".join("%-6s" % fmt_err(r["errors"][ref][q], r["tol"][q]) if ref else "%-6s" % "–"
                             for q in QUANTITY_KEYS)
            out.append("%-*s %-8s %-7s %-5s %-3s %s  %s" % (
                w, r["name"] if i == 0 else "", (r["fmt"] + ("/float" if r["floating"] else "")) if i == 0 else "",
                nqnv(r) if i == 0 else "", loads(r) if i == 0 else "", REF_SHORT.get(ref, "–"), cells,
                r["result"] if i == 0 else ""))
    out.append("")
    out.append("L/M/P: loads in lagrange / MuJoCo / Pinocchio (✓ yes, ✗ no, ~ loads but not comparable, "
               "E lagrange eval error, C crashed); errors are max relative errors over the states; "
               "n/c: not compared (see the report's loosened tolerances).")
    fails = [r for r in rows if r["result"] == "FAIL"]
    if fails:
        out.append("")
        out.append("FAILURES:")
        for r in fails:
            out.append("  %s: %s" % (r["name"], "; ".join(r["notes"][:3])))
            if "lagrange" in r["load_detail"]:
                out.append("      lagrange: %s" % r["load_detail"]["lagrange"])
    out.append("")
    out += headline(rows, meta)
    return "\n".join(out)


def md_escape(s: str) -> str:
    return str(s).replace("|", "\\|").replace("\n", " ")


def render_markdown(rows, meta) -> str:
    s = summary(rows, meta)
    L = []
    L.append("# Cross-validation report")
    L.append("")
    L.append("Generated by `validation/crossval` on %s — lagrange `%s`%s, MuJoCo %s, Pinocchio %s; "
             "%d random states per model (seed %d); %.0f s on %d jobs." % (
                 time.strftime("%Y-%m-%d"), meta["commit"], " (+ uncommitted src changes)" if meta["dirty"] else "",
                 meta["mujoco"], meta["pinocchio"], meta["states"], meta["seed"], meta["seconds"], meta["jobs"]))
    L.append("")
    L.append("## Summary")
    L.append("")
    for line in headline(rows, meta):
        L.append("- " + line)
    L.append("")
    L.append("| quantity | worst relative error | model | reference |")
    L.append("| --- | --- | --- | --- |")
    for q, title in QUANTITIES:
        w = s["worst"][q]
        if w is None:
            L.append("| %s | – | – | – |" % title)
        else:
            L.append("| %s | %s | %s | %s |" % (title, "%.2e" % w[1] if w[1] else "0", md_escape(w[2]), REF_REL_NAME(w[3])))
    L.append("")
    L.append("## How to read this")
    L.append("")
    L.append("- Relative error of a quantity in one state: `‖a − b‖∞ / max(‖a‖∞, ‖b‖∞, 1e-300)` (the definition "
             "of `tests/common/mod.rs`), a = lagrange, b = the reference; each cell is the maximum over the states. "
             "Tolerance %.0e unless the model lists a measured reason below." % REF_REL)
    L.append("- `M` mass matrix (with armature), `bias` = RNEA(q, v, 0), `ABA` forward dynamics M⁻¹(τ − bias), "
             "`poses` world position and rotation matrix of every body (MuJoCo bodies, URDF links, by name), "
             "`Jac` 6×nv world-aligned Jacobians of up to 4 end frames (leaf bodies), `mass`/`com` of the moving "
             "bodies, `T` kinetic and `V` potential energy (moving bodies, zero at the world origin).")
    L.append("- Cells read `vs MuJoCo · vs Pinocchio`; `–`: not compared. Loads: lagrange / MuJoCo / Pinocchio, "
             "✓ loads, ✗ does not, ~ loads but is not comparable (different joints) or disagrees with the "
             "reference whose own format this is (see the notes), E lagrange loads but `eval` fails.")
    L.append("- The reference whose own format it is (Pinocchio for URDF, MuJoCo for MJCF) always counts; the "
             "other counts when it agrees with the first to the tolerance (MuJoCo's URDF import and Pinocchio's "
             "MJCF reader are partial).")
    L.append("- Results: PASS; FAIL (a counted reference loads it and lagrange does not, or an error is above tolerance, "
             "or a reference body has no lagrange frame); `no reference` (lagrange loads it, no reference "
             "does); `rejected` (the reference of the file's own format rejects it and so does lagrange, "
             "though the other reference loads it); `nobody loads`.")
    L.append("")

    fails = [r for r in core(rows) if r["result"] == "FAIL"]
    if fails:
        L.append("## Failures (%d)" % len(fails))
        L.append("")
        groups = defaultdict(list)
        for r in fails:
            if r["load"]["lagrange"] != "yes" and "lagrange" in r["load_detail"]:
                groups["lagrange cannot load: " + error_group(r["load_detail"]["lagrange"])].append(r)
            else:
                groups["differs: " + ", ".join(sorted({n.split(" vs ")[0] for n in r["notes"] if " vs " in n}) or ["other"])].append(r)
        for g, rs in sorted(groups.items(), key=lambda kv: -len(kv[1])):
            L.append("### %s (%d)" % (md_escape(g), len(rs)))
            L.append("")
            for r in rs:
                detail = r["load_detail"].get("lagrange") if r["load"]["lagrange"] != "yes" else "; ".join(r["notes"][:3])
                L.append("- `%s`: %s" % (r["name"], md_escape(detail)))
            L.append("")

    loosened = [r for r in core(rows) if r["tol_reasons"]]
    L.append("## Loosened tolerances (%d)" % len(loosened))
    L.append("")
    if not loosened:
        L.append("None: every compared model is held to %.0e." % REF_REL)
    for r in loosened:
        conds = ", ".join("cond(M) %s %.2e" % (REF_REL_NAME(k), v) for k, v in r["cond_M"].items())
        L.append("- `%s`: %s (measured: %s)" % (r["name"], md_escape("; ".join(r["tol_reasons"])), conds or "–"))
    L.append("")

    for source in dict.fromkeys(r["source"] for r in rows):
        rs = [r for r in rows if r["source"] == source]
        L.append("## %s (%d)" % (source, len(rs)))
        L.append("")
        L.append("| model | nq/nv | loads | " + " | ".join(t for _, t in QUANTITIES) + " | result |")
        L.append("| --- | --- | --- | " + " | ".join("---" for _ in QUANTITIES) + " | --- |")
        for r in rs:
            cells = []
            for q in QUANTITY_KEYS:
                parts = [fmt_err(r["errors"][ref][q], r["tol"][q]) if ref in r["errors"] else "–"
                         for ref in ("mujoco", "pinocchio")]
                cells.append(" · ".join(parts))
            L.append("| %s | %s | %s | %s | %s |" % (md_escape(r["name"]), nqnv(r), loads(r), " | ".join(cells), r["result"]))
        L.append("")

    L.append("## Notes per model")
    L.append("")
    L.append("Load errors of each engine, references that are not comparable or disagree, and what failed.")
    L.append("")
    for r in rows:
        items = []
        for k in ("lagrange", "mujoco", "pinocchio"):
            if k in r["load_detail"]:
                items.append("%s: %s" % (k, r["load_detail"][k]))
        items += [n for n in r["notes"] if n not in items]
        if items:
            L.append("- `%s` (%s):" % (r["name"], r["result"]))
            for it in items:
                L.append("  - %s" % md_escape(it))
    L.append("")

    # lagrange load errors grouped by cause
    groups = defaultdict(list)
    for r in core(rows):
        if r["load"]["lagrange"] != "yes" and "lagrange" in r["load_detail"]:
            groups[error_group(r["load_detail"]["lagrange"])].append(r["name"])
    if groups:
        L.append("## lagrange load errors by cause")
        L.append("")
        for g, names in sorted(groups.items(), key=lambda kv: -len(kv[1])):
            L.append("- %s — %d: %s" % (md_escape(g), len(names), ", ".join("`%s`" % n for n in names)))
        L.append("")
    return "\n".join(L)


def write_csv(rows, path: Path) -> None:
    cols = ["model", "source", "format", "base", "nq", "nv", "loads_lagrange", "loads_mujoco", "loads_pinocchio",
            "reference", "reference_status"] + QUANTITY_KEYS + ["cond_M", "tolerance", "result", "seconds", "notes"]
    tmp = path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in rows:
            refs = [k for k in ("mujoco", "pinocchio")]
            for ref in refs:
                errs = r["errors"].get(ref, {})
                w.writerow([
                    r["name"], r["source"], r["fmt"], ("floating" if r["floating"] else "fixed") if r["fmt"] == "urdf" else "",
                    r["nq"] if r["nq"] is not None else "", r["nv"] if r["nv"] is not None else "",
                    r["load"]["lagrange"], r["load"]["mujoco"], r["load"]["pinocchio"],
                    ref, r["status"].get(ref, ""),
                    *[("%.3e" % errs[q]) if q in errs else "" for q in QUANTITY_KEYS],
                    ("%.3e" % r["cond_M"][ref]) if ref in r["cond_M"] else "",
                    ";".join("%s=%.0e" % (q, t) for q, t in r["tol"].items() if t != REF_REL) or "%.0e" % REF_REL,
                    r["result"], "%.2f" % r.get("seconds", 0.0),
                    " | ".join([("%s: %s" % (k, v)) for k, v in r["load_detail"].items()] + r["notes"]),
                ])
    tmp.replace(path)
