"""LQR for paper5 about a straight-line motion, from the exact linearisation (nhdyn.linearize)
and SciPy's Riccati solver, then simulated on the full nonlinear nonholonomic dynamics
(nhdyn.state_derivative, RK4) — the Python twin of examples/lqr_paper5.cpp.

    PYTHONPATH=build/python python3 examples/python/lqr_paper5.py
"""
import numpy as np
import scipy.linalg

import nhdyn

robot = nhdyn.load("paper5")
idyn, lin, xdot = nhdyn.inverse_dynamics(robot), nhdyn.linearize(robot), nhdyn.state_derivative(robot)

v0 = 0.5
q0, eta_ref = np.array([0.0, 0.0, 0.3, 0.6, -0.8]), np.array([v0, 0.0, 0.0, 0.0])
tau_ref = idyn(q0, eta_ref, np.zeros(4))
qdot_ref = xdot(q0, eta_ref, tau_ref)[:5]
x_ref = lambda t: np.concatenate([q0 + qdot_ref * t, eta_ref])

A, B = lin(q0, eta_ref, tau_ref)
ctrb = np.hstack([np.linalg.matrix_power(A, i) @ B for i in range(9)])
ctrb /= np.maximum(np.linalg.norm(ctrb, axis=0), 1e-300)
print("controllability rank at v0 = 0.5:", np.linalg.matrix_rank(ctrb, tol=1e-9), "of 9")

Q = np.diag([10, 10, 10, 10, 10, 1, 1, 0.1, 0.1])
R = np.diag([0.05, 0.05, 100, 100])
P = scipy.linalg.solve_continuous_are(A, B, Q, R)
K = np.linalg.solve(R, B.T @ P)
print("closed-loop max real part:", np.linalg.eigvals(A - B @ K).real.max(), "1/s")

x = x_ref(0.0) + np.array([0.05, 0.10, 0.10, 0.10, -0.10, 0.05, 0, 0, 0])
e0 = np.linalg.norm(x - x_ref(0.0))
f = lambda t, s: xdot(s[:5], s[5:], tau_ref - K @ (s - x_ref(t)))
dt, T = 2e-3, 10.0
for k in range(int(round(T / dt))):
    t = k * dt
    k1 = f(t, x)
    k2 = f(t + dt / 2, x + dt / 2 * k1)
    k3 = f(t + dt / 2, x + dt / 2 * k2)
    k4 = f(t + dt, x + dt * k3)
    x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
e = np.linalg.norm(x - x_ref(T))
print(f"|x - x_ref|: {e0:.3e} at t = 0, {e:.3e} at t = {T:.0f} s")
assert e < 1e-2 * e0, "the LQR did not bring the robot back to the line"
