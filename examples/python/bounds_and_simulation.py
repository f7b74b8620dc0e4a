"""Guaranteed torque bounds and a closed-loop simulation from Python.

    PYTHONPATH=build/python python3 examples/python/bounds_and_simulation.py [out.png]

1. The actuator torques paper5 can need anywhere in a box of states (interval arithmetic:
   every torque in the box lies inside, whatever the sampling would miss), tightened by
   bisecting the box, and checked against 10 000 sampled states in one batch.
2. The shipped mobile manipulator tracking a circle with its tool frame (a robot file's
   scene), the result as NumPy arrays; with a path given, a figure of the tracking error.
"""
import sys

import numpy as np

import nhdyn

robot = nhdyn.load("paper5")
q = np.array([0.0, 0.0, 0.3, 2.0, 1.2])
eta, eta_dot = np.array([0.5, 0.2, 0.3, -0.3]), np.zeros(4)
dq, de, dd = np.array([0, 0, 0.05, 0.05, 0.05]), np.full(4, 0.05), np.full(4, 0.2)
box = (q - dq, q + dq, eta - de, eta + de, eta_dot - dd, eta_dot + dd)
rng = np.random.default_rng(0)
k = 10_000
samples = nhdyn.inverse_dynamics(robot)(*(lo + (hi - lo) * rng.uniform(size=(k, lo.size))
                                          for lo, hi in zip(box[::2], box[1::2])), threads=2)
print("sampled tau range:  ", np.array2string(samples.min(axis=0), precision=3), "…",
      np.array2string(samples.max(axis=0), precision=3))
for split in (0, 4, 8):
    lo, hi = nhdyn.torque_bounds(robot, split=split)(*box)
    assert np.all(lo <= samples.min(axis=0)) and np.all(samples.max(axis=0) <= hi)
    print(f"guaranteed (split {split}):", np.array2string(lo, precision=3), "…", np.array2string(hi, precision=3))

(run,) = nhdyn.simulate("mobile-manipulator-circle")
print(f"{run['name']}: success {run['success']}, tail error {1e3 * run['max_tail_error']:.4f} mm, "
      f"{run['steps']} steps in {1e3 * run['cpu_time_s']:.0f} ms CPU; q {run['q'].shape}, tau {run['tau'].shape}")
assert run["success"]
if len(sys.argv) > 1:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    ax[0].semilogy(run["t"], run["err"])
    ax[0].set_ylabel("|r_d - r| [m]")
    names = [c[len("tau_"):] for c in run["columns"] if c.startswith("tau_")]
    for j in (0, 1, names.index("arm_2_joint"), names.index("arm_4_joint")):
        ax[1].plot(run["t"], run["tau"][:, j], label=names[j])
    ax[1].set_xlabel("t [s]")
    ax[1].set_ylabel("tau [N, N m]")
    ax[1].legend()
    fig.suptitle("mobile-manipulator-circle from nhdyn.simulate")
    fig.savefig(sys.argv[1], dpi=90)
    print("wrote", sys.argv[1])
