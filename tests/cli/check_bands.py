"""Checks DIR/<group>-bands.csv of `nhdyn simulate` against percentiles computed here by
NumPy from the runs' own CSVs (numpy.percentile, linear interpolation between order
statistics: the definition the tool documents), and that the band figures were drawn.

usage: check_bands.py DIR GROUP RUNS [--figures]
"""
import csv
import glob
import os
import sys

import numpy as np


def read(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(x) for x in r] for r in rows[1:]])


def main():
    out, group, runs = sys.argv[1], sys.argv[2], int(sys.argv[3])
    head, bands = read(os.path.join(out, group + "-bands.csv"))
    files = sorted(f for f in glob.glob(os.path.join(out, group + "-*.csv")) if not f.endswith("-bands.csv"))
    assert len(files) == runs, f"{len(files)} run CSVs, expected {runs}"
    cols, first = read(files[0])
    data = np.stack([read(f)[1] for f in files])  # runs × rows × columns
    assert head[0] == "t" and len(head) == 1 + 5 * (len(cols) - 1), head[:6]
    assert bands.shape[0] == data.shape[1], (bands.shape, data.shape)
    assert np.allclose(bands[:, 0], first[:, 0], rtol=0, atol=1e-9)
    worst = 0.0
    for j, name in enumerate(cols[1:], start=1):
        assert head[1 + 5 * (j - 1)] == name + "_min", (head[1 + 5 * (j - 1)], name)
        want = np.stack([data[:, :, j].min(0), np.percentile(data[:, :, j], 5, axis=0),
                         np.median(data[:, :, j], axis=0), np.percentile(data[:, :, j], 95, axis=0),
                         data[:, :, j].max(0)], axis=1)
        got = bands[:, 1 + 5 * (j - 1): 1 + 5 * j]
        scale = np.maximum(np.abs(want), 1e-300)
        worst = max(worst, float(np.max(np.abs(got - want) / np.maximum(scale, 1e-12))))
        assert np.all(np.diff(got, axis=1) >= -1e-12 * scale[:, 1:]), f"{name}: bands out of order"
    assert worst < 1e-8, f"bands differ from NumPy's percentiles by {worst:.3g} (relative)"
    # the figure script reads the columns it names: every band is a (_min, _max) or
    # (_p5, _p95) pair of one column, every median line a _p50, the error figure err's
    import re
    script = open(os.path.join(out, group + ".gp")).read()
    pairs = re.findall(r"using 1:(\d+):(\d+) with filledcurves", script)
    medians = re.findall(r"using 1:(\d+) with lines lw 2", script)
    assert pairs and len(medians) * 2 == len(pairs), (len(pairs), len(medians))
    for a, b in pairs:
        lo, hi = head[int(a) - 1], head[int(b) - 1]
        assert (lo.endswith("_min") and hi == lo[:-4] + "_max") or (lo.endswith("_p5") and hi == lo[:-3] + "_p95"), (lo, hi)
    for c in medians:
        assert head[int(c) - 1].endswith("_p50"), head[int(c) - 1]
    error_plot = script[script.index("-error.png"):]
    first = re.search(r"using 1:(\d+):(\d+) with filledcurves", error_plot)
    assert head[int(first.group(1)) - 1] == "err_min", head[int(first.group(1)) - 1]
    if "--figures" in sys.argv:
        for fig in ("path", "error", "q", "tau"):
            p = os.path.join(out, f"{group}-{fig}.png")
            assert os.path.getsize(p) > 1000, p
    print(f"{group}: bands of {len(cols) - 1} columns over {runs} runs = NumPy's percentiles (worst {worst:.2g})")


if __name__ == "__main__":
    main()
