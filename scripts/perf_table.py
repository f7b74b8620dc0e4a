#!/usr/bin/env python3
"""Turns nhdyn_bench's JSON (Google Benchmark, --benchmark_repetitions=N with aggregates)
into the tables of docs/performance.md and the plot docs/performance_scaling.png.

Usage: perf_table.py BENCH.json DOC.md PLOT.png [--cpu "model name"] [--compiler "g++ ..."]

The generated part of DOC.md lies between the markers
    <!-- BEGIN GENERATED: scripts/bench.sh -->  and  <!-- END GENERATED -->
and is replaced; the rest of the file is kept. Every number is a median over the
repetitions of CPU time per call (ns), taken from the JSON, never typed in by hand.
"""
import argparse
import datetime
import json
import math
import re
import statistics
import sys

BEGIN = "<!-- BEGIN GENERATED: scripts/bench.sh -->"
END = "<!-- END GENERATED -->"

RNE_MODELS = ["paper5", "puma560", "rev6", "rev12", "rev24", "rev48", "rev96"]
NH_MODELS = ["paper5", "ddrive_arm2", "ddrive_arm4", "ddrive_arm8", "ddrive_arm16",
             "ddrive_arm24", "ddrive_arm48"]
DOF = {"paper5": 5, "puma560": 6, "rev6": 6, "rev12": 12, "rev24": 24, "rev48": 48,
       "rev96": 96}
for a in (2, 4, 8, 16, 24, 48):
    DOF[f"ddrive_arm{a}"] = 3 + a
SCENE_VARIANTS = [
    ("full", "everything (gravity, velocity terms, τ only), compile-time sized"),
    ("no_gravity", "gravity off"),
    ("no_velocity", "velocity terms off (C(q, q̇)q̇ dropped)"),
    ("no_gravity_no_velocity", "gravity and velocity terms off (M_η η̇ only)"),
    ("with_constraint_forces", "τ and the constraint forces λ (inverse_dynamics_with_forces)"),
    ("run_time_sized", "run-time-sized chain and constraint"),
    ("no_massless_links", "base links 1–2 given 1 kg (no massless link to skip)"),
    ("half_arm_massless", "every other arm link massless (skipped)"),
]
TARGET_FIXED, TARGET_DYN, TARGET_NH = 0.25, 0.35, 1.3
TREE_MODELS = ["mobile_manipulator", "powered_castors_arm", "tiago_style", "tree12", "tree24", "tree48", "tree96"]
TREE_BODIES = {"mobile_manipulator": 16, "powered_castors_arm": 16, "tiago_style": 56, "tree12": 12, "tree24": 24,
               "tree48": 48, "tree96": 96}
TARGET_CRBA = 0.6  # CRBA ≤ 0.6× one rne of the same tree and state, paired (issue 33)
CLANG_TREES = ["mobile_manipulator", "tree12", "tree24", "tree48"]  # the trees of the clang comparison (issue 33)
TARGET_TREE = 0.25
WHEELED = [("mobile_manipulator_ddrive", 1), ("mobile_manipulator_wheels", 3), ("mobile_manipulator_bicycle", 2)]
# every wheeled base (issue 31): (robot, n, k, m, p)
WHEEL_BASES = [("mecanum_arm", 12, 4, 8, 9), ("omni3_arm", 11, 3, 8, 8), ("castor_drive_arm", 15, 7, 8, 8),
               ("powered_castors_arm", 19, 8, 11, 16), ("mobile_manipulator_castors", 19, 7, 12, 12),
               ("mobile_manipulator_wheels_as_wheeled_base", 19, 3, 16, 16)]
TARGET_WHEEL_NH, TARGET_WHEEL_EL = 1.5, 20


DERIV_MODELS = ["paper5", "puma560", "mobile_manipulator", "tree12", "tree24", "tree48", "tree96"]
DERIV_NH_MODELS = ["paper5", "mobile_manipulator_ddrive", "mobile_manipulator_wheels", "mobile_manipulator_bicycle"]
DERIV_FD_MODELS = ["paper5", "puma560", "tree12", "tree24", "tree48", "tree96"]
# shown, but outside the derivative targets' models (issue 18: random trees of 12–48 bodies):
# the outputs (∂τ/∂q, M⁻¹, ∂q̈/∂q) grow as n², one call as n
BEYOND_DERIV_TARGETS = {"tree96"}
TARGET_DERIV, TARGET_DERIV_NH, TARGET_DERIV_FD = 3.0, 3.5, 5.0
BATCH_MODELS = ["paper5", "puma560", "mobile_manipulator", "tree12", "tree24", "tree48"]
BATCH_STATES, TARGET_BATCH = 256, 2.5
PAIRED = {}  # every paired case (nh_pair/…, el_pair/…, crba_pair/…) → the median over repetitions (and sittings) of its ratio counter


def load(path):
    with open(path) as f:
        data = json.load(f)
    med, allocs, reps, paired = {}, {}, {}, {}
    for b in data["benchmarks"]:
        name = b.get("run_name", b["name"])
        if b.get("aggregate_name") == "median":
            # a file of several sittings (merge_bench.py --sittings) holds one median per sitting
            med.setdefault(name, []).append(b["cpu_time"] * {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[b["time_unit"]])
            if "allocs_per_call" in b:
                allocs[name] = b["allocs_per_call"]
            if "ratio" in b:  # a paired measurement (nh_pair/…): the median of its ratio counter
                paired.setdefault(name, []).append(b["ratio"])
            reps[name] = b.get("repetitions", 1)
    if not med:
        sys.exit("perf_table.py: no median aggregates in %s (run with --benchmark_repetitions)" % path)
    med = {name: statistics.median(v) for name, v in med.items()}  # over the sittings' medians
    PAIRED.update({name: statistics.median(v) for name, v in paired.items()})  # the same for the paired ratios
    return data["context"], med, allocs, reps


def ns(x):
    if x is None:
        return "—"
    if x >= 1e6:
        return f"{x / 1e6:.2f} ms"
    if x >= 1e4:
        return f"{x / 1e3:.1f} µs"
    return f"{x:.0f}"


def ratio(a, b):
    return None if a is None or b is None else a / b


def r2(x):
    return "—" if x is None else f"{x:.2f}"


def al(x):
    return "—" if x is None else (f"{x:.0f}" if abs(x - round(x)) < 1e-9 else f"{x:.2f}")


def slope(ns_, ts):
    """Least-squares exponent p of t ≈ c·nᵖ."""
    pts = [(math.log(n), math.log(t)) for n, t in zip(ns_, ts) if t]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx


def reruns(ctx):
    """The filtered re-runs merged into the file (scripts/merge_bench.py), oldest first."""
    if "partial_reruns" in ctx:
        return ctx["partial_reruns"]
    return [ctx["partial_rerun"]] if "partial_rerun" in ctx else []


def tables(ctx, med, allocs, reps, cpu, compiler):
    g = med.get
    out = []
    nrep = max(reps.values())
    out.append(f"Measured {ctx.get('date', '?')} on **{cpu}** ({ctx.get('num_cpus', '?')} logical CPUs, "
               f"shared with other jobs), nhdyn compiled by **{compiler}** with "
               f"`{ctx.get('nhdyn_flags', '?')}`; KDL {ctx.get('kdl_flags', '?')}. Every figure is the "
               f"**median of {nrep} repetitions** of the CPU time per call in nanoseconds "
               f"(Google Benchmark `cpu_time`), from `docs/performance.json`.\n")
    for pr in reruns(ctx):  # some cases re-run later by filtered runs, merged by name
        fams = sorted({"/".join(r.split("/")[:1]) for r in pr["run_names"]})
        out[-1] = out[-1].rstrip("\n") + (f" The cases {', '.join(f'`{f}/…`' for f in fams)} were "
                                         f"re-run {pr['date']} (a filtered run, the same binary and flags; "
                                         f"{len(pr['run_names'])} cases), and the ratios among them are of that run.\n")

    # ---------------------------------------------------------------- rne vs KDL
    out.append("### Holonomic rne against Orocos KDL (issue 2)\n")
    out.append("| model | n | nhdyn run-time sized | nhdyn fixed | KDL | run-time / KDL | fixed / KDL "
               "| allocations per call (run-time, fixed, KDL) |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---|")
    worst_fixed = worst_dyn = 0.0
    for m in RNE_MODELS:
        d, f, k = g(f"rne/{m}/nhdyn"), g(f"rne/{m}/nhdyn_fixed"), g(f"rne/{m}/kdl")
        rd, rf = ratio(d, k), ratio(f, k)
        worst_fixed = max(worst_fixed, rf or 0)
        worst_dyn = max(worst_dyn, rd or 0)
        out.append(f"| {m} | {DOF[m]} | {ns(d)} | {ns(f)} | {ns(k)} | {r2(rd)} | {r2(rf)} | "
                   f"{al(allocs.get(f'rne/{m}/nhdyn'))}, {al(allocs.get(f'rne/{m}/nhdyn_fixed'))}, "
                   f"{al(allocs.get(f'rne/{m}/kdl'))} |")
    fixed_allocs = max(allocs.get(f"rne/{m}/nhdyn_fixed", 0) for m in RNE_MODELS)
    out.append("")
    out.append(f"- Target fixed-size ≤ {TARGET_FIXED}× KDL on every model: worst ratio "
               f"**{worst_fixed:.2f}** — {'met' if worst_fixed <= TARGET_FIXED else 'NOT met'}.")
    out.append(f"- Target run-time-sized ≤ {TARGET_DYN}× KDL: worst ratio **{worst_dyn:.2f}** — "
               f"{'met' if worst_dyn <= TARGET_DYN else 'NOT met'}.")
    out.append(f"- Heap allocations per call, fixed-size models: **{al(fixed_allocs)}** (counted, see "
               f"below) — {'met' if fixed_allocs == 0 else 'NOT met'}. The run-time-sized call makes "
               f"exactly one: the returned `Eigen::VectorXd`.")
    ks = [DOF[m] for m in RNE_MODELS if m.startswith("rev")]
    for label, suf in (("nhdyn fixed", "nhdyn_fixed"), ("nhdyn run-time", "nhdyn"), ("KDL", "kdl")):
        ts = [g(f"rne/rev{n}/{suf}") for n in ks]
        out.append(f"- Growth on the revolute chains 6…96, {label}: time ∝ n^{slope(ks, ts):.2f} "
                   f"(least-squares over all sizes), n^{slope(ks[-2:], ts[-2:]):.2f} between the two largest.")
    out.append("")

    # ---------------------------------------------------------------- nh vs holonomic, Lagrange
    out.append("### Nonholonomic inverse dynamics: rne against the holonomic rne and projected Euler–Lagrange (issue 3)\n")
    out.append("Holonomic = `rne/<model>/nhdyn*` on the same chain without the constraint; "
               "nh = `nh_id/<model>/rne*` = project ∘ rne ∘ lift; E–L = `nh_id/<model>/lagrange`.\n")
    out.append("Paired = `nh_pair/<model>/{fixed,run_time}`: the holonomic rne at the lifted state ξ = lift(ζ) and "
               "nh at ζ timed in alternating blocks of 16 calls inside one benchmark (median over the "
               "repetitions of the ratio of their summed times); the other ratios divide medians of "
               "separately run benchmarks.\n")
    out.append("| model | n | holonomic fixed | nh fixed | nh / holonomic (fixed) | paired (fixed) | holonomic run-time | "
               "nh run-time | nh / holonomic (run-time) | paired (run-time) | E–L | E–L / nh run-time | "
               "allocations nh (run-time, fixed) |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    worst_nh_f = worst_nh_d = worst_pf = worst_pd = 0.0
    for m in NH_MODELS:
        hf, nf = g(f"rne/{m}/nhdyn_fixed"), g(f"nh_id/{m}/rne_fixed")
        hd, nd = g(f"rne/{m}/nhdyn"), g(f"nh_id/{m}/rne")
        pf, pd = PAIRED.get(f"nh_pair/{m}/fixed"), PAIRED.get(f"nh_pair/{m}/run_time")
        el = g(f"nh_id/{m}/lagrange")
        worst_nh_f = max(worst_nh_f, ratio(nf, hf) or 0)
        worst_nh_d = max(worst_nh_d, ratio(nd, hd) or 0)
        worst_pf = max(worst_pf, pf or 0)
        worst_pd = max(worst_pd, pd or 0)
        out.append(f"| {m} | {DOF[m]} | {ns(hf)} | {ns(nf)} | {r2(ratio(nf, hf))} | {r2(pf)} | {ns(hd)} | {ns(nd)} | "
                   f"{r2(ratio(nd, hd))} | {r2(pd)} | {ns(el)} | {ratio(el, nd):.0f} | "
                   f"{al(allocs.get(f'nh_id/{m}/rne'))}, {al(allocs.get(f'nh_id/{m}/rne_fixed'))} |")
    out.append("")
    verdict = lambda x: "met" if 0 < x <= TARGET_NH else "NOT met"
    out.append(f"- Target nh ≤ {TARGET_NH}× holonomic rne of the same chain, judged on the paired measurement: "
               f"compile-time sized, worst **{worst_pf:.2f}** — {verdict(worst_pf)}; run-time sized, worst "
               f"**{worst_pd:.2f}** — {verdict(worst_pd)}. Ratios of separately run medians: worst "
               f"{worst_nh_f:.2f} (fixed) and {worst_nh_d:.2f} (run-time).")
    arms = [DOF[m] for m in NH_MODELS if m.startswith("ddrive")]
    for label, key in (("holonomic rne (fixed)", "rne/{}/nhdyn_fixed"), ("nh rne (fixed)", "nh_id/{}/rne_fixed"),
                       ("nh rne (run-time)", "nh_id/{}/rne"), ("projected E–L", "nh_id/{}/lagrange")):
        ts = [g(key.format(f"ddrive_arm{a - 3}")) for a in arms]
        out.append(f"- Growth on the differential-drive arms (n = 5…51), {label}: time ∝ n^{slope(arms, ts):.2f} "
                   f"(least-squares over all sizes), n^{slope(arms[-2:], ts[-2:]):.2f} between the two largest.")
    out.append("")

    # ---------------------------------------------------------------- scenes
    out.append("### Model only what a scene requires (issue 3)\n")
    out.append("Nonholonomic inverse dynamics (`inverse_dynamics`, compile-time sized unless said), "
               "relative to `full` of the same model.\n")
    out.append("| variant | what it computes | paper5 | × full | ddrive_arm24 (n = 27) | × full |")
    out.append("|---|---|---:|---:|---:|---:|")
    for v, what in SCENE_VARIANTS:
        a, b = g(f"scene/paper5/{v}"), g(f"scene/ddrive_arm24/{v}")
        fa, fb = g("scene/paper5/full"), g("scene/ddrive_arm24/full")
        out.append(f"| `{v}` | {what} | {ns(a)} | {r2(ratio(a, fa))} | {ns(b)} | {r2(ratio(b, fb))} |")
    out.append("")

    # ---------------------------------------------------------------- M_eta
    out.append("### M_η = SᵀMS: composite rigid body vs m rne columns (nh_forward_dynamics)\n")
    out.append("| model | n | crba | rne_columns | rne_columns / crba | faster |")
    out.append("|---|---:|---:|---:|---:|---|")
    crba_wins = 0
    for m in NH_MODELS:
        c, r = g(f"nh_inertia/{m}/crba"), g(f"nh_inertia/{m}/rne_columns")
        crba_wins += (c or 0) < (r or 0)
        out.append(f"| {m} | {DOF[m]} | {ns(c)} | {ns(r)} | {r2(ratio(r, c))} | "
                   f"{'crba' if c < r else 'rne_columns'} |")
    out.append("")
    out.append(f"- crba is faster on {crba_wins} of {len(NH_MODELS)} models; "
               f"`reduced_inertia_method::crba` is the default.")
    out.append("")

    # ---------------------------------------------------------------- forward dynamics
    out.append("### Holonomic forward dynamics: ABA, CRBA + LDLᵀ and KDL's ChainFdSolver_RNE (issue 15)\n")
    out.append("`fd/<model>/{aba, aba_reference, crba_ldlt, crba_ldlt_evaluate, kdl}`: the articulated-body algorithm (`nhdyn::aba`, "
               "the kernel, on the chain as a tree, run-time sized), the book's algorithm it optimises "
               "(`reference::aba`: RBDA Table 7.1 with 6×6 spatial matrices), the chain's `forward_dynamics` forced to CRBA + LDLᵀ "
               "(`fd_method::crba_ldlt`: CRBA mass matrix, LDLᵀ; as a call, and `evaluate` into a q̈ and a "
               "`forward_dynamics_scratch` the caller reuses), and KDL's `ChainFdSolver_RNE` on the same chain "
               "and state. The default `forward_dynamics` (`fd_method::automatic`) is the CRBA + LDLᵀ column below "
               "9 joints and the ABA column from 9 on (`fd_options::aba_from`).\n")
    out.append("| model | n | ABA | ABA reference | CRBA + LDLᵀ | CRBA + LDLᵀ, evaluate | KDL | ABA / KDL | CRBA / KDL | faster of ours | allocations (CRBA + LDLᵀ, evaluate) |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---|")
    worst_aba = 0.0
    crossover = None
    for m in RNE_MODELS:
        a, c, k = g(f"fd/{m}/aba"), g(f"fd/{m}/crba_ldlt"), g(f"fd/{m}/kdl")
        if a is None:
            continue
        worst_aba = max(worst_aba, ratio(a, k) or 0)
        if m.startswith("rev") and crossover is None and a < c:
            crossover = DOF[m]
        out.append(f"| {m} | {DOF[m]} | {ns(a)} | {ns(g(f'fd/{m}/aba_reference'))} | {ns(c)} | "
                   f"{ns(g(f'fd/{m}/crba_ldlt_evaluate'))} | {ns(k)} | "
                   f"{r2(ratio(a, k))} | {r2(ratio(c, k))} | "
                   f"{'ABA' if a < c else 'CRBA + LDLᵀ'} | "
                   f"{al(allocs.get(f'fd/{m}/crba_ldlt'))}, {al(allocs.get(f'fd/{m}/crba_ldlt_evaluate'))} |")
    out.append("")
    out.append(f"- Target ABA ≤ 0.3× KDL's forward dynamics on every chain: worst **{worst_aba:.2f}** — "
               f"{'met' if 0 < worst_aba <= 0.3 else 'NOT met'}.")
    out.append(f"- On the revolute chains ABA is first faster than CRBA + LDLᵀ at n = "
               f"{crossover if crossover else '— (never, up to 96)'}.")
    out.append("")

    # ---------------------------------------------------------------- trees
    out.append("### Kinematic trees: rne and CRBA against KDL's tree solver and the plain reference (issue 13)\n")
    out.append("`rne/<tree>/{nhdyn, reference, kdl}`, `crba/<tree>/{nhdyn, reference}`: the kernel, the plain "
               "reference and KDL on each tree (run-time sized); `{rne, crba}/<tree>/evaluate`: "
               "the same kernels into a vector or matrix the caller reuses (`evaluate`); `aba/<tree>/{nhdyn, "
               "evaluate}`: the articulated-body forward dynamics, the same two ways. CRBA / rne: the two "
               "calls' medians (not paired); paired: `crba_pair/<tree>`, the two `evaluate` forms timed in "
               "alternating blocks on the same state; kept: `crba_pair_kept/<tree>`, the same with M into a "
               "`mass_matrix_result`, whose zeros the calls after its first keep (not written again). "
               "The trees are the shipped mobile manipulator's URDF, the "
               "project's PR2-style (`powered_castors_arm.urdf`) and TIAGo-style (`tiago_style.urdf`: "
               "a five-finger hand) files, and random branching trees.\n")
    out.append("| tree | bodies | rne nhdyn | rne reference | rne KDL | nhdyn / KDL | CRBA nhdyn | CRBA reference | CRBA / rne | "
               "CRBA / rne (paired) | CRBA / rne (paired, kept) | ABA nhdyn | allocations (rne, CRBA, ABA) | allocations, evaluate (rne, CRBA, ABA) |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|")
    worst_tree, worst_crba = 0.0, 0.0
    for m in TREE_MODELS:
        a, r, k = g(f"rne/{m}/nhdyn"), g(f"rne/{m}/reference"), g(f"rne/{m}/kdl")
        if a is None:
            continue
        worst_tree = max(worst_tree, ratio(a, k) or 0)
        worst_crba = max(worst_crba, PAIRED.get(f"crba_pair/{m}") or 0)
        out.append(f"| {m} | {TREE_BODIES[m]} | {ns(a)} | {ns(r)} | {ns(k)} | {r2(ratio(a, k))} | "
                   f"{ns(g(f'crba/{m}/nhdyn'))} | {ns(g(f'crba/{m}/reference'))} | {r2(ratio(g(f'crba/{m}/nhdyn'), a))} | "
                   f"{r2(PAIRED.get(f'crba_pair/{m}'))} | {r2(PAIRED.get(f'crba_pair_kept/{m}'))} | {ns(g(f'aba/{m}/nhdyn'))} | "
                   f"{al(allocs.get(f'rne/{m}/nhdyn'))}, {al(allocs.get(f'crba/{m}/nhdyn'))}, {al(allocs.get(f'aba/{m}/nhdyn'))} | "
                   f"{al(allocs.get(f'rne/{m}/evaluate'))}, {al(allocs.get(f'crba/{m}/evaluate'))}, "
                   f"{al(allocs.get(f'aba/{m}/evaluate'))} |")
    out.append("")
    out.append(f"- Target rne ≤ {TARGET_TREE}× KDL's tree solver on every tree: worst **{worst_tree:.2f}** — "
               f"{'met' if 0 < worst_tree <= TARGET_TREE else 'NOT met'}.")
    if worst_crba > 0:
        best_crba = min(PAIRED[f"crba_pair/{m}"] for m in TREE_MODELS if f"crba_pair/{m}" in PAIRED)
        out.append(f"- Target CRBA ≤ {TARGET_CRBA}× one rne of the same tree and state (paired, every tree of 9 or "
                   f"more joints): {best_crba:.2f}–**{worst_crba:.2f}** — "
                   f"{'met' if worst_crba <= TARGET_CRBA else 'NOT met'}.")
        kept = [PAIRED[f"crba_pair_kept/{m}"] for m in TREE_MODELS if f"crba_pair_kept/{m}" in PAIRED]
        if kept:
            out.append(f"- The same with M's zeros kept (`crba_pair_kept`): {min(kept):.2f}–**{max(kept):.2f}** — "
                       f"{'met' if max(kept) <= TARGET_CRBA else 'NOT met'}.")
    out.append("")

    # ---------------------------------------------------------------- wheeled robots
    def el_over_nh(m, el, nh):  # E–L / nh: paired (el_pair/<robot>); a run without it, the medians' ratio
        return PAIRED.get(f"el_pair/{m}", ratio(el, nh))

    def el_cell(m, el, nh):  # the column: "—" without a figure, "(medians)" where not paired
        x = el_over_nh(m, el, nh)
        return "—" if x is None else f"{x:.1f}" + ("" if f"el_pair/{m}" in PAIRED else " (medians)")

    def nh_allocs(m):  # the wheeled tables' last column: (nh, nh evaluate, fd, fd evaluate)
        return ", ".join(al(allocs.get(f"{c}/{m}/{v}"))
                         for c, v in (("nh_id", "rne"), ("nh_id", "evaluate"), ("nh_fd", "nhdyn"), ("nh_fd", "evaluate")))

    out.append("### A real robot's URDF with each constraint type (issue 14)\n")
    out.append("The shipped mobile manipulator (16 URDF joints on a planar base: n = 19) from its robot files: "
               "`nh_id/<robot>/{rne, lagrange}` (the paper's method; the projected Euler–Lagrange equations on "
               "the tree, `bench/lagrange.hpp`), `nh_id/<robot>/evaluate` (the method into a τ the caller reuses), "
               "`nh_pair/<robot>/run_time` (the holonomic rne at the lifted "
               "state and the method at ζ, paired as above; `nh_pair/<robot>/evaluate`: the two `evaluate` forms paired), "
               "`el_pair/<robot>` (the method's call and the projected Euler–Lagrange equations, paired: E–L / nh), `nh_fd/<robot>/nhdyn` (the constrained forward "
               "dynamics η̇ = M_η⁻¹(SᵀEτ − h_η)) and `nh_fd/<robot>/evaluate` (the same into a result the caller reuses).\n")
    out.append("| robot file | k | m | nh | paired nh / holonomic | nh, evaluate | paired, evaluate | E–L | E–L / nh (paired) | forward dynamics | fd, evaluate | allocations (nh, nh evaluate, fd, fd evaluate) |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    worst_pair, worst_pair_ev, least_el = 0.0, 0.0, float("inf")
    for m, k in WHEELED:
        nh, el, fd, pr = g(f"nh_id/{m}/rne"), g(f"nh_id/{m}/lagrange"), g(f"nh_fd/{m}/nhdyn"), PAIRED.get(f"nh_pair/{m}/run_time")
        if nh is None:
            continue
        ev, pe = g(f"nh_id/{m}/evaluate"), PAIRED.get(f"nh_pair/{m}/evaluate")
        worst_pair = max(worst_pair, pr or 0)
        worst_pair_ev = max(worst_pair_ev, pe or 0)
        least_el = min(least_el, el_over_nh(m, el, nh) or 0)
        out.append(f"| {m} | {k} | {19 - k} | {ns(nh)} | {r2(pr)} | {ns(ev)} | {r2(pe)} | {ns(el)} | {el_cell(m, el, nh)} | {ns(fd)} | {ns(g(f'nh_fd/{m}/evaluate'))} | "
                   f"{nh_allocs(m)} |")
    out.append("")
    out.append(f"- Target nh ≤ {TARGET_NH}× the holonomic rne (paired): worst **{worst_pair:.2f}** — "
               f"{verdict(worst_pair)}; both into reused storage (`evaluate`): " +
               (f"worst **{worst_pair_ev:.2f}**." if worst_pair_ev > 0 else "not in this run."))
    out.append(f"- Target nh ≥ 20× faster than projected Euler–Lagrange (paired, `el_pair/<robot>`): least **{least_el:.1f}×** — "
               f"{'met' if least_el >= 20 else 'NOT met'}.")
    out.append("")
    # ---------------------------------------------------------------- every wheeled base (issue 31)
    out.append("### Every wheeled base: wheeled_base on the shipped bases (issue 31)\n")
    out.append("The shipped robot files with a `wheeled_base` constraint (docs/model-format.md): the same cases as above "
               "(`nh_id/<robot>/{rne, evaluate, lagrange}`, `nh_pair/<robot>/{run_time, evaluate}`, `el_pair/<robot>`, `nh_fd/<robot>/{nhdyn, evaluate}`), with the "
               "redundancy resolution (the least-norm τ of p > m actuators) inside the nonholonomic call, and "
               "`deriv_nh_pair/<robot>` (the analytic ∂τ/∂ζ, paired with one call). The last row is "
               "mobile_manipulator_wheels' two drive wheels as a `wheeled_base` (the `wheels` type above is its "
               "closed-form instance).\n")
    out.append("| robot file | n | k | m | p | nh | paired nh / holonomic | nh, evaluate | paired, evaluate | E–L | E–L / nh (paired) | forward dynamics | fd, evaluate | ∂τ/∂ζ / nh (paired) | allocations (nh, nh evaluate, fd, fd evaluate) |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    worst_wp, worst_wpe, least_wel = 0.0, 0.0, float("inf")
    for m, n_, k_, m_, p_ in WHEEL_BASES:
        nh, el, fd, pr = g(f"nh_id/{m}/rne"), g(f"nh_id/{m}/lagrange"), g(f"nh_fd/{m}/nhdyn"), PAIRED.get(f"nh_pair/{m}/run_time")
        if nh is None:
            continue
        ev, pe = g(f"nh_id/{m}/evaluate"), PAIRED.get(f"nh_pair/{m}/evaluate")
        if m != "mobile_manipulator_wheels_as_wheeled_base":
            worst_wp = max(worst_wp, pr or 0)
            worst_wpe = max(worst_wpe, pe or 0)
            least_wel = min(least_wel, el_over_nh(m, el, nh) or 0)
        out.append(f"| {m} | {n_} | {k_} | {m_} | {p_} | {ns(nh)} | {r2(pr)} | {ns(ev)} | {r2(pe)} | {ns(el)} | {el_cell(m, el, nh)} | {ns(fd)} | {ns(g(f'nh_fd/{m}/evaluate'))} | "
                   f"{r2(PAIRED.get(f'deriv_nh_pair/{m}'))} | {nh_allocs(m)} |")
    out.append("")
    out.append(f"- Target nh ≤ {TARGET_WHEEL_NH}× the holonomic rne (paired, redundancy resolution included): worst "
               f"**{worst_wp:.2f}** — {'met' if 0 < worst_wp <= TARGET_WHEEL_NH else 'NOT met'}; both into reused "
               f"storage (`nh_pair/<robot>/evaluate`: rne's and the method's `evaluate`): " +
               (f"worst **{worst_wpe:.2f}** — {'met' if worst_wpe <= TARGET_WHEEL_NH else 'NOT met'}." if worst_wpe > 0
                else "not in this run."))
    out.append(f"- Target nh ≥ {TARGET_WHEEL_EL}× faster than projected Euler–Lagrange (paired, `el_pair/<robot>`): least **{least_wel:.1f}×** — "
               + ("met." if least_wel >= TARGET_WHEEL_EL else "NOT met (E–L costs O(n⁴), the method O(n): the ratio "
                  "grows with n, and below n ≈ 19 it is bounded by E–L / rne itself)."))
    out.append("")
    # ---------------------------------------------------------------- derivatives (issue 18)
    out.append("### Analytic derivatives against one call and against dual numbers (issue 18)\n")
    out.append("`deriv_rne/<model>/{rne, analytic, dual}`: one double rne of the tree (the tree kernel, its "
               "output allocated), the full ∂τ/∂(q, q̇) and M of `rne_derivatives` (into a reused result), "
               "and ∂τ/∂(q, q̇) by duals through the tree kernel (`jacobian`, 8 directions a pass); "
               "`deriv_rne_pair/<model>`: rne and analytic paired as above. `deriv_nh/<model>/{nh, analytic, "
               "dual}`: one nonholonomic inverse dynamics on the tree, `inverse_dynamics_derivatives` "
               "(∂τ/∂(q, η, η̇), `evaluate` into a reused result) and `inverse_dynamics_linearizer` (duals); "
               "`deriv_nh_pair` paired. `deriv_fd/<model>/{fd, analytic, dual}`: holonomic forward dynamics, "
               "`forward_dynamics_derivatives` (q̈, ∂q̈/∂(q, q̇), M⁻¹; `evaluate` into a reused result) and "
               "`linearize_forward_dynamics`; `deriv_nh_fd/...`: the constrained forward dynamics and its A, B "
               "(`evaluate`); `deriv_fd_pair`, `deriv_nh_fd_pair` paired.\n")
    out.append("| model | rne | ∂τ/∂(q, q̇) analytic | analytic / rne | paired | dual | dual / analytic |")
    out.append("|---|---:|---:|---:|---:|---:|---:|")
    worst_d = 0.0
    for m in DERIV_MODELS:
        r, a, d, pr = g(f"deriv_rne/{m}/rne"), g(f"deriv_rne/{m}/analytic"), g(f"deriv_rne/{m}/dual"), PAIRED.get(f"deriv_rne_pair/{m}")
        if a is None:
            continue
        if m not in BEYOND_DERIV_TARGETS:
            worst_d = max(worst_d, pr or ratio(a, r) or 0)
        out.append(f"| {m} | {ns(r)} | {ns(a)} | {r2(ratio(a, r))} | {r2(pr)} | {ns(d)} | {r2(ratio(d, a))} |")
    out.append("")
    out.append(f"- Target full ∂τ/∂(q, q̇) ≤ {TARGET_DERIV}× one rne on every model up to 48 bodies (paired): worst "
               f"**{worst_d:.2f}** — {'met' if 0 < worst_d <= TARGET_DERIV else 'NOT met'}"
               + "".join(f"; {m}, past the target's models: {r2(PAIRED.get(f'deriv_rne_pair/{m}'))}"
                         for m in sorted(BEYOND_DERIV_TARGETS) if PAIRED.get(f"deriv_rne_pair/{m}")) + ".")
    out.append("")
    out.append("| model | nh | ∂τ/∂ζ analytic | analytic / nh | paired | dual | dual / analytic |")
    out.append("|---|---:|---:|---:|---:|---:|---:|")
    worst_n = 0.0
    for m in DERIV_NH_MODELS:
        r, a, d, pr = g(f"deriv_nh/{m}/nh"), g(f"deriv_nh/{m}/analytic"), g(f"deriv_nh/{m}/dual"), PAIRED.get(f"deriv_nh_pair/{m}")
        if a is None:
            continue
        worst_n = max(worst_n, pr or ratio(a, r) or 0)
        out.append(f"| {m} | {ns(r)} | {ns(a)} | {r2(ratio(a, r))} | {r2(pr)} | {ns(d)} | {r2(ratio(d, a))} |")
    out.append("")
    out.append(f"- Target nonholonomic ∂τ/∂ζ ≤ {TARGET_DERIV_NH}× one nonholonomic call (paired): worst **{worst_n:.2f}** — "
               f"{'met' if 0 < worst_n <= TARGET_DERIV_NH else 'NOT met'}.")
    out.append("")
    out.append("| model | forward dynamics | A, B analytic | analytic / fd | paired | dual | dual / analytic |")
    out.append("|---|---:|---:|---:|---:|---:|---:|")
    worst_f = 0.0
    for m, key in [(m, "deriv_fd") for m in DERIV_FD_MODELS] + [(m, "deriv_nh_fd") for m in DERIV_NH_MODELS]:
        r, a, d, pr = g(f"{key}/{m}/fd"), g(f"{key}/{m}/analytic"), g(f"{key}/{m}/dual"), PAIRED.get(f"{key}_pair/{m}")
        if a is None:
            continue
        if m not in BEYOND_DERIV_TARGETS:
            worst_f = max(worst_f, pr or ratio(a, r) or 0)
        label = m if key == "deriv_fd" else f"{m} (constrained)"
        out.append(f"| {label} | {ns(r)} | {ns(a)} | {r2(ratio(a, r))} | {r2(pr)} | {ns(d)} | {r2(ratio(d, a))} |")
    out.append("")
    out.append(f"- Target A, B ≤ {TARGET_DERIV_FD}× one forward dynamics call on every model up to 48 bodies (paired): "
               f"worst **{worst_f:.2f}** — {'met' if 0 < worst_f <= TARGET_DERIV_FD else 'NOT met'}"
               + "".join(f"; {m}, past the target's models: {r2(PAIRED.get(f'deriv_fd_pair/{m}'))}"
                         for m in sorted(BEYOND_DERIV_TARGETS) if PAIRED.get(f"deriv_fd_pair/{m}")) + ".")
    out.append("")
    # allocations of the derivatives' evaluate, on every model the run has (issue 33 item 3)
    alloc_models = list(dict.fromkeys(DERIV_MODELS + DERIV_FD_MODELS + DERIV_NH_MODELS + [w[0] for w in WHEEL_BASES]))
    alloc_rows = []
    for m in alloc_models:
        cells = [allocs.get(f"{k}/{m}/analytic") for k in ("deriv_rne", "deriv_nh", "deriv_fd", "deriv_nh_fd")]
        if any(c is not None for c in cells):
            alloc_rows.append(f"| {m} | " + " | ".join(al(c) for c in cells) + " |")
    if alloc_rows:
        out.append("Heap allocations per call of each `evaluate` into a reused result (`…/analytic`; — where the "
                   "model has no such case):\n")
        out.append("| model | ∂τ/∂(q, q̇) | ∂τ/∂(q, η, η̇) | A, B holonomic | A, B constrained |")
        out.append("|---|---:|---:|---:|---:|")
        out.extend(alloc_rows)
        out.append("")
    # ---------------------------------------------------------------- batches (issue 18)
    out.append("### Many states per call: SIMD packs (issue 18)\n")
    out.append(f"`batch_rne/<model>/{{one, batch}}`: one double rne of the tree, and `rne_batch` over "
               f"{BATCH_STATES} states in one call on `simd_pack<{ctx.get('simd_width', '?')}>` (per state: the "
               f"call's time / {BATCH_STATES}); `batch_fd/...`: `aba` and `forward_dynamics_batch`.\n")
    out.append("| model | rne one state | rne per state, batched | throughput gain | aba one state | aba per state, batched | throughput gain |")
    out.append("|---|---:|---:|---:|---:|---:|---:|")
    least_b = float("inf")
    for m in BATCH_MODELS:
        r1, rb, f1, fb = g(f"batch_rne/{m}/one"), g(f"batch_rne/{m}/batch"), g(f"batch_fd/{m}/one"), g(f"batch_fd/{m}/batch")
        if rb is None:
            continue
        rb, fb = rb / BATCH_STATES, (fb / BATCH_STATES if fb else None)
        least_b = min(least_b, ratio(r1, rb) or 0)
        out.append(f"| {m} | {ns(r1)} | {ns(rb)} | {r2(ratio(r1, rb))} | {ns(f1)} | {ns(fb)} | {r2(ratio(f1, fb))} |")
    out.append("")
    if least_b < float("inf"):
        out.append(f"- Target batched rne ≥ {TARGET_BATCH}× the one-state throughput: least **{least_b:.2f}×** — "
                   f"{'met' if least_b >= TARGET_BATCH else 'NOT met'}.")
        out.append("")
    out.append("![scaling](performance_scaling.png)")
    return "\n".join(out) + "\n"


def plot(med, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    g = med.get
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(16, 4.4))
    ks = [6, 12, 24, 48, 96]
    for suf, lab, st in (("kdl", "KDL ChainIdSolver_RNE", "s-"), ("nhdyn", "nhdyn run-time sized", "o-"),
                         ("nhdyn_fixed", "nhdyn fixed size", "^-")):
        a1.loglog(ks, [g(f"rne/rev{n}/{suf}") for n in ks], st, label=lab)
    a1.set_xlabel("joints n (random revolute chains)")
    a1.set_ylabel("ns per call (median CPU time)")
    a1.set_title("holonomic inverse dynamics")
    a1.legend()
    a1.grid(True, which="both", alpha=0.3)
    arms = [2, 4, 8, 16, 24, 48]
    n = [3 + a for a in arms]
    for key, lab, st in (("nh_id/ddrive_arm{}/lagrange", "projected Euler–Lagrange", "s-"),
                         ("nh_id/ddrive_arm{}/rne", "nh rne (project∘rne∘lift), run-time", "o-"),
                         ("nh_id/ddrive_arm{}/rne_fixed", "nh rne, fixed size", "^-"),
                         ("rne/ddrive_arm{}/nhdyn_fixed", "holonomic rne, fixed size", "v--")):
        a2.loglog(n, [g(key.format(a)) for a in arms], st, label=lab)
    a2.set_xlabel("joints n (differential-drive base + arm)")
    a2.set_title("nonholonomic inverse dynamics")
    a2.legend(fontsize=8)
    a2.grid(True, which="both", alpha=0.3)
    a3.loglog(ks, [g(f"rne/rev{n}/nhdyn_fixed") / g(f"rne/rev{n}/kdl") for n in ks], "^-",
               label="nhdyn fixed / KDL (rev chains)")
    a3.loglog(ks, [g(f"rne/rev{n}/nhdyn") / g(f"rne/rev{n}/kdl") for n in ks], "o-",
               label="nhdyn run-time / KDL (rev chains)")
    a3.loglog(n, [g(f"nh_id/ddrive_arm{a}/rne_fixed") / g(f"rne/ddrive_arm{a}/nhdyn_fixed") for a in arms],
               "v-", label="nh / holonomic rne, fixed (ddrive)")
    a3.loglog(n, [g(f"nh_id/ddrive_arm{a}/rne") / g(f"rne/ddrive_arm{a}/nhdyn") for a in arms],
               "d-", label="nh / holonomic rne, run-time (ddrive)")
    a3.loglog(n, [g(f"nh_id/ddrive_arm{a}/lagrange") / g(f"nh_id/ddrive_arm{a}/rne") for a in arms],
               "s-", label="projected E–L / nh rne, run-time (ddrive)")
    for y, lab in ((TARGET_FIXED, "target 0.25"), (TARGET_DYN, "target 0.35"), (TARGET_NH, "target 1.3")):
        a3.axhline(y, color="grey", lw=0.8, ls=":")
        a3.text(ks[-1], y, lab, fontsize=7, va="bottom", ha="right", color="grey")
    a3.set_xlabel("joints n")
    a3.set_ylabel("time ratio")
    a3.set_title("ratios")
    a3.legend(fontsize=7)
    a3.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


# The kernels timed under both compilers (issue 33): (label, model, benchmark name)
TWO_COMPILERS = (
    [("rne", m, f"rne/{m}/nhdyn") for m in ["puma560", "rev24"] + CLANG_TREES]
    + [("CRBA", m, f"crba/{m}/nhdyn") for m in CLANG_TREES + ["tiago_style"]]
    + [("ABA", "rev24", "fd/rev24/aba")] + [("ABA", m, f"batch_fd/{m}/one") for m in CLANG_TREES]
    + [("∂τ/∂(q, q̇)", m, f"deriv_rne/{m}/analytic") for m in CLANG_TREES]
    + [("nonholonomic id", m, f"nh_id/{m}/rne") for m in ["paper5", "mecanum_arm", "castor_drive_arm"]])
TARGET_CLANG = 1.1
# the benchmark filter of that run (scripts/bench.sh, NHDYN_BENCH_CLANG=1)
CLANG_FILTER = "^(" + "|".join(re.escape(n) for _, _, n in TWO_COMPILERS) + ")$"


def sitting_ratios(first_path, second_path):
    """Per case, the ratio second / first of each sitting's medians (files of merge_bench.py --sittings)."""
    per = {}
    for k, path in enumerate((first_path, second_path)):
        with open(path) as f:
            for b in json.load(f)["benchmarks"]:
                if b.get("aggregate_name") == "median":
                    per.setdefault(b["run_name"], {}).setdefault(b.get("sitting", 0), [None, None])[k] = b["cpu_time"]
    return {name: [s / f for f, s in v.values() if f and s] for name, v in per.items()}


def widest_spread(ratios):
    """The case whose sittings' ratios spread the most, as "from lo to hi for name"."""
    name, r = max(((n, r) for n, r in ratios.items() if len(r) > 1), key=lambda x: max(x[1]) - min(x[1]),
                  default=(None, None))
    return f"from {min(r):.2f} to {max(r):.2f} for {name}" if name else "one sitting only"


def two_compilers(med, second_med, second_compiler, first_compiler, rerun=frozenset(), baseline=None, sittings=None,
                  spread=None):
    out = ["### Two compilers: the same kernels built by clang (issue 33)\n"]
    if sittings:  # the two builds alternated, sitting after sitting (bench.sh clang mode)
        first = (f"and this page's build by {first_compiler} on the same cases, the two builds alternating in "
                 f"{len(sittings)} sittings (docs/performance-clang-gcc.json, {sittings[0]} to {sittings[-1]}); "
                 f"each figure is the median of the sittings' medians, ns per call. A single sitting's "
                 f"ratio wanders: {spread}.")
    elif baseline:
        first = (f"and this page's build by {first_compiler} run on the same cases right after it "
                 f"(docs/performance-clang-gcc.json, {baseline}); medians, ns per call.")
    else:
        first = f"beside this page's build by {first_compiler}; medians, ns per call, each build's own run."
    out.append(f"The benchmarks below from a second build of `nhdyn_bench` by {second_compiler} (same flags, "
               f"`NHDYN_BENCH_CLANG=1 scripts/bench.sh`: `build-bench-clang/`, docs/performance-clang.json), "
               f"{first}\n")
    out.append("| kernel | model | g++ | clang | clang / g++ |")
    out.append("|---|---|---:|---:|---:|")
    worst, later = 0.0, False
    for label, m, name in TWO_COMPILERS:
        a, b = med.get(name), second_med.get(name)
        if a is None and b is None:
            continue
        if name in rerun:  # the g++ median is of another sitting than the clang one: no ratio
            later = True
            out.append(f"| {label} | {m} | {ns(a)}* | {ns(b)} | — |")
            continue
        r = ratio(b, a)
        worst = max(worst, r or 0)
        out.append(f"| {label} | {m} | {ns(a)} | {ns(b)} | {r2(r)} |")
    out.append("")
    if later:
        out.append("\\* the g++ median is of a run more than 12 hours from the clang run (see the top of the page): "
                   "the machine's speed drifts from hour to hour and day to day, so no ratio is drawn from them.\n")
    out.append(f"- Target every kernel under clang within {TARGET_CLANG}× its g++ time: worst **{worst:.2f}** — "
               f"{'met' if 0 < worst <= TARGET_CLANG else 'NOT met'}.")
    out.append("")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("json")
    ap.add_argument("doc")
    ap.add_argument("png")
    ap.add_argument("--cpu", default="unknown CPU")
    ap.add_argument("--compiler", default="unknown compiler")
    ap.add_argument("--second", help="a second build's JSON (clang): the two-compiler table")
    ap.add_argument("--second-compiler", default="clang")
    ap.add_argument("--second-baseline", help="the first compiler's run of the second's cases in the same sitting "
                                              "(the two-compiler table's g++ column)")
    ap.add_argument("--print-clang-filter", action="store_true", help="print the second run's benchmark filter")
    if "--print-clang-filter" in sys.argv:
        print(CLANG_FILTER)
        return
    a = ap.parse_args()
    ctx, med, allocs, reps = load(a.json)
    text = tables(ctx, med, allocs, reps, a.cpu, a.compiler)
    if a.second and a.second_baseline:  # (after tables(): the paired ratios of these files do not reach them)
        second_ctx, second_med, _, _ = load(a.second)
        base_ctx, base_med, _, _ = load(a.second_baseline)
        sittings = base_ctx.get("sittings") if second_ctx.get("sittings") else None
        text += two_compilers(base_med, second_med, a.second_compiler, a.compiler,
                              baseline=f"{base_ctx['date']}; clang: {second_ctx['date']}", sittings=sittings,
                              spread=widest_spread(sitting_ratios(a.second_baseline, a.second)) if sittings else None)
    elif a.second:
        second_ctx, second_med, _, _ = load(a.second)
        # each g++ median's run: the last filtered re-run that holds it, else the full run; a ratio
        # is drawn only where that run and the clang run are within 12 hours of each other
        when = {}
        for pr in reruns(ctx):
            for x in pr["run_names"]:
                when[x] = pr["date"]
        t2 = datetime.datetime.fromisoformat(second_ctx["date"])
        rerun = frozenset(name for _, _, name in TWO_COMPILERS
                          if abs(datetime.datetime.fromisoformat(when.get(name, ctx["date"])) - t2)
                          > datetime.timedelta(hours=12))
        text += two_compilers(med, second_med, a.second_compiler, a.compiler, rerun)
    with open(a.doc) as f:
        doc = f.read()
    if BEGIN not in doc or END not in doc:
        sys.exit(f"perf_table.py: {a.doc} lacks the markers {BEGIN} … {END}")
    doc = re.sub(re.escape(BEGIN) + ".*?" + re.escape(END), lambda _: BEGIN + "\n" + text + END, doc,
                 flags=re.S)
    with open(a.doc, "w") as f:
        f.write(doc)
    plot(med, a.png)
    print(f"perf_table.py: wrote {a.doc} and {a.png}")


if __name__ == "__main__":
    main()
