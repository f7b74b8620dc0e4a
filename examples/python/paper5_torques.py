"""The paper's inverse dynamics from Python: paper5's actuator torques and constraint force
along a motion, one state at a time and as one batch (the same numbers).

    PYTHONPATH=build/python python3 examples/python/paper5_torques.py
"""
import numpy as np

import nhdyn

robot = nhdyn.load("paper5")
print(robot, "q:", robot.joints, "eta:", robot.eta)
id_forces = nhdyn.inverse_dynamics_with_forces(robot)

# a motion: the base drives forward while turning, the arm swings
t = np.linspace(0.0, 2.0, 201)
eta = np.column_stack([0.3 + 0.1 * t, 0.2 * np.ones_like(t), np.sin(t), np.cos(t)])
eta_dot = np.column_stack([0.1 * np.ones_like(t), np.zeros_like(t), np.cos(t), -np.sin(t)])
q = np.zeros((len(t), 5))
q[:, 2] = 0.2 * t          # heading (the base position does not change the dynamics)
q[:, 3] = 2.05 - np.cos(t) + 1.0
q[:, 4] = 1.2 + np.sin(t)

tau, lam = id_forces(q, eta, eta_dot)          # one batch: 201 rows
for k in (0, 100, 200):
    one_tau, one_lam = id_forces(q[k], eta[k], eta_dot[k])
    assert np.array_equal(one_tau, tau[k]) and np.array_equal(one_lam, lam[k])
    print(f"t = {t[k]:.1f} s: tau = {np.array2string(tau[k], precision=4)}, lambda = {lam[k][0]:.4f} N")
print("peak |tau| per actuator:", np.array2string(np.abs(tau).max(axis=0), precision=4))
