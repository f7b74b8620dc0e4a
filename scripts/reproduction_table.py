#!/usr/bin/env python3
"""Rewrites the generated part of docs/reproduction.md from a `nhdyn simulate paper` run.

    python3 scripts/reproduction_table.py out/paper [docs/reproduction.md]

Reads DIR/summary.json (one entry per run: name, success, max_tail_error [m], steps,
failure, wall_time_s, cpu_time_s, peak_tau), writes the per-scene and per-run tables between
the BEGIN/END GENERATED markers of the document, and copies the figures the document shows
(DIR/paper-circle-{path,error,q,tau}.png, DIR/paper-factorial-{error,tau}.png, DIR/paper-noise-error.png) into
docs/figures/reproduction/. No number in those tables is typed by hand.
"""
import json
import os
import platform
import shutil
import sys
from datetime import datetime, timezone

BEGIN = "<!-- BEGIN GENERATED: scripts/reproduction_table.py -->"
END = "<!-- END GENERATED -->"
FIGURES = ["paper-circle-path.png", "paper-circle-error.png", "paper-circle-q.png", "paper-circle-tau.png",
           "paper-factorial-error.png", "paper-factorial-tau.png", "paper-noise-error.png"]
PAPER = {"paper-circle": "(fig. 4–6)", "paper-factorial": "14", "paper-noise": "13"}


def scene_of(name):
    for s in ("paper-factorial", "paper-noise", "paper-circle"):
        if name.startswith(s):
            return s
    return name


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out_dir = sys.argv[1]
    doc = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "..", "docs", "reproduction.md")
    with open(os.path.join(out_dir, "summary.json")) as f:
        data = json.load(f)
    runs = data["runs"] if isinstance(data, dict) else data  # {"runs", "aggregate"}; a list before

    scenes = {}
    for r in runs:
        scenes.setdefault(scene_of(r["name"]), []).append(r)

    mm = lambda r: 1e3 * r["max_tail_error"] if r["max_tail_error"] is not None else float("nan")
    lines = []
    ok_total = sum(r["success"] for r in runs)
    lines.append(f"Generated {datetime.now(timezone.utc).strftime('%Y-%m-%d')} from `{os.path.basename(os.path.normpath(out_dir))}/summary.json` "
                 f"({cpu_model()}, {os.cpu_count()} logical CPUs): **{ok_total}/{len(runs)} runs succeeded**.")
    lines.append("")
    lines.append("| scene | runs | succeeded | paper | max tail error [mm]: min … max (mean) | peak \\|τ\\| [N]: min … max | wall per run [ms]: min … max |")
    lines.append("|---|---|---|---|---|---|---|")
    for s in ("paper-circle", "paper-factorial", "paper-noise"):
        rs = scenes.get(s, [])
        if not rs:
            continue
        tails = [mm(r) for r in rs]
        peaks = [r["peak_tau"] for r in rs]
        walls = [1e3 * r["wall_time_s"] for r in rs]
        ok = sum(r["success"] for r in rs)
        rng = lambda v, fmt: (fmt.format(v[0]) if len(v) == 1 else (fmt + " … " + fmt).format(min(v), max(v)))
        tail_txt = rng(tails, "{:.3f}") + ("" if len(tails) == 1 else f" ({sum(tails) / len(tails):.3f})")
        lines.append(f"| {s} | {len(rs)} | **{ok}** | {PAPER.get(s, '')} | {tail_txt} | {rng(peaks, '{:.1f}')} | {rng(walls, '{:.1f}')} |")
    lines.append("")
    lines.append("Every run (tail error: max ‖r_d − r‖ of the true r over t ∈ [15, 20] s; wall and CPU time of the run, CSV included):")
    lines.append("")
    lines.append("| run | ok | tail [mm] | peak \\|τ\\| [N] | steps | wall [ms] | CPU [ms] | failure |")
    lines.append("|---|---|---|---|---|---|---|---|")
    for r in runs:
        lines.append(f"| {r['name']} | {'yes' if r['success'] else '**no**'} | {mm(r):.3f} | {r['peak_tau']:.1f} | {r['steps']} | "
                     f"{1e3 * r['wall_time_s']:.1f} | {1e3 * r.get('cpu_time_s', float('nan')):.1f} | {r['failure'] or ''} |")
    block = "\n".join(lines)

    with open(doc) as f:
        text = f.read()
    if BEGIN not in text or END not in text:
        sys.exit(f"{doc}: no {BEGIN} … {END} markers")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    with open(doc, "w") as f:
        f.write(head + BEGIN + "\n" + block + "\n" + END + tail)

    fig_dir = os.path.join(os.path.dirname(doc), "figures", "reproduction")
    os.makedirs(fig_dir, exist_ok=True)
    for name in FIGURES:
        src = os.path.join(out_dir, name)
        if os.path.exists(src):
            shutil.copyfile(src, os.path.join(fig_dir, name))
        else:
            print(f"reproduction_table: {src} missing (figures need gnuplot)", file=sys.stderr)
    print(f"reproduction_table: {doc} updated ({ok_total}/{len(runs)} succeeded)")


if __name__ == "__main__":
    main()
