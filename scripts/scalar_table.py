#!/usr/bin/env python3
"""Rewrites the scalar-type tables of docs/performance.md from nhdyn_bench_scalar's JSON.

    python3 scripts/scalar_table.py docs/performance-scalar.json docs/performance.md --cpu CPU --compiler CC

Reads Google Benchmark JSON (--benchmark_repetitions with aggregates: the *_median rows) of the
benchmarks scalar/<algorithm>/<model>/<scalar>, scalar/jacobian/paper5/<method> and
scalar/bounds/paper5/split:<k>, and writes three tables between the markers
`<!-- BEGIN GENERATED: scripts/scalar_table.py -->` and `<!-- END GENERATED: scripts/scalar_table.py -->`:
time per call of every scalar type relative to double, the full Jacobian dτ/dζ of paper5 by
each method, and interval width against bisection depth. No number in them is typed by hand.
"""
import argparse
import json
import sys
from datetime import datetime, timezone

BEGIN = "<!-- BEGIN GENERATED: scripts/scalar_table.py -->"
END = "<!-- END GENERATED: scripts/scalar_table.py -->"

SCALARS = [
    ("float", "float"),
    ("double", "double"),
    ("long_double", "long double"),
    ("quad", "quad (binary128)"),
    ("mp50", "mp50"),
    ("dec50", "dec50"),
    ("dual1", "dual<double,1>"),
    ("dual13", "dual<double,13>"),
    ("dual13_state", "dual<double,13>, double model"),
    ("autodiff13", "AutoDiffScalar<13>"),
    ("interval_state", "**interval, double model**"),
    ("interval", "interval, interval model"),
    ("boost_interval_state", "boost_interval, double model"),
    ("boost_interval", "boost_interval, interval model"),
]
JACOBIANS = [
    ("dual", "duals: `inverse_dynamics_linearizer` (built once; 6 dual directions along q₄, q₅, η, the 3 base columns that vanish by symmetry skipped, ∂τ/∂η̇ = M_η by CRBA)"),
    ("dual_all_columns", "duals: all 13 columns seeded (`jacobian` of the pipeline)"),
    ("dual_oneshot", "duals: `linearize_inverse_dynamics` (builds the pipeline in every call)"),
    ("autodiff", "Eigen AutoDiffScalar<Matrix<double,13,1>>"),
    ("central", "central differences (26 double evaluations)"),
]


def fmt_ns(ns):
    if ns is None:
        return ""
    if ns >= 1e6:
        return f"{ns / 1e6:.2f} ms"
    if ns >= 1e3:
        return f"{ns / 1e3:.3g} µs"
    return f"{ns:.0f} ns"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("json")
    ap.add_argument("doc")
    ap.add_argument("--cpu", default="unknown CPU")
    ap.add_argument("--compiler", default="unknown compiler")
    ap.add_argument("--flags", default="-O3 -march=native")
    a = ap.parse_args()

    with open(a.json) as f:
        data = json.load(f)
    med, counters = {}, {}
    reps = 0
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        name = b["run_name"]
        unit = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[b.get("time_unit", "ns")]
        med[name] = b["cpu_time"] * unit
        counters[name] = b
        reps = max(reps, int(b.get("repetitions", 0)))

    def t(alg, model, scalar):
        return med.get(f"scalar/{alg}/{model}/{scalar}")

    lines = [f"Measured {datetime.now(timezone.utc).strftime('%Y-%m-%d')} on **{a.cpu}**, `nhdyn_bench_scalar` compiled by "
             f"**{a.compiler}** with `{a.flags}`; median of {reps} repetitions of the CPU time per call "
             f"(`docs/performance-scalar.json`). `_state` rows: the double model evaluated on a state of that scalar.",
             "",
             "| scalar | rne paper5 | nh_id paper5 | rne chain24 | nh_id chain24 | × double (nh_id paper5 / chain24) |",
             "|---|---|---|---|---|---|"]
    d5, d24 = t("nh_id", "paper5", "double"), t("nh_id", "chain24", "double")
    for key, label in SCALARS:
        n5, n24 = t("nh_id", "paper5", key), t("nh_id", "chain24", key)
        if n5 is None and n24 is None:
            continue
        ratio = " / ".join(f"{x / d:.3g}" if x is not None and d else "—" for x, d in ((n5, d5), (n24, d24)))
        lines.append(f"| {label} | {fmt_ns(t('rne', 'paper5', key))} | {fmt_ns(n5)} | {fmt_ns(t('rne', 'chain24', key))} | "
                     f"{fmt_ns(n24)} | {ratio} |")
    lines += ["", f"Full Jacobian ∂τ/∂ζ of paper5 (4 × 13); one double nh_id paper5 call = **{fmt_ns(d5)}** in this run.", "",
              "| method | CPU per Jacobian | × one double nh_id | target |", "|---|---|---|---|"]
    for key, label in JACOBIANS:
        x = med.get(f"scalar/jacobian/paper5/{key}")
        if x is None:
            continue
        target = ("≤ 8: **met**" if x / d5 <= 8 else "≤ 8: **NOT met**") if key == "dual" else ""
        lines.append(f"| {label} | {fmt_ns(x)} | {x / d5:.3g} | {target} |")
    fdd = med.get("scalar/fd_linearize/paper5/double_fd")
    ift = med.get("scalar/fd_linearize/paper5/ift")
    ift1 = med.get("scalar/fd_linearize/paper5/ift_oneshot")
    alld = med.get("scalar/fd_linearize/paper5/all_duals")
    if fdd and ift and ift1 and alld:
        lines += ["", "Forward-dynamics linearisation of paper5, A (9 × 9) and B (9 × 4) of ẋ = f(x, τ), x = (q, η); "
                      f"one double `nh_forward_dynamics` call = **{fmt_ns(fdd)}** in this run.", "",
                  "| method | CPU per (A, B) | × one double forward dynamics |", "|---|---|---|",
                  f"| `forward_dynamics_linearizer` (built once): the linearizer's ∂τ/∂(q, η, η̇) at (q, η, fd(q, η, τ)), implicit function theorem | {fmt_ns(ift)} | {ift / fdd:.3g} |",
                  f"| `linearize_forward_dynamics` (the same, built in every call) | {fmt_ns(ift1)} | {ift1 / fdd:.3g} |",
                  f"| duals: all 13 columns of (q, η, τ) seeded through `nh_forward_dynamics` | {fmt_ns(alld)} | {alld / fdd:.3g} |"]
    iv = t("nh_id", "paper5", "interval_state")
    if iv is not None:
        lines += ["", f"Intervals, paper5, double model with an interval state box (what `torque_bounds` over states does): "
                      f"**{iv / d5:.3g}×** double (target ≤ 10×: **{'met' if iv / d5 <= 10 else 'NOT met'}**)."]
    splits = sorted((int(n.split(":")[1].split("/")[0]), n) for n in med if n.startswith("scalar/bounds/paper5/split:"))
    if splits:
        lines += ["", "Width vs bisection depth vs time (paper5, state box q ± 0.05, η ± 0.05, η̇ ± 0.1; sum of the 4 torque widths):", "",
                  "| split k | sub-boxes | total width | CPU |", "|---|---|---|---|"]
        for k, n in splits:
            lines.append(f"| {k} | {2 ** k} | {counters[n].get('width', float('nan')):.3g} | {fmt_ns(med[n])} |")
    block = "\n".join(lines)

    with open(a.doc) as f:
        text = f.read()
    if BEGIN not in text or END not in text:
        sys.exit(f"{a.doc}: no {BEGIN} … {END} markers")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    with open(a.doc, "w") as f:
        f.write(head + BEGIN + "\n" + block + "\n" + END + tail)
    print(f"scalar_table: {a.doc} updated")


if __name__ == "__main__":
    main()
