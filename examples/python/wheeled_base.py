"""Every wheeled base from Python: the shipped base on four driven castors (a PR2,
examples/robots/powered_castors_arm.json) drives sideways and turns. Eight actuators (each
castor's swivel and wheel) drive three base velocities: nhdyn returns the torques of least
norm (a robot file's "weights" make it a weighted norm); any torques that differ from them by
a squeeze (zero in S^T E) give the same motion.

    PYTHONPATH=build/python python3 examples/python/wheeled_base.py
"""
import os

import numpy as np

import nhdyn

here = os.path.dirname(os.path.abspath(__file__))
robot = nhdyn.load(os.path.join(here, "..", "robots", "powered_castors_arm.json"))
print(robot, "m =", robot.m, "p =", robot.p)
print("eta:", robot.eta[:4], "...")
print("tau:", robot.tau[:8], "...")

inverse = nhdyn.inverse_dynamics_with_forces(robot)
forward = nhdyn.forward_dynamics(robot)

# sideways at 0.4 m/s (world y) while turning at 0.3 rad/s, accelerating; the castors turned
q = np.zeros(robot.dof)
for j, name in enumerate(robot.joints):
    if name.endswith("caster_rotation_joint"):
        q[j] = 1.2                     # every castor already points roughly sideways
eta = np.zeros(robot.m)
eta_dot = np.zeros(robot.m)
eta[1], eta[2] = 0.4, 0.3              # base_y rate [m/s], base_yaw rate [rad/s]
eta_dot[1] = 0.5

tau, lam = inverse(q, eta, eta_dot)
back = forward(q, eta, tau)
assert np.allclose(back, eta_dot, atol=1e-9), (back, eta_dot)
print("castor torques [N m]:", np.array2string(tau[:8], precision=3))
print("floor forces on the wheels [N]:", np.array2string(lam, precision=2))

# The same motion with other torques: the least-norm tau plus any vector that S^T E maps to 0
# (found here numerically) gives the same eta_dot, with a larger norm.
lin = nhdyn.linearize(robot)
A, B = lin(q, eta, tau)                # B: (n + m) x p, its last m rows are M_eta^-1 S^T E
Bm = B[robot.dof:, :]
_, _, vt = np.linalg.svd(Bm)
squeeze = vt[-1]                       # a direction of tau with no effect on eta_dot
other = tau + 20.0 * squeeze
assert np.allclose(forward(q, eta, other), eta_dot, atol=1e-8)
assert np.linalg.norm(other) > np.linalg.norm(tau)
print(f"|tau| = {np.linalg.norm(tau):.3f} (least), |tau + squeeze| = {np.linalg.norm(other):.3f}, the same eta_dot")
