"""Python call overhead and batch throughput of the nhdyn module (issue 16), in one process:

- batch: 10⁶ paper5 nonholonomic inverse dynamics, `nhdyn.inverse_dynamics(model)(Q, E, ED)`
  on 2-D arrays (one state per row, threads=1), against `nhdyn._cxx_loop_inverse_dynamics`,
  the plain C++ loop over the same rows compiled in the same module (rows copied into Eigen
  vectors, the library's call, τ stored): target ≤ 1.5× its time;
- one state: `f(q, eta, eta_dot)` on 1-D float64 arrays in a Python loop, minus the C++
  loop's time per state: the call's overhead, target ≤ 1 µs; beside it the same call with
  one argument a list (the general path, converted) and the batch on two threads.

Medians of REPS repetitions (interleaved: batch, C++ loop, single calls). Writes a JSON
file and, with --doc, the table between the markers in docs/performance.md.

usage: PYTHONPATH=<build>/python python3 bench/python_bench.py OUT.json [--doc docs/performance.md] [--reps 7]
"""
import json
import os
import platform
import statistics
import sys
import time

import numpy as np

import nhdyn

BEGIN, END = "<!-- python_bench:begin -->", "<!-- python_bench:end -->"


def build_flags():
    """The compiler and Release flags of the build the module comes from (its CMakeCache.txt)."""
    cache = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(nhdyn.__file__))), "CMakeCache.txt")
    try:
        entries = dict(line.split("=", 1) for line in open(cache).read().splitlines() if "=" in line and not line.startswith(("#", "//")))
    except OSError:
        return "flags unknown"
    compiler = os.path.basename(entries.get("CMAKE_CXX_COMPILER:FILEPATH", entries.get("CMAKE_CXX_COMPILER:STRING", "c++")))
    flags = " ".join(x for x in (entries.get("CMAKE_CXX_FLAGS:STRING", ""), entries.get("CMAKE_CXX_FLAGS_RELEASE:STRING", "")) if x)
    return f"{compiler} {flags}".strip()


def main():
    out = sys.argv[1]
    doc = sys.argv[sys.argv.index("--doc") + 1] if "--doc" in sys.argv else None
    reps = int(sys.argv[sys.argv.index("--reps") + 1]) if "--reps" in sys.argv else 7
    m = nhdyn.load("paper5")
    f = nhdyn.inverse_dynamics(m)
    n_states, n_calls = 1_000_000, 200_000
    rng = np.random.default_rng(1)
    Q = rng.uniform(-1, 1, (n_states, m.dof))
    E = rng.uniform(-1, 1, (n_states, m.m))
    ED = rng.uniform(-1, 1, (n_states, m.m))
    # the two computations agree to the last bit (the same library call on the same rows)
    assert np.array_equal(f(Q[:1000], E[:1000], ED[:1000]), nhdyn._cxx_loop_inverse_dynamics(m, Q[:1000], E[:1000], ED[:1000]))
    q, e, ed = Q[0].copy(), E[0].copy(), ED[0].copy()
    el = e.tolist()
    batch, loop, single, general, two = [], [], [], [], []
    for _ in range(reps):
        t = time.perf_counter()
        f(Q, E, ED)
        batch.append((time.perf_counter() - t) / n_states)
        t = time.perf_counter()
        nhdyn._cxx_loop_inverse_dynamics(m, Q, E, ED)
        loop.append((time.perf_counter() - t) / n_states)
        t = time.perf_counter()
        for _ in range(n_calls):
            f(q, e, ed)
        single.append((time.perf_counter() - t) / n_calls)
        t = time.perf_counter()
        for _ in range(n_calls // 4):
            f(q, el, ed)
        general.append((time.perf_counter() - t) / (n_calls // 4))
        t = time.perf_counter()
        f(Q, E, ED, threads=2)
        two.append((time.perf_counter() - t) / n_states)
    b, c, s = statistics.median(batch), statistics.median(loop), statistics.median(single)
    g, b2 = statistics.median(general), statistics.median(two)
    res = {"batch_ns_per_state": b * 1e9, "cxx_loop_ns_per_state": c * 1e9, "batch_over_cxx": b / c,
           "single_call_us": s * 1e6, "single_call_overhead_us": (s - c) * 1e6, "general_path_call_us": g * 1e6,
           "batch_two_threads_ns_per_state": b2 * 1e9, "states": n_states, "calls": n_calls,
           "reps": reps, "python": platform.python_version(), "numpy": np.__version__}
    with open(out, "w") as fh:
        json.dump(res, fh, indent=1)
    when = time.strftime("%Y-%m-%d")
    table = "\n".join([
        BEGIN,
        f"Measured {when}, Python {platform.python_version()}, NumPy {np.__version__}, the module built in "
        f"`{os.path.basename(os.path.dirname(os.path.dirname(os.path.abspath(nhdyn.__file__))))}/` ({build_flags()}); "
        f"medians of {reps}:",
        "",
        f"| measure (paper5 nonholonomic inverse dynamics) | value | target | met |",
        "|---|---:|---:|---|",
        f"| batch of 10⁶ states from Python, per state | {b * 1e9:.0f} ns | | |",
        f"| the same rows in a C++ loop (same module, same arrays), per state | {c * 1e9:.0f} ns | | |",
        f"| batch / C++ loop | {b / c:.2f}× | ≤ 1.5× | {'yes' if b / c <= 1.5 else 'NO'} |",
        f"| one state from Python (1-D arrays), per call | {s * 1e6:.2f} µs | | |",
        f"| its overhead over the C++ call | {(s - c) * 1e6:.2f} µs | ≤ 1 µs | {'yes' if s - c <= 1e-6 else 'NO'} |",
        f"| one state with eta a list (the general path: converted), per call | {g * 1e6:.2f} µs | | |",
        f"| batch of 10⁶ states on two threads, per state | {b2 * 1e9:.0f} ns | | |",
        END])
    print(table)
    if doc:
        text = open(doc).read()
        if BEGIN in text:
            text = text[:text.index(BEGIN)] + table + text[text.index(END) + len(END):]
            open(doc, "w").write(text)
        else:
            print(f"python_bench: no markers in {doc}; table not written", file=sys.stderr)


if __name__ == "__main__":
    main()
