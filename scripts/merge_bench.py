#!/usr/bin/env python3
"""Merges a filtered benchmark run into docs/performance.json, case by case.

    NHDYN_BENCH_FILTER='^nh_(id|fd)/' scripts/bench.sh --no-docs        # writes build-bench/performance.json
    scripts/merge_bench.py docs/performance.json build-bench/performance.json [--skip REGEX]
    /usr/bin/python3 scripts/perf_table.py docs/performance.json docs/performance.md docs/performance_scaling.png ...

Every case of the new run (its run_name) replaces the same case of the main file, or is added;
--skip leaves the main file's cases whose run_name matches REGEX as they were (cases that the
filter caught but whose tables divide them by cases it did not re-run). The main file's context
records the re-runs (`partial_reruns`: each one's date and the case names still its own), which
perf_table.py states at the top of the page and uses to draw no ratio across runs where it must
not (the clang table).

    scripts/merge_bench.py OUT --sittings A.json B.json ...

pools runs of the same cases made in several sittings (the two-compiler table's, which
bench.sh makes alternating the two builds) into OUT: every entry kept, tagged with its
sitting; perf_table.py takes a case's median over the sittings' medians.
"""
import argparse
import json
import re


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("main")
    ap.add_argument("new", nargs="?")
    ap.add_argument("--skip", help="run_names (regex) to keep from the main file")
    ap.add_argument("--sittings", nargs="+", help="runs of the same cases to pool into MAIN (written anew)")
    a = ap.parse_args()
    if a.sittings:
        runs = []
        for path in a.sittings:
            with open(path) as f:
                runs.append(json.load(f))
        out = {"context": dict(runs[0]["context"], sittings=[r["context"]["date"] for r in runs]), "benchmarks": []}
        for k, r in enumerate(runs):
            out["benchmarks"] += [dict(b, sitting=k) for b in r["benchmarks"]]
        with open(a.main, "w") as f:
            json.dump(out, f, indent=1)
        print(f"merge_bench: {len(runs)} sittings pooled into {a.main}")
        return
    if not a.new:
        ap.error("NEW (the filtered run to merge) is required without --sittings")
    with open(a.main) as f:
        d = json.load(f)
    with open(a.new) as f:
        n = json.load(f)
    new = [b for b in n["benchmarks"] if not (a.skip and re.search(a.skip, b["run_name"]))]
    names = {b["run_name"] for b in new}
    kept = [b for b in d["benchmarks"] if b.get("run_name") not in names]
    print(f"merge_bench: {len(names)} cases from {a.new} ({len(d['benchmarks']) - len(kept)} entries replaced, "
          f"{len(new)} written)")
    d["benchmarks"] = kept + new
    # every filtered run merged so far, each with the cases that are still its own
    ctx = d["context"]
    runs = ctx.pop("partial_reruns", None) or ([ctx.pop("partial_rerun")] if "partial_rerun" in ctx else [])
    runs = [{"date": r["date"], "run_names": [x for x in r["run_names"] if x not in names]} for r in runs]
    ctx["partial_reruns"] = [r for r in runs if r["run_names"]] + [
        {"date": n["context"]["date"], "run_names": sorted(names)}]
    with open(a.main, "w") as f:
        json.dump(d, f, indent=1)


if __name__ == "__main__":
    main()
