"""The Python module against the C++ library (through the nhdyn tool, whose JSON numbers
read back bit for bit), against a closed form computed here in NumPy, and its batches,
threads, dtypes and errors. Run by ctest (python_tests) with PYTHONPATH at the built module."""
import json
import os
import subprocess

import numpy as np
import pytest

import nhdyn

SOURCE = os.environ.get("NHDYN_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.environ.get("NHDYN_TOOL")


def tool(model, lines):
    """Runs `nhdyn id|fd --model MODEL` on JSON lines; returns the parsed output lines."""
    if not TOOL:
        pytest.skip("NHDYN_TOOL not set (the tool was not built)")
    out = subprocess.run([TOOL, *model], input="\n".join(json.dumps(l) for l in lines) + "\n",
                         capture_output=True, text=True, check=True).stdout
    return [json.loads(l) for l in out.splitlines()]


def load_robot_or_skip(path):
    """nhdyn.load(path) of a robot file; the test is skipped when nhdyn was built without URDF support."""
    try:
        return nhdyn.load(path)
    except nhdyn.ModelError as e:
        if "without URDF support" in str(e):
            pytest.skip(str(e))
        raise


def test_models_load_with_names_and_sizes():
    assert "paper5" in nhdyn.presets() and "puma560_motors" in nhdyn.presets()
    p = nhdyn.load("paper5")
    assert (p.name, p.dof, p.m, p.k, p.constrained) == ("paper5", 5, 4, 1, True)
    assert p.joints == ["joint1", "joint2", "joint3", "joint4", "joint5"]
    assert len(p.eta) == 4
    puma = nhdyn.load(os.path.join(SOURCE, "examples", "models", "puma560.json"))
    assert (puma.dof, puma.k, puma.constrained) == (6, 0, False)
    assert "paper5" in repr(p)


def test_values_equal_the_cpp_library_to_the_last_bit():
    rng = np.random.default_rng(1)
    puma = nhdyn.load("puma560")
    q, qd, qdd = rng.uniform(-2, 2, (3, 6))
    (ref,) = tool(["id", "--model", "puma560"], [{"q": q.tolist(), "qd": qd.tolist(), "qdd": qdd.tolist()}])
    assert np.array_equal(nhdyn.rne(puma)(q, qd, qdd), np.array(ref["tau"]))
    (fd,) = tool(["fd", "--model", "puma560"], [{"q": q.tolist(), "qd": qd.tolist(), "tau": qdd.tolist()}])
    assert np.array_equal(nhdyn.forward_dynamics(puma)(q, qd, qdd), np.array(fd["qdd"]))
    p = nhdyn.load("paper5")
    q, eta, eta_dot = rng.uniform(-1, 1, 5), rng.uniform(-1, 1, 4), rng.uniform(-1, 1, 4)
    (ref,) = tool(["id", "--model", "paper5"], [{"q": q.tolist(), "eta": eta.tolist(), "eta_dot": eta_dot.tolist()}])
    tau, lam = nhdyn.inverse_dynamics_with_forces(p)(q, eta, eta_dot)
    assert np.array_equal(tau, np.array(ref["tau"])) and np.array_equal(lam, np.array(ref["lambda"]))
    assert np.array_equal(nhdyn.inverse_dynamics(p)(q, eta, eta_dot), tau)


def test_a_planar_two_link_arm_equals_its_closed_form_computed_in_numpy(tmp_path):
    l1, l2, m1, m2, g = 0.7, 0.5, 3.0, 2.0, 9.81
    link = lambda l, m: {"joint": "revolute", "alpha": 0, "a": l, "theta": 0, "d": 0, "mass": m,
                         "com": [-l / 2, 0, 0], "inertia": [[0, 0, 0], [0, m * l * l / 12, 0], [0, 0, m * l * l / 12]]}
    path = tmp_path / "arm.json"
    path.write_text(json.dumps({"name": "arm", "gravity": [0, -g, 0], "links": [link(l1, m1), link(l2, m2)]}))
    arm = nhdyn.load(str(path))
    rng = np.random.default_rng(2)
    for _ in range(10):
        q, qd, qdd = rng.uniform(-2, 2, (3, 2))
        c2, I1, I2, a1, a2 = np.cos(q[1]), m1 * l1**2 / 12, m2 * l2**2 / 12, l1 / 2, l2 / 2
        M = np.array([[I1 + I2 + m1 * a1**2 + m2 * (l1**2 + a2**2 + 2 * l1 * a2 * c2), I2 + m2 * (a2**2 + l1 * a2 * c2)],
                      [I2 + m2 * (a2**2 + l1 * a2 * c2), I2 + m2 * a2**2]])
        h = m2 * l1 * a2 * np.sin(q[1])
        C = np.array([-h * qd[1] * (2 * qd[0] + qd[1]), h * qd[0] ** 2])
        G = g * np.array([(m1 * a1 + m2 * l1) * np.cos(q[0]) + m2 * a2 * np.cos(q[0] + q[1]), m2 * a2 * np.cos(q[0] + q[1])])
        assert np.allclose(nhdyn.mass_matrix(arm)(q), M, rtol=1e-13, atol=1e-13)
        assert np.allclose(nhdyn.rne(arm)(q, qd, qdd), M @ qdd + C + G, rtol=1e-12, atol=1e-12)
        assert np.allclose(nhdyn.bias(arm)(q, qd), C + G, rtol=1e-12, atol=1e-12)
        assert np.allclose(nhdyn.forward_dynamics(arm)(q, qd, M @ qdd + C + G), qdd, rtol=1e-10, atol=1e-10)
        # kinematics: the tip's pose and Jacobian
        s1, c1, s12, c12 = np.sin(q[0]), np.cos(q[0]), np.sin(q[0] + q[1]), np.cos(q[0] + q[1])
        T = nhdyn.frame(arm, "link2")(q)
        assert np.allclose(T[:3, 3], [l1 * c1 + l2 * c12, l1 * s1 + l2 * s12, 0], atol=1e-15)
        assert np.allclose(T[:3, :3], [[c12, -s12, 0], [s12, c12, 0], [0, 0, 1]], atol=1e-15)
        J = nhdyn.jacobian(arm, "link2")(q)
        assert np.allclose(J, [[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12], [0, 0], [0, 0], [0, 0], [1, 1]], atol=1e-15)


def test_batches_equal_row_by_row_calls_on_any_number_of_threads():
    p = nhdyn.load("paper5")
    rng = np.random.default_rng(3)
    N = 257
    q, eta, eta_dot = rng.uniform(-1, 1, (N, 5)), rng.uniform(-1, 1, (N, 4)), rng.uniform(-1, 1, (N, 4))
    f = nhdyn.inverse_dynamics(p)
    batch = f(q, eta, eta_dot)
    assert batch.shape == (N, 4)
    rows = np.array([f(q[i], eta[i], eta_dot[i]) for i in range(N)])
    assert np.array_equal(batch, rows)
    assert np.array_equal(f(q, eta, eta_dot, threads=2), batch)
    assert np.array_equal(f(q, eta, eta_dot, threads=7), batch)
    M = nhdyn.mass_matrix(p)(q[:3])
    assert M.shape == (3, 5, 5) and np.array_equal(M[1], nhdyn.mass_matrix(p)(q[1]))
    tau, lam = nhdyn.inverse_dynamics_with_forces(p)(q, eta, eta_dot)
    assert tau.shape == (N, 4) and lam.shape == (N, 1)


def test_dtypes_are_converted_or_refused():
    puma = nhdyn.load("puma560")
    z = np.zeros(6)
    ref = nhdyn.rne(puma)(z, z, z)
    assert np.array_equal(nhdyn.rne(puma)(np.zeros(6, dtype=int), [0] * 6, np.zeros(6, dtype=np.float32)), ref)
    with pytest.raises(TypeError, match="dtype"):
        nhdyn.rne(puma)(np.zeros(6, dtype=complex), z, z)
    with pytest.raises(TypeError, match="takes 3 arrays"):
        nhdyn.rne(puma)(z, z)


def test_errors_carry_the_library_messages():
    puma = nhdyn.load("puma560")
    z = np.zeros(6)
    with pytest.raises(ValueError, match="'q' has 5 entries; the model needs 6"):
        nhdyn.rne(puma)(np.zeros(5), z, z)
    bad = z.copy()
    bad[2] = np.nan
    with pytest.raises(nhdyn.InputError, match=r"qd\[2\] is not finite"):
        nhdyn.rne(puma)(z, bad, z)
    with pytest.raises(nhdyn.InputError, match=r"row 1: .*qd\[2\] is not finite"):
        nhdyn.rne(puma)(np.zeros((2, 6)), np.vstack([z, bad]), np.zeros((2, 6)))
    with pytest.raises(nhdyn.ModelError, match="no such file"):
        nhdyn.load("no/such/model.json")
    with pytest.raises(nhdyn.ModelError, match="has no constraint"):
        nhdyn.inverse_dynamics_with_forces(puma)
    with pytest.raises(ValueError, match="rows"):
        nhdyn.rne(puma)(np.zeros((2, 6)), np.zeros((3, 6)), np.zeros((2, 6)))
    assert issubclass(nhdyn.NumericalError, ArithmeticError)


def test_help_shows_signatures_and_units():
    assert "f(q, qd, qdd) -> tau" in nhdyn.rne.__doc__ and "N m" in nhdyn.rne.__doc__
    assert "rne(q[6], qd[6], qdd[6]) -> tau[6]" == nhdyn.rne(nhdyn.load("puma560")).signature
    assert "eta_dot" in nhdyn.forward_dynamics.__doc__


@pytest.mark.skipif(not hasattr(nhdyn, "load"), reason="")
def test_a_robot_file_runs_the_papers_method():
    path = os.path.join(SOURCE, "examples", "robots", "mobile_manipulator_wheels.json")
    r = load_robot_or_skip(path)
    assert (r.dof, r.k, r.eta[0]) == (19, 3, "wheel_left_joint")
    rng = np.random.default_rng(4)
    q, eta, eta_dot = rng.uniform(-1, 1, r.dof), rng.uniform(-1, 1, r.m), rng.uniform(-1, 1, r.m)
    tau = nhdyn.inverse_dynamics(r)(q, eta, eta_dot)
    assert np.allclose(nhdyn.forward_dynamics(r)(q, eta, tau), eta_dot, rtol=1e-10, atol=1e-10)
    # the tool point's Jacobian against central differences of its position, in NumPy
    pose, J = nhdyn.frame(r, "tool_frame"), nhdyn.jacobian(r, "tool_frame", (0.0, 0.0, 0.05))
    point = lambda x: (pose(x) @ np.array([0, 0, 0.05, 1]))[:3]
    h, Jq = 1e-6, J(q)
    num = np.column_stack([(point(q + h * e) - point(q - h * e)) / (2 * h) for e in np.eye(r.dof)])
    assert np.allclose(Jq[:3], num, atol=1e-8)
    with pytest.raises(nhdyn.InputError, match="no body named 'nowhere'"):
        nhdyn.frame(r, "nowhere")


def test_linearize_equals_central_differences_of_forward_dynamics():
    rng = np.random.default_rng(5)
    puma = nhdyn.load("puma560")
    q, qd, tau = rng.uniform(-1, 1, (3, 6))
    A, B = nhdyn.linearize(puma)(q, qd, tau)
    fd, h, n = nhdyn.forward_dynamics(puma), 1e-6, 6
    x = np.concatenate([q, qd])
    f = lambda x, u: np.concatenate([x[n:], fd(x[:n], x[n:], u)])
    An = np.column_stack([(f(x + h * e, tau) - f(x - h * e, tau)) / (2 * h) for e in np.eye(2 * n)])
    Bn = np.column_stack([(f(x, tau + h * e) - f(x, tau - h * e)) / (2 * h) for e in np.eye(n)])
    assert np.allclose(A, An, atol=1e-6 * (1 + abs(An).max())) and np.allclose(B, Bn, atol=1e-6 * (1 + abs(Bn).max()))
    # constrained: the eta_dot rows against differences of the constrained forward dynamics
    p = nhdyn.load("paper5")
    q, eta, tau = rng.uniform(-1, 1, 5), rng.uniform(-1, 1, 4), rng.uniform(-1, 1, 4)
    A, B = nhdyn.linearize(p)(q, eta, tau)
    assert A.shape == (9, 9) and B.shape == (9, 4)
    fd = nhdyn.forward_dynamics(p)
    x = np.concatenate([q, eta])
    g = lambda x, u: fd(x[:5], x[5:], u)
    An = np.column_stack([(g(x + h * e, tau) - g(x - h * e, tau)) / (2 * h) for e in np.eye(9)])
    Bn = np.column_stack([(g(x, tau + h * e) - g(x, tau - h * e)) / (2 * h) for e in np.eye(4)])
    assert np.allclose(A[5:], An, atol=1e-6 * (1 + abs(An).max())) and np.allclose(B[5:], Bn, atol=1e-6 * (1 + abs(Bn).max()))
    assert np.array_equal(B[:5], np.zeros((5, 4)))


def test_torque_bounds_enclose_every_sampled_torque_and_tighten_with_splitting():
    # an independent check of the enclosure: 2000 point evaluations inside the box (a batch)
    p = nhdyn.load("paper5")
    rng = np.random.default_rng(5)
    q, eta, eta_dot = rng.uniform(-1, 1, 5), rng.uniform(-1, 1, 4), rng.uniform(-1, 1, 4)
    w = 0.02
    lo, hi = nhdyn.torque_bounds(p)(q - w, q + w, eta - w, eta + w, eta_dot - w, eta_dot + w)
    lo2, hi2 = nhdyn.torque_bounds(p, split=3)(q - w, q + w, eta - w, eta + w, eta_dot - w, eta_dot + w)
    k = 2000
    Q = q + rng.uniform(-w, w, (k, 5))
    E, ED = eta + rng.uniform(-w, w, (k, 4)), eta_dot + rng.uniform(-w, w, (k, 4))
    tau = nhdyn.inverse_dynamics(p)(Q, E, ED, threads=2)
    assert np.all(tau >= lo2) and np.all(tau <= hi2)
    assert np.all(lo <= lo2) and np.all(hi2 <= hi) and np.any(hi2 - lo2 < hi - lo)
    # the bounds are not vacuous: measured 1.1-4.4x the sampled spread at split=3 (interval
    # arithmetic's dependency effect; samples also miss the corners of the true range)
    assert np.all(hi2 - lo2 < 10 * (tau.max(axis=0) - tau.min(axis=0)))
    # holonomic models bound rne; batches are one box per row
    puma = nhdyn.load("puma560")
    Z = np.zeros((2, 6))
    blo, bhi = nhdyn.torque_bounds(puma)(Z - 0.1, Z + 0.1, Z, Z, Z, Z)
    assert blo.shape == (2, 6) and np.all(blo <= bhi)
    g = nhdyn.rne(puma)(np.zeros(6), np.zeros(6), np.zeros(6))
    assert np.all(blo[0] <= g) and np.all(g <= bhi[0])
    with pytest.raises(nhdyn.InputError, match=r"q\[0\]"):
        nhdyn.torque_bounds(p)(q + w, q - w, eta, eta, eta_dot, eta_dot)


def test_simulate_gives_the_tools_rows_bit_for_bit_and_names_the_columns(tmp_path):
    scene = {"name": "py-circle", "duration": 2, "success": {"tail_from": 1.5, "max_tail_error": 1}}
    (run,) = nhdyn.simulate(scene)
    assert run["success"] and run["failure"] is None
    assert run["data"].shape == (201, 21) and run["q"].shape == (201, 5) and run["tau"].shape == (201, 4)
    assert run["columns"][:2] == ["t", "q1"] and run["columns"][-1] == "err"
    assert np.array_equal(run["err"], np.linalg.norm(run["rd"] - run["r"], axis=1))
    if not TOOL:
        pytest.skip("NHDYN_TOOL not set (the tool was not built)")
    path = tmp_path / "py-circle.json"
    path.write_text(json.dumps(scene))
    subprocess.run([TOOL, "simulate", str(path), "--out", str(tmp_path / "out"), "--no-plots"], check=True,
                   capture_output=True)
    csv = np.loadtxt(tmp_path / "out" / "py-circle.csv", delimiter=",", skiprows=1)
    assert np.array_equal(csv, run["data"])
    # a robot file's scene: columns from its names; a study: one dict per run
    (mm,) = nhdyn.simulate(os.path.join(SOURCE, "examples", "scenes", "mobile-manipulator-circle.json"))
    assert mm["success"] and mm["q"].shape[1] == 19 and mm["eta"].shape[1] == 18
    assert mm["columns"][1] == "q_base_x" and "tau_arm_1_joint" in mm["columns"]
    runs = nhdyn.simulate({"name": "mc", "study": {"base": scene, "monte_carlo": {"runs": 3, "seed": 1},
                           "factors": [{"path": "/plant/d3_factor", "distribution": {"uniform": [0.95, 1.05]}}]}}, threads=2)
    assert [r["name"] for r in runs] == ["mc-0", "mc-1", "mc-2"] and all(r["seed"] is not None for r in runs)
    with pytest.raises(nhdyn.InputError, match="controller.K2"):
        nhdyn.simulate({"name": "bad", "controller": {"K2": 1}})
    # a run that cannot be set up is a failed run (no rows), not a crash or an exception
    robot = os.path.join(SOURCE, "examples", "robots", "mobile_manipulator.json")
    (bad,) = nhdyn.simulate({"name": "nowhere", "robot": robot, "task": {"frame": "no_such_frame"}})
    assert not bad["success"] and "no_such_frame" in bad["failure"] and bad["data"].shape == (0, 0)


def test_a_python_controller_drives_a_scene_as_the_same_law_in_cpp_does():
    # Joint-space computed torque written here in NumPy on nhdyn.rne (the DH chain's kernel)
    # against the library's computed_torque controller (the tree pipeline): the same law by
    # two implementations, the same closed loop.
    kp, kd = 400.0, 40.0
    scene = {"name": "ct", "robot": "puma560", "task": {"frame": "link6"},
             "controller": {"type": "computed_torque", "kp": kp, "kd": kd},
             "initial": {"q": [0.05, -0.55, 0.45, 0.25, -0.45, 0.75]},
             "reference": {"type": "joint_spline", "times": [0, 1, 2],
                           "q": [[0, -0.6, 0.4, 0.3, -0.5, 0.7], [0.5, -0.3, 0.6, 0, 0, 1], [0.2, -0.5, 0.5, 0.2, -0.2, 0.9]]},
             "integrator": {"rtol": 1e-9, "atol": 1e-11},
             "duration": 2.5, "success": {"tail_from": 2, "max_tail_error": 1e-4}}
    (lib,) = nhdyn.simulate(scene)
    rne = nhdyn.rne(nhdyn.load("puma560"))
    calls = []

    def ct(q, eta, r, ref):
        calls.append(1)
        assert q.shape == (6,) and eta.shape == (6,) and r.shape == (3,) and ref["qdd"].shape == (6,)
        return rne(q, eta, ref["qdd"] + kd * (ref["qd"] - eta) + kp * (ref["q"] - q))

    (mine,) = nhdyn.simulate(scene, controller=ct)
    assert lib["success"] and mine["success"], (lib["failure"], mine["failure"])
    assert len(calls) > 100
    assert lib["q"].shape == mine["q"].shape
    assert np.max(np.abs(lib["q"] - mine["q"])) < 1e-9
    assert np.max(np.abs(lib["tau"] - mine["tau"])) < 1e-6
    # a controller that raises, or returns the wrong size, fails the run with the reason
    def broken(q, eta, r, ref):
        raise RuntimeError("sensor offline")

    (bad,) = nhdyn.simulate(scene, controller=broken)
    assert not bad["success"] and "sensor offline" in bad["failure"]
    (short,) = nhdyn.simulate(scene, controller=lambda q, eta, r, ref: np.zeros(2))
    assert not short["success"] and "6 numbers" in short["failure"]
    with pytest.raises(nhdyn.InputError, match="callable"):
        nhdyn.simulate(scene, controller=3)
    # Ctrl-C in the controller stops a study: the KeyboardInterrupt comes back, after one call
    study = {"name": "ct-study", "study": {"base": scene, "factors": [{"path": "/controller/kp", "levels": [300, 400, 500]}]}}
    seen = []

    def interrupted(q, eta, r, ref):
        seen.append(1)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        nhdyn.simulate(study, controller=interrupted)
    assert len(seen) == 1


def test_wrenches_and_friction_from_python():
    rng = np.random.default_rng(5)
    # External wrenches: rne with them = rne - J^T [f; m], the Jacobian of the same point
    # (nhdyn.jacobian, in the world's axes) and the sign the docs state.
    puma = nhdyn.load("puma560")
    q, qd, qdd = (rng.uniform(-1, 1, 6) for _ in range(3))
    point, force, moment = np.array([0.01, 0.02, 0.05]), np.array([3.0, -2.0, 5.0]), np.array([0.4, 0.1, -0.3])
    w = [{"body": "link6", "point": point, "force": force, "moment": moment}]
    # the point's Jacobian by central differences of its pose (nhdyn.frame): velocity rows
    # from the point's position, angular rows from R(q + h e_j) R(q - h e_j)^T
    pose = nhdyn.frame(puma, "link6")
    h, J = 1e-6, np.zeros((6, 6))
    for j in range(6):
        d = np.zeros(6)
        d[j] = h
        Tp, Tm = pose(q + d), pose(q - d)
        J[:3, j] = (Tp[:3, :3] @ point + Tp[:3, 3] - Tm[:3, :3] @ point - Tm[:3, 3]) / (2 * h)
        W = Tp[:3, :3] @ Tm[:3, :3].T
        J[3:, j] = np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]]) / (4 * h)
    want = nhdyn.rne(puma)(q, qd, qdd) - J[:3].T @ force - J[3:].T @ moment
    got = nhdyn.rne(puma, wrenches=w)(q, qd, qdd)
    assert np.max(np.abs(got - want)) < 1e-7 * max(1.0, np.max(np.abs(want)))
    assert np.array_equal(nhdyn.rne(puma)(q, qd, qdd) - nhdyn.generalized_force(puma, w)(q), got)
    assert np.array_equal(nhdyn.rne(puma, wrenches=[])(q, qd, qdd), nhdyn.rne(puma)(q, qd, qdd))
    # body axes: the same wrench rotated into the body frame is the same physics
    R = nhdyn.frame(puma, "link6")(q)[:3, :3]
    wb = [{"body": "link6", "frame": "body", "point": point, "force": R.T @ force, "moment": R.T @ moment}]
    assert np.allclose(nhdyn.rne(puma, wrenches=wb)(q, qd, qdd), got, rtol=0, atol=1e-11)
    # forward dynamics with the same wrenches inverts rne with them
    assert np.allclose(nhdyn.forward_dynamics(puma, wrenches=w)(q, qd, got), qdd, rtol=0, atol=1e-9)
    # constrained: paper5 pushed at its tip; forward dynamics inverts inverse dynamics
    p5 = nhdyn.load("paper5")
    q5, e, ed = rng.uniform(-1, 1, 5), rng.uniform(-1, 1, 4), rng.uniform(-1, 1, 4)
    push = [{"body": "link5", "force": [0, 5.0, -3.0]}]
    tau = nhdyn.inverse_dynamics(p5, wrenches=push)(q5, e, ed)
    assert np.max(np.abs(tau - nhdyn.inverse_dynamics(p5)(q5, e, ed))) > 1e-3
    assert np.allclose(nhdyn.forward_dynamics(p5, wrenches=push)(q5, e, tau), ed, rtol=0, atol=1e-9)
    with pytest.raises(nhdyn.InputError, match="no body 'hand'"):
        nhdyn.rne(puma, wrenches=[{"body": "hand"}])
    with pytest.raises(nhdyn.InputError, match="unknown key 'torque'"):
        nhdyn.rne(puma, wrenches=[{"body": "link6", "torque": [0, 0, 1]}])
    # Friction of puma560_motors (Corke's drives on the joint side: B = G^2 B_m, Tc = |G| Tc_m;
    # joint 1: G = -62.6111, B_m = 1.48e-3, Tc_m = (0.395, -0.435)): viscous plus Coulomb
    motors = nhdyn.load("puma560_motors")
    fr = nhdyn.friction(motors)
    one = np.zeros(6)
    one[0] = 1.0
    assert fr(one)[0] == pytest.approx(62.6111**2 * 1.48e-3 + 62.6111 * 0.395, rel=1e-5)
    assert fr(-one)[0] == pytest.approx(-(62.6111**2) * 1.48e-3 - 62.6111 * 0.435, rel=1e-5)
    assert np.all(fr(np.zeros(6)) == 0)
    assert np.allclose(fr(3 * one) - fr(2 * one), fr(2 * one) - fr(one), rtol=1e-14)  # linear beyond rest
    # the smooth law: c+ s(qd) above rest, -c- s(qd) below, s = qd / sqrt(qd^2 + v_s^2); B = 5.80182
    sm = nhdyn.friction(motors, smooth=0.01)
    for v in (1e-4, 0.01, 0.5):
        s_ = v / np.sqrt(v * v + 1e-4)
        assert sm(v * one)[0] == pytest.approx(5.8018217679508 * v + 24.7313845 * s_, rel=1e-12)
        assert sm(-v * one)[0] == pytest.approx(-5.8018217679508 * v - 27.2358285 * s_, rel=1e-12)
    assert np.all(sm(np.zeros(6)) == 0)
    with pytest.raises(nhdyn.InputError, match="smooth"):
        nhdyn.friction(motors, smooth=-1)


def test_the_one_state_fast_path_equals_the_general_path_and_the_cxx_loop():
    m = nhdyn.load("paper5")
    f = nhdyn.inverse_dynamics(m)
    rng = np.random.default_rng(9)
    Q, E, ED = rng.uniform(-1, 1, (50, 5)), rng.uniform(-1, 1, (50, 4)), rng.uniform(-1, 1, (50, 4))
    loop = nhdyn._cxx_loop_inverse_dynamics(m, Q, E, ED)
    assert np.array_equal(f(Q, E, ED), loop)
    for i in range(50):
        before = nhdyn._fast_path_calls()
        fast = f(Q[i].copy(), E[i].copy(), ED[i].copy())  # float64, contiguous: the fast path
        assert nhdyn._fast_path_calls() == before + 1
        general = f(Q[i], E[i].tolist(), np.repeat(ED[i], 2)[::2])  # a list, a strided view: the general path
        assert nhdyn._fast_path_calls() == before + 1
        assert np.array_equal(fast, loop[i]) and np.array_equal(general, loop[i])
    # arrays the fast path must not take as they are: big-endian, misaligned; read-only is fine
    before = nhdyn._fast_path_calls()
    assert np.array_equal(f(Q[0].astype(">f8"), E[0], ED[0]), loop[0])
    buf = bytearray(5 * 8 + 1)
    buf[1:41] = Q[0].tobytes()
    misaligned = np.frombuffer(bytes(buf), dtype="<f8", count=5, offset=1)
    assert not misaligned.flags["ALIGNED"]
    assert np.array_equal(f(misaligned, E[0], ED[0]), loop[0])
    assert nhdyn._fast_path_calls() == before
    readonly = Q[0].copy()
    readonly.flags.writeable = False
    assert np.array_equal(f(readonly, E[0], ED[0]), loop[0]) and nhdyn._fast_path_calls() == before + 1
    strided = np.asfortranarray(np.vstack([Q[0], Q[0]]))[0]  # a non-contiguous row
    assert not strided.flags["C_CONTIGUOUS"]
    assert np.array_equal(f(strided, E[0], ED[0]), loop[0])
    with pytest.raises(nhdyn.InputError, match="'eta' has 3 entries; the model needs 4"):
        f(Q[0], E[0][:3], ED[0])


def test_stages_compose_in_python_as_the_paper_composes_them():
    # inverse_dynamics = project o rne o lift, composed here from the three stages; and a
    # stage of one's own (friction on the lifted rates) inserted between rne and project.
    robot = os.path.join(SOURCE, "examples", "robots", "mobile_manipulator_wheels.json")
    for spec in ("paper5", robot):
        m = nhdyn.load(spec)
        lift, rne, project = nhdyn.lift(m), nhdyn.rne(m), nhdyn.project(m)
        rng = np.random.default_rng(3)
        q, e, ed = rng.uniform(-1, 1, m.dof), rng.uniform(-1, 1, m.m), rng.uniform(-1, 1, m.m)
        xq, xqd, xqdd = lift(q, e, ed)
        assert np.array_equal(xq, q)
        want = nhdyn.inverse_dynamics(m)(q, e, ed)
        got = project(q, rne(xq, xqd, xqdd))
        assert np.max(np.abs(got - want)) <= 1e-12 * max(1.0, np.max(np.abs(want)))
        # project's defining property, with lift's S: the actuators' generalized force E tau does
        # the same work as v along every admissible motion S eta, (E tau)·(S eta) = v·(S eta).
        v = rng.uniform(-1, 1, m.dof)
        tau = project(q, v)
        if spec == "paper5":  # no input map, E = S: E tau = S tau = lift's rate of "eta" = tau
            e_tau = lift(q, tau, np.zeros(m.m))[1]
        else:  # the wheels robot: E places tau on the actuated joints, SᵀE = I, so (E tau)·(S eta) = tau·eta
            e_tau = None
        work = e_tau @ xqd if e_tau is not None else tau @ e
        assert work == pytest.approx(v @ xqd, rel=1e-12)
    with pytest.raises(nhdyn.ModelError, match="no constraint"):
        nhdyn.lift(nhdyn.load("puma560"))


@pytest.mark.parametrize("file,n,k,p", [("mecanum_arm.json", 12, 4, 9), ("omni3_arm.json", 11, 3, 8),
                                        ("castor_drive_arm.json", 15, 7, 8), ("powered_castors_arm.json", 19, 8, 16)])
def test_every_wheeled_base_from_python(file, n, k, p):
    path = os.path.join(SOURCE, "examples", "robots", file)
    r = load_robot_or_skip(path)
    assert (r.dof, r.k, r.m, r.p, len(r.tau)) == (n, k, n - k, p, p)
    assert not any(t.startswith("base_") for t in r.tau)
    rng = np.random.default_rng(31)
    q, eta, eta_dot = rng.uniform(-1, 1, r.dof), rng.uniform(-1, 1, r.m), rng.uniform(-1, 1, r.m)
    tau, lam = nhdyn.inverse_dynamics_with_forces(r)(q, eta, eta_dot)
    assert tau.shape == (p,) and lam.shape == (k,)
    assert np.array_equal(nhdyn.inverse_dynamics(r)(q, eta, eta_dot), tau) or np.allclose(
        nhdyn.inverse_dynamics(r)(q, eta, eta_dot), tau, rtol=1e-14, atol=1e-14)
    fd = nhdyn.forward_dynamics(r)
    assert np.allclose(fd(q, eta, tau), eta_dot, rtol=1e-9, atol=1e-9)
    # the tool's numbers, bit for bit
    (ref,) = tool(["id", "--model", path], [{"q": q.tolist(), "eta": eta.tolist(), "eta_dot": eta_dot.tolist()}])
    assert np.array_equal(tau, np.array(ref["tau"])) and np.array_equal(lam, np.array(ref["lambda"]))
    # the linearisation's eta_dot rows (B with p columns) against central differences
    A, B = nhdyn.linearize(r)(q, eta, tau)
    assert A.shape == (n + r.m, n + r.m) and B.shape == (n + r.m, p)
    h, x = 1e-6, np.concatenate([q, eta])
    g = lambda x, u: fd(x[:n], x[n:], u)
    An = np.column_stack([(g(x + h * e, tau) - g(x - h * e, tau)) / (2 * h) for e in np.eye(n + r.m)])
    Bn = np.column_stack([(g(x, tau + h * e) - g(x, tau - h * e)) / (2 * h) for e in np.eye(p)])
    assert np.allclose(A[n:], An, atol=1e-6 * (1 + abs(An).max()))
    assert np.allclose(B[n:], Bn, atol=1e-6 * (1 + abs(Bn).max()))
    with pytest.raises(nhdyn.InputError, match=f"'tau' has {p + 1} entries; the model needs {p}"):
        fd(q, eta, np.zeros(p + 1))


def test_locked_joints_from_python():
    """load(locked=...) on a robot file: the kept rows of the full robot's torques, with the
    locked joints at their positions and at rest; the tool's --lock gives the same numbers."""
    path = os.path.join(SOURCE, "examples", "robots", "mobile_manipulator_wheels.json")
    full = load_robot_or_skip(path)
    r = nhdyn.load(path, locked={"head_*": 0.3, "arm_7_joint": -0.5})
    assert r.locked == {"head_pan_joint": 0.3, "head_tilt_joint": 0.3, "arm_7_joint": -0.5}
    assert (r.dof, r.m) == (full.dof - 3, full.m - 3)
    assert not any(n.startswith("head_") for n in r.joints)
    kept_q = [full.joints.index(n) for n in r.joints]
    kept_eta = [full.eta.index(n) for n in r.eta]
    rng = np.random.default_rng(9)
    q, eta, eta_dot = rng.uniform(-1, 1, full.dof), rng.uniform(-1, 1, full.m), rng.uniform(-1, 1, full.m)
    for n, x in r.locked.items():
        q[full.joints.index(n)] = x
        eta[full.eta.index(n)] = eta_dot[full.eta.index(n)] = 0.0
    want = nhdyn.inverse_dynamics(full)(q, eta, eta_dot)[kept_eta]
    got = nhdyn.inverse_dynamics(r)(q[kept_q], eta[kept_eta], eta_dot[kept_eta])
    assert np.allclose(got, want, rtol=1e-12, atol=1e-12)
    line = {"q": list(q[kept_q]), "eta": list(eta[kept_eta]), "eta_dot": list(eta_dot[kept_eta])}
    assert np.array_equal(np.array(tool(["id", "--model", path, "--lock", "head_*=0.3,arm_7_joint=-0.5"], [line])[0]["tau"]), got)
    with pytest.raises(nhdyn.ModelError, match="'wheel_left_joint' belongs to the constraint"):
        nhdyn.load(path, locked={"wheel_left_joint": 0.0})
    with pytest.raises(nhdyn.ModelError, match="'finger_\\*' matches no movable joint"):
        nhdyn.load(path, locked={"finger_*": 0.0})


def test_locked_dh_model_from_python():
    """load(preset, locked=...): the DH chain as a tree with those joints held; rne's kept rows
    equal the full chain's (the DH kernel) with the locked joints at their positions, at rest;
    paper5's constraint stays on its base joints."""
    full = nhdyn.load("puma560")
    try:
        r = nhdyn.load("puma560", locked={"joint2": 0.3, "joint5": -0.4})
    except nhdyn.ModelError as e:
        if "without tree support" in str(e):
            pytest.skip(str(e))
        raise
    assert r.joints == ["joint1", "joint3", "joint4", "joint6"]
    assert r.locked == {"joint2": 0.3, "joint5": -0.4}
    rng = np.random.default_rng(13)
    q, qd, qdd = (rng.uniform(-1, 1, 6) for _ in range(3))
    q[[1, 4]] = [0.3, -0.4]
    qd[[1, 4]] = qdd[[1, 4]] = 0.0
    kept = [0, 2, 3, 5]
    assert np.allclose(nhdyn.rne(r)(q[kept], qd[kept], qdd[kept]), nhdyn.rne(full)(q, qd, qdd)[kept], rtol=1e-12, atol=1e-12)
    p5 = nhdyn.load("paper5", locked={"joint5": 0.1})
    assert (p5.dof, p5.m) == (4, 3)
    with pytest.raises(nhdyn.ModelError, match="'joint1' belongs to the constraint"):
        nhdyn.load("paper5", locked={"joint1": 0.0})


def page_data(path):
    """The data a page of nhdyn view carries (its line window.NHDYN_DATA = {...};)."""
    text = open(path, encoding="utf-8").read()
    key = "window.NHDYN_DATA = "
    return json.JSONDecoder().raw_decode(text, text.index(key) + len(key))[0]


def view_or_skip(*args, **kwargs):
    """nhdyn.view, skipped where the page cannot be made here (no page template: node was
    missing at build time; no tool; no URDF support)."""
    try:
        return nhdyn.view(*args, **kwargs)
    except nhdyn.InputError as e:
        if "template" in str(e) or "cannot run the nhdyn tool" in str(e) or "without URDF support" in str(e):
            pytest.skip(str(e))
        raise
    except nhdyn.ModelError as e:
        if "template" in str(e) or "without URDF support" in str(e):
            pytest.skip(str(e))
        raise


def test_view_from_python(tmp_path):
    """nhdyn.view writes the tool's page of a Model (its pose, its locked joints), of a DH
    model, and of nhdyn.simulate's runs, whose q reach the page bit for bit; the Page shows
    inline in Jupyter; errors are named."""
    path = os.path.join(SOURCE, "examples", "robots", "mecanum_arm.json")
    m = load_robot_or_skip(path)
    q = np.linspace(-0.5, 0.5, m.dof) / 3
    page = view_or_skip(m, tmp_path / "mecanum.html", q=q)
    assert str(page) == os.fspath(page) == page.path == str(tmp_path / "mecanum.html")
    d = page_data(page.path)
    assert d["robot"]["joint_names"] == m.joints
    assert d["runs"][0]["q"] == [list(q)]
    html = page._repr_html_()
    assert html.startswith('<iframe srcdoc="') and "window.NHDYN_DATA" in html and "&quot;" in html
    # a DH preset with a joint held: drawn from its chain, the held joint in the page's "locked"
    p = nhdyn.load("puma560", locked={"joint6": 0.7})
    d = page_data(view_or_skip(p, tmp_path / "puma.html").path)
    assert d["robot"]["locked"] == {"joint6": 0.7}
    assert d["robot"]["joint_names"] == p.joints == ["joint1", "joint2", "joint3", "joint4", "joint5"]
    # runs: paper-circle's first half second, and the mobile manipulator with its head held
    runs = nhdyn.simulate({"name": "p-short", "duration": 0.5})
    d = page_data(view_or_skip(runs, tmp_path / "runs.html").path)
    assert runs[0]["robot"] == "paper5"
    assert d["runs"][0]["name"] == "p-short"
    assert d["runs"][0]["q"] == runs[0]["q"].tolist()
    scene = json.load(open(os.path.join(SOURCE, "examples", "scenes", "mobile-manipulator-circle.json")))
    scene.update({"robot": os.path.join(SOURCE, "examples", "robots", "mobile_manipulator.json"), "duration": 0.2,
                  "locked": {"head_*": 0.2}, "initial": {"q": scene["initial"]["q"][:17]},
                  "success": {"tail_from": 0.1, "max_tail_error": 1}})
    scene["controller"]["posture_joints"] = [j for j in scene["controller"]["posture_joints"] if not j.startswith("head_")]
    runs = nhdyn.simulate(scene)
    assert runs[0]["locked"] == {"head_*": 0.2}
    d = page_data(view_or_skip(runs[0], tmp_path / "mm.html").path)
    assert d["robot"]["locked"] == {"head_pan_joint": 0.2, "head_tilt_joint": 0.2}
    assert d["runs"][0]["q"] == runs[0]["q"].tolist()
    with pytest.raises(TypeError, match="expected a Model"):
        nhdyn.view(3)
    with pytest.raises(nhdyn.InputError, match="nothing_here"):
        nhdyn.view(str(tmp_path / "nothing_here.urdf"))
    with pytest.raises(nhdyn.InputError, match="q= is for a model"):
        nhdyn.view(runs, q=[0.0])


def test_terms_from_python():
    """rne(terms=...) and inverse_dynamics(terms=...): the Robotics Toolbox's rne(qn, 1, 1)
    (friction included) on puma560_motors, the tool's --terms numbers, and a robot file whose
    friction (URDF damping) the constrained pipeline includes only when asked."""
    p = nhdyn.load("puma560_motors")
    qn = np.array([0, np.pi / 4, np.pi, 0, np.pi / 4, 0])
    o = np.ones(6)
    tau = nhdyn.rne(p, terms="gravity,velocity,armature,friction")(qn, o, o)
    assert np.allclose(tau, [32.4952, 60.867, 17.7436, 1.45452, 1.29911, 0.713781], rtol=0, atol=0.5e-4)
    assert np.array_equal(nhdyn.rne(p, terms=["gravity", "velocity", "armature"])(qn, o, o), nhdyn.rne(p)(qn, o, o))
    line = {"q": list(qn), "qd": list(o), "qdd": list(o)}
    for t in ("all", "velocity,armature", "none"):
        got = nhdyn.rne(p, terms=t)(qn, o, o)
        assert np.array_equal(np.array(tool(["id", "--model", "puma560_motors", "--terms", t], [line])[0]["tau"]), got)
    smooth = nhdyn.rne(p, terms="all", smooth=0.01)(qn, o, o)
    assert np.all(smooth < tau) and np.all(tau - smooth < 2e-3)  # 1 − v_s²/(2q̇²) of |G|Tc⁺ ≤ 25 N m
    with pytest.raises(nhdyn.InputError, match="no term named 'coriolis'"):
        nhdyn.rne(p, terms="gravity,coriolis")
    with pytest.raises(nhdyn.InputError, match="do not include friction"):
        nhdyn.rne(p, terms="gravity", smooth=0.1)
    path = os.path.join(SOURCE, "examples", "robots", "mobile_manipulator_castors.json")
    r = load_robot_or_skip(path)
    rng = np.random.default_rng(4)
    q, eta, eta_dot = rng.uniform(-1, 1, r.dof), rng.uniform(-1, 1, r.m), rng.uniform(-1, 1, r.m)
    with_f = nhdyn.inverse_dynamics(r, terms="all")(q, eta, eta_dot)
    assert np.allclose(nhdyn.inverse_dynamics(r, terms="gravity,velocity,armature")(q, eta, eta_dot),
                       nhdyn.inverse_dynamics(r)(q, eta, eta_dot), rtol=1e-12, atol=1e-12)
    assert np.max(np.abs(with_f - nhdyn.inverse_dynamics(r)(q, eta, eta_dot))) > 1e-3
    line = {"q": list(q), "eta": list(eta), "eta_dot": list(eta_dot)}
    assert np.allclose(np.array(tool(["id", "--model", path, "--terms", "all"], [line])[0]["tau"]), with_f,
                       rtol=1e-12, atol=1e-12)
