#!/usr/bin/env python3
"""compare_summaries.py ONE MANY: the summary.json of a study run in one process (ONE) and
under MPI (MANY) hold the same runs with the same results bit for bit (everything but the
times and where each ran), the MPI one names more than one rank, and the aggregates agree."""
import json
import sys

one, many = (json.load(open(p)) for p in sys.argv[1:3])
where = ("wall_time_s", "cpu_time_s", "rank", "host")
strip = lambda runs: [{k: v for k, v in r.items() if k not in where} for r in runs]
if strip(one["runs"]) != strip(many["runs"]):
    sys.exit("the runs differ:\n" + json.dumps(strip(one["runs"]))[:2000] + "\n" + json.dumps(strip(many["runs"]))[:2000])
ranks = {r["rank"] for r in many["runs"]}
if len(ranks) < 2 or many["aggregate"]["processes"] < 2:
    sys.exit(f"the MPI run used ranks {sorted(ranks)} and {many['aggregate']['processes']} processes")
if {r["rank"] for r in one["runs"]} != {0}:
    sys.exit("the single-process run names a rank other than 0")
for k in ("count", "succeeded", "success_rate", "max_tail_error", "peak_tau"):
    if one["aggregate"][k] != many["aggregate"][k]:
        sys.exit(f"aggregate {k} differs: {one['aggregate'][k]} vs {many['aggregate'][k]}")
print(f"{len(one['runs'])} runs identical on 1 process and on ranks {sorted(ranks)}")
