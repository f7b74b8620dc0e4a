#!/usr/bin/env python3
"""Writes the URDFs of nhdyn's floating-base (legged) robots, in the style of published robot
descriptions, for tests, examples, benchmarks and the shipped scenes:

    python3 scripts/legged_robots_urdf.py examples/urdf

- quadruped.urdf: a quadruped of ANYmal C's size and layout (its published dimensions and
  masses, rounded): a 25 kg trunk and four legs LF, RF, LH, RH of three joints each, HAA (hip
  abduction/adduction, about x), HFE (hip flexion/extension, about y) and KFE (knee, about
  y), 80 N m and 12 rad/s each; a fixed foot link at the end of each shank (the foot's
  centre, a 3 cm ball's, drawn as a cylinder). 12 movable joints, 48 kg. The root link is
  `trunk`: no world link, no floating joint (its robot file gives the floating base,
  "base": {"type": "floating"}).
  At q = 0 the legs hang straight down: thigh and shank vertical, each foot's centre
  0.585 m below its HFE joint and the trunk's origin, the soles 0.615 m below it. The knees
  bend toward the body's centre ("X" layout, as ANYmal C's): front knees backward
  (KFE <= 0 on LF, RF), hind knees forward (KFE >= 0 on LH, RH); ANYmal's standing pose
  HFE = +0.4 (front) / -0.4 (hind), KFE = -0.8 (front) / +0.8 (hind) puts the soles
  0.569 m below the trunk's origin, the feet under the hips.
- humanoid.urdf: a humanoid of TALOS's dimensions, joint layout, limits and masses (rounded;
  96 kg): a `world` link, the floating joint `root_joint` (identity origin) from `world` to
  `pelvis`, then in document (q) order two legs of 6 joints (leg_<side>_1..6_joint: hip yaw
  z, hip roll x, hip pitch y, knee y, ankle pitch y, ankle roll x), a torso of 2 (torso_1
  yaw z, torso_2 pitch y), two arms of 7 (arm_<side>_1..7_joint: shoulder z, x, z, elbow y,
  wrist z, x, y) with a gripper body and the tool frame arm_<side>_tool_link, and a head of 2
  (head_1 pitch y, head_2 yaw z): 30 movable joints. Fixed frames: left_sole_link and
  right_sole_link under the ankles, arm_left_tool_link and arm_right_tool_link, and
  floor_marker fixed to the world (1 m ahead of the world origin, on the floor plane z = 0).
  At q = 0 the robot stands upright: legs straight, arms hanging straight down at the
  sides, head level; the soles are 1.083 m below the pelvis' origin (q = 0 puts the pelvis
  at the world origin: root_z = 1.083 stands it on the floor z = 0).

Every inertia is that of a solid box or cylinder, so physically valid; every link that has
one carries a visual of the same primitive at the same place. Frames (feet of the quadruped
aside, which have a small mass) carry no inertial. No <dynamics> (no damping or friction).
"""
import os
import sys

# the inertia formulas and the <inertial>/<joint>/<link>/<visual> writers of the other scripts
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mobile_manipulator_urdf import PI2, box, cylinder, joint  # noqa: E402
from wheeled_robots_urdf import box_shape, cyl_shape, link, visual  # noqa: E402


def num(x):
    """A number as the files write it: shortest of %g, never '-0'."""
    return f"{x + 0.0:g}"


def v3(x, y, z):
    return f"{num(x)} {num(y)} {num(z)}"


def lim(lo, hi, effort, velocity):
    return (round(lo + 0.0, 6), round(hi + 0.0, 6), effort, velocity)


def mirror(limits):
    """The limits of the other side's joint about an axis that mirrors (x or z): (-hi, -lo)."""
    lo, hi, effort, velocity = limits
    return lim(-hi, -lo, effort, velocity)


def solid_box(name, m, size, com=(0, 0, 0), material="grey"):
    """A link whose inertia is that of a solid box of `size` at `com`, drawn as that box."""
    c = v3(*com)
    return link(name, m, c, box(m, *size), visuals=[visual(box_shape(*size), c, material=material)])


def solid_cylinder(name, m, r, h, com=(0, 0, 0), along="z", material="grey"):
    """A link whose inertia is that of a solid cylinder (axis along x, y or z) at `com`."""
    rpy = {"x": f"0 {PI2} 0", "y": f"{PI2} 0 0", "z": "0 0 0"}[along]
    c = v3(*com)
    return link(name, m, c, cylinder(m, r, h), rpy, visuals=[visual(cyl_shape(r, h), c, rpy, material=material)])


def header(name, what):
    return ['<?xml version="1.0"?>\n',
            f'<!-- Written by scripts/legged_robots_urdf.py for nhdyn (tests, examples, benchmarks).\n     {what} -->\n',
            f'<robot name="{name}">\n',
            '  <material name="grey"><color rgba="0.6 0.6 0.62 1"/></material>\n',
            '  <material name="dark"><color rgba="0.15 0.15 0.17 1"/></material>\n',
            '  <material name="orange"><color rgba="0.95 0.5 0.1 1"/></material>\n',
            '  <material name="white"><color rgba="0.92 0.92 0.92 1"/></material>\n']


# ---------------------------------------------------------------------------------------------
# the quadruped (ANYmal C's size)

QUAD = dict(
    trunk=(25.0, (0.6, 0.3, 0.2)),  # mass [kg], box [m]
    haa=(0.3, 0.1),                 # the HAA joints at (+-0.3, +-0.1, 0) in the trunk
    hip_to_hfe=(0.06, 0.085),       # HAA -> HFE: (+-0.06, +-0.085, 0), outward and away from the centre
    thigh=(0.1, 0.285),             # HFE -> KFE: (0, +-0.1, -0.285), the knee drive outboard
    shank=0.3,                      # KFE -> foot centre: (0, 0, -0.3)
    foot_r=0.03,
    masses=(2.5, 2.5, 0.6, 0.15),   # hip (the HFE drive), thigh (the KFE drive), shank, foot
)


def quadruped():
    q = QUAD
    m_trunk, size = q["trunk"]
    m_hip, m_thigh, m_shank, m_foot = q["masses"]
    o = header("quadruped", "A quadruped of ANYmal C's size: a trunk and four legs (LF, RF, LH, RH) of three joints (HAA about x,\n"
               "     HFE and KFE about y): 12 joints, 18 velocities with the floating base its robot file gives.\n"
               "     q = 0: legs straight down, the foot centres 0.585 m below the trunk's origin (soles 0.615 m).")
    o.append(solid_box("trunk", m_trunk, size, material="orange"))
    effort, velocity = 80.0, 12.0
    for leg, sx, sy in (("LF", 1, 1), ("RF", 1, -1), ("LH", -1, 1), ("RH", -1, -1)):
        front = sx > 0
        haa = lim(-0.72, 0.72, effort, velocity)                 # symmetric: +-41 deg
        hfe = lim(-2.0, 2.0, effort, velocity)
        # knees toward the body's centre: front legs bend backward (KFE < 0), hind legs forward
        kfe = lim(-2.7, 0.1, effort, velocity) if front else lim(-0.1, 2.7, effort, velocity)
        hx, hy = q["haa"]
        o.append(joint(f"{leg}_HAA", "revolute", "trunk", f"{leg}_hip", v3(sx * hx, sy * hy, 0), "0 0 0", "1 0 0", haa))
        dx, dy = q["hip_to_hfe"]
        # the hip: the HFE drive, a cylinder along y between the HAA and the HFE joint
        o.append(solid_cylinder(f"{leg}_hip", m_hip, 0.06, 0.09, (sx * dx, sy * dy / 2, 0), "y", "dark"))
        o.append(joint(f"{leg}_HFE", "revolute", f"{leg}_hip", f"{leg}_thigh", v3(sx * dx, sy * dy, 0), "0 0 0", "0 1 0", hfe))
        ty, tz = q["thigh"]
        # the thigh: from the HFE joint down to the knee drive, outboard by 0.1 m
        o.append(solid_box(f"{leg}_thigh", m_thigh, (0.08, 0.1, tz), (0, sy * ty / 2, -tz / 2), "grey"))
        o.append(joint(f"{leg}_KFE", "revolute", f"{leg}_thigh", f"{leg}_shank", v3(0, sy * ty, -tz), "0 0 0", "0 1 0", kfe))
        L = q["shank"]
        o.append(solid_cylinder(f"{leg}_shank", m_shank, 0.02, L, (0, 0, -L / 2), "z", "grey"))
        o.append(joint(f"{leg}_foot_joint", "fixed", f"{leg}_shank", f"{leg}_foot", v3(0, 0, -L)))
        r = q["foot_r"]
        o.append(solid_cylinder(f"{leg}_foot", m_foot, r, 2 * r, (0, 0, 0), "y", "dark"))
    o.append("</robot>\n")
    return "".join(o)


# ---------------------------------------------------------------------------------------------
# the humanoid (TALOS's dimensions)

def humanoid():
    o = header("humanoid", "A humanoid of TALOS's dimensions and masses (rounded): a floating joint from world to the pelvis,\n"
               "     two legs of 6 joints, a torso of 2, two arms of 7, a head of 2: 30 joints, 36 velocities.\n"
               "     q = 0: standing upright, legs straight, arms down; the soles 1.083 m below the pelvis' origin.")
    o.append(link("world"))
    o.append(joint("root_joint", "floating", "world", "pelvis", "0 0 0"))
    # the pelvis: its origin between the hips, 0.271 m above the hip joints
    o.append(solid_box("pelvis", 13.5, (0.2, 0.3, 0.2), (-0.02, 0, -0.07), "white"))
    o.append(joint("floor_marker_joint", "fixed", "world", "floor_marker", "1 0 0"))
    o.append(link("floor_marker"))

    # the legs: TALOS's leg_<side>_1..6 (hip yaw, roll, pitch; knee; ankle pitch, roll)
    for side, s in (("left", 1), ("right", -1)):
        p = f"leg_{side}_"
        hip_yaw = lim(-0.35, 1.57, 100.0, 3.87)
        legs = [  # (axis, origin, limits (the left leg's; x and z mirror), link body)
            ("0 0 1", v3(-0.02, s * 0.085, -0.271), hip_yaw if s > 0 else mirror(hip_yaw),
             lambda n: solid_cylinder(n, 1.8, 0.06, 0.1, (0, 0, 0.05), "z", "dark")),
            ("1 0 0", "0 0 0", lim(-0.5236, 0.5236, 160.0, 5.8),
             lambda n: solid_cylinder(n, 1.5, 0.06, 0.12, (0, 0, 0), "x", "dark")),
            ("0 1 0", "0 0 0", lim(-2.095, 0.7854, 160.0, 5.8),
             lambda n: solid_box(n, 6.2, (0.12, 0.12, 0.38), (0, 0, -0.19), "white")),
            ("0 1 0", "0 0 -0.38", lim(0.0, 2.618, 300.0, 7.0),
             lambda n: solid_box(n, 3.9, (0.1, 0.1, 0.325), (0, 0, -0.1625), "white")),
            ("0 1 0", "0 0 -0.325", lim(-1.27, 0.68, 160.0, 5.8),
             lambda n: solid_cylinder(n, 1.6, 0.05, 0.1, (0, 0, 0), "y", "dark")),
            ("1 0 0", "0 0 0", lim(-0.5236, 0.5236, 100.0, 4.8),
             lambda n: solid_box(n, 1.4, (0.22, 0.13, 0.05), (0.02, 0, -0.082), "grey")),
        ]
        parent = "pelvis"
        for i, (axis, xyz, limits, body) in enumerate(legs, start=1):
            child = f"{p}{i}_link"
            o.append(joint(f"{p}{i}_joint", "revolute", parent, child, xyz, "0 0 0", axis, limits))
            o.append(body(child))
            parent = child
        o.append(joint(f"{p}sole_joint", "fixed", parent, f"{side}_sole_link", "0 0 -0.107"))
        o.append(link(f"{side}_sole_link"))

    # the torso: yaw, then pitch; torso_2 carries the arms and the head
    o.append(joint("torso_1_joint", "revolute", "pelvis", "torso_1_link", "0 0 0.0722", "0 0 0", "0 0 1",
                   lim(-1.309, 1.309, 200.0, 5.4)))
    o.append(solid_cylinder("torso_1_link", 3.0, 0.08, 0.06, (0, 0, 0), "z", "dark"))
    o.append(joint("torso_2_joint", "revolute", "torso_1_link", "torso_2_link", "0 0 0", "0 0 0", "0 1 0",
                   lim(-0.2618, 0.7854, 200.0, 5.4)))
    o.append(solid_box("torso_2_link", 17.5, (0.22, 0.3, 0.32), (-0.03, 0, 0.15), "white"))

    # the arms: TALOS's arm_<side>_1..7 (shoulder z, x, z; elbow y; wrist z, x, y), hanging down at q = 0
    for side, s in (("left", 1), ("right", -1)):
        p = f"arm_{side}_"
        shoulder_1 = lim(-1.5708, 0.7854, 45.0, 2.7)
        shoulder_2 = lim(0.0, 2.8798, 45.0, 3.7)  # abduction: outward is +x on the left, -x on the right
        arms = [  # (axis, origin (left; y mirrors), limits (left; x and z mirror), mirrors, link body)
            ("0 0 1", (0, 0.157, 0.232), shoulder_1, True,
             lambda n: solid_cylinder(n, 2.7, 0.06, 0.12, (0, s * 0.07, 0.03), "y", "dark")),
            ("1 0 0", (0.005, 0.137, 0.047), shoulder_2, True,
             lambda n: solid_cylinder(n, 2.4, 0.055, 0.11, (0, 0, -0.03), "x", "dark")),
            ("0 0 1", (0, 0, 0), lim(-2.4435, 2.4435, 20.0, 4.6), True,
             lambda n: solid_cylinder(n, 2.6, 0.05, 0.22, (0, 0, -0.15), "z", "white")),
            ("0 1 0", (0.02, 0, -0.273), lim(-2.3562, 0.0, 20.0, 4.6), False,
             lambda n: solid_cylinder(n, 2.3, 0.045, 0.12, (-0.01, 0, -0.06), "z", "white")),
            ("0 0 1", (-0.02, 0, -0.264), lim(-2.5307, 2.5307, 5.0, 2.0), True,
             lambda n: solid_cylinder(n, 1.9, 0.045, 0.14, (0, 0, 0.09), "z", "white")),
            ("1 0 0", (0, 0, 0), lim(-1.3963, 1.3963, 5.0, 1.8), True,
             lambda n: solid_cylinder(n, 0.3, 0.03, 0.06, (0, 0, 0), "x", "dark")),
            ("0 1 0", (0, 0, 0), lim(-0.6981, 0.6981, 5.0, 1.8), False,
             lambda n: solid_cylinder(n, 0.3, 0.03, 0.06, (0, 0, 0), "y", "dark")),
        ]
        parent = "torso_2_link"
        for i, (axis, (x, y, z), limits, mirrors, body) in enumerate(arms, start=1):
            child = f"{p}{i}_link"
            limits = mirror(limits) if (s < 0 and mirrors) else limits
            o.append(joint(f"{p}{i}_joint", "revolute", parent, child, v3(x, s * y, z), "0 0 0", axis, limits))
            o.append(body(child))
            parent = child
        # the gripper (a body fixed to the wrist) and its tool frame between the fingers
        o.append(joint(f"gripper_{side}_base_joint", "fixed", parent, f"gripper_{side}_base_link", "0 0 -0.06"))
        o.append(solid_box(f"gripper_{side}_base_link", 1.1, (0.08, 0.1, 0.12), (0, 0, -0.06), "grey"))
        o.append(joint(f"{p}tool_joint", "fixed", f"gripper_{side}_base_link", f"{p}tool_link", "0 0 -0.15"))
        o.append(link(f"{p}tool_link"))

    # the head: pitch, then yaw, on the neck above the torso
    o.append(joint("head_1_joint", "revolute", "torso_2_link", "head_1_link", "0.02 0 0.321", "0 0 0", "0 1 0",
                   lim(-0.2618, 0.7854, 6.0, 3.0)))
    o.append(solid_cylinder("head_1_link", 0.7, 0.04, 0.08, (0, 0, 0), "y", "dark"))
    o.append(joint("head_2_joint", "revolute", "head_1_link", "head_2_link", "0 0 0", "0 0 0", "0 0 1",
                   lim(-1.309, 1.309, 6.0, 3.0)))
    o.append(solid_box("head_2_link", 1.6, (0.2, 0.18, 0.22), (0.01, 0, 0.11), "white"))
    o.append("</robot>\n")
    return "".join(o)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "examples/urdf"
    for name, text in (("quadruped", quadruped()), ("humanoid", humanoid())):
        with open(os.path.join(out, name + ".urdf"), "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
