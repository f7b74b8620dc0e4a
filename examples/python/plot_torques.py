"""A plot of paper5's actuator torques along a motion (matplotlib, no display needed).

    PYTHONPATH=build/python python3 examples/python/plot_torques.py [out.png]
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import nhdyn

robot = nhdyn.load("paper5")
t = np.linspace(0.0, 4.0, 401)
eta = np.column_stack([0.4 * np.sin(t), 0.3 * np.cos(t), np.sin(2 * t), np.cos(2 * t)])
eta_dot = np.column_stack([0.4 * np.cos(t), -0.3 * np.sin(t), 2 * np.cos(2 * t), -2 * np.sin(2 * t)])
q = np.column_stack([np.zeros_like(t), np.zeros_like(t), 0.3 * np.sin(t), 2.0 + 0.5 * np.sin(t), 1.0 + np.cos(t)])
tau = nhdyn.inverse_dynamics(robot)(q, eta, eta_dot)

fig, ax = plt.subplots(len(robot.eta), 1, sharex=True, figsize=(7, 8))
units = ["N", "N m", "N m", "N m"]
for j, name in enumerate(robot.eta):
    ax[j].plot(t, tau[:, j])
    ax[j].set_ylabel(f"tau[{name}] [{units[j]}]")
ax[-1].set_xlabel("t [s]")
fig.suptitle("paper5: actuator torques, project o rne o lift")
out = sys.argv[1] if len(sys.argv) > 1 else "paper5_torques.png"
fig.savefig(out, dpi=80)
print("wrote", out)
