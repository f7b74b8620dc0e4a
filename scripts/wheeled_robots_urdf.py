#!/usr/bin/env python3
"""Writes the URDFs of nhdyn's wheeled-base robots (issue: every wheeled base), in the style of
published robot descriptions, for tests, examples, benchmarks and the shipped scenes:

    python3 scripts/wheeled_robots_urdf.py examples/urdf

- mecanum_arm.urdf: an omnidirectional base on four mecanum wheels (rollers at ±45°) with a
  5-joint arm, as a KUKA youBot (its published dimensions, rounded);
- omni3_arm.urdf: a round base on three omni wheels 120° apart (rollers at 90°), the same arm;
- castor_drive_arm.urdf: a differential drive with two passive castors (swivel and wheel
  joints) and a 6-joint arm of a UR5's dimensions on a column, as a TIAGo-style base;
- powered_castors_arm.urdf: a base on four driven castors, as a PR2 (a swivel and a wheel
  joint each), with a torso lift and a 7-joint arm of a PR2 arm's dimensions.

Each base hangs from a `base_footprint` link on the floor (z = 0): the wheels' centres are one
radius above it. Every inertia is that of a solid box or cylinder, so physically valid; every
link that has one carries a visual of the same primitive.
"""
import math
import os
import sys

# the inertia formulas and the <inertial>/<joint> writers of the mobile manipulator's script
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mobile_manipulator_urdf import PI2, box, cylinder, inertial, joint  # noqa: E402


def visual(shape, xyz="0 0 0", rpy="0 0 0", material="grey"):
    return (f'    <visual>\n      <origin xyz="{xyz}" rpy="{rpy}"/>\n      <geometry>{shape}</geometry>\n'
            f'      <material name="{material}"/>\n    </visual>\n')


def box_shape(x, y, z):
    return f'<box size="{x:g} {y:g} {z:g}"/>'


def cyl_shape(r, h):
    return f'<cylinder radius="{r:g}" length="{h:g}"/>'


def link(name, m=None, com="0 0 0", I=None, rpy="0 0 0", visuals=()):
    s = f'  <link name="{name}">\n'
    if m is not None:
        s += inertial(m, com, I, rpy)
    for v in visuals:
        s += v
    return s + "  </link>\n"


def header(name, what):
    return ['<?xml version="1.0"?>\n',
            f'<!-- Written by scripts/wheeled_robots_urdf.py for nhdyn (tests, examples, benchmarks).\n     {what} -->\n',
            f'<robot name="{name}">\n',
            '  <material name="grey"><color rgba="0.6 0.6 0.62 1"/></material>\n',
            '  <material name="dark"><color rgba="0.15 0.15 0.17 1"/></material>\n',
            '  <material name="orange"><color rgba="0.95 0.5 0.1 1"/></material>\n',
            '  <material name="white"><color rgba="0.92 0.92 0.92 1"/></material>\n']


def wheel_link(name, m, r, width, material="dark"):
    """A wheel whose spin axis is the link's y axis (the spin joint's axis 0 1 0)."""
    return link(name, m, "0 0 0", cylinder(m, r, width), f"{PI2} 0 0",
                visuals=[visual(cyl_shape(r, width), rpy=f"{PI2} 0 0", material=material)])


def chain(o, parent, joints, prefix):
    """Revolute joints in a row: (name, axis, xyz, rpy, mass, com, inertia, visual, limits)."""
    for (name, axis, xyz, rpy, m, com, I, vis, lim) in joints:
        child = f"{prefix}{name}_link"
        o.append(joint(f"{prefix}{name}_joint", "revolute", parent, child, xyz, rpy, axis, lim, (0.5, 0.1)))
        o.append(link(child, m, com, I, visuals=vis))
        parent = child
    return parent


def five_joint_arm(o, parent, xyz):
    """A 5-joint arm of a youBot arm's dimensions: yaw, three pitches, a wrist roll."""
    o.append(joint("arm_mount_joint", "fixed", parent, "arm_link_0", xyz))
    o.append(link("arm_link_0", 0.961, "0 0 0.03", box(0.961, 0.15, 0.1, 0.07),
                  visuals=[visual(box_shape(0.15, 0.1, 0.07), "0 0 0.035", material="orange")]))
    lim = (-2.9, 2.9, 9.5, 1.57)
    joints = [
        ("1", "0 0 1", "0.024 0 0.096", "0 0 0", 1.39, "0 0 0.02", cylinder(1.39, 0.06, 0.08),
         [visual(cyl_shape(0.06, 0.08), "0 0 0.02", material="orange")], lim),
        ("2", "0 1 0", "0.033 0 0.019", "0 0 0", 1.318, "0 0 0.0775", box(1.318, 0.07, 0.07, 0.155),
         [visual(box_shape(0.07, 0.07, 0.155), "0 0 0.0775", material="orange")], lim),
        ("3", "0 1 0", "0 0 0.155", "0 0 0", 0.821, "0 0 0.0675", box(0.821, 0.06, 0.06, 0.135),
         [visual(box_shape(0.06, 0.06, 0.135), "0 0 0.0675", material="orange")], lim),
        ("4", "0 1 0", "0 0 0.135", "0 0 0", 0.769, "0 0 0.05", box(0.769, 0.05, 0.05, 0.1),
         [visual(box_shape(0.05, 0.05, 0.1), "0 0 0.05", material="orange")], lim),
        ("5", "0 0 1", "0 0 0.1136", "0 0 0", 0.687, "0 0 0.03", cylinder(0.687, 0.03, 0.06),
         [visual(cyl_shape(0.03, 0.06), "0 0 0.03", material="dark")], lim),
    ]
    last = chain(o, "arm_link_0", joints, "arm_")
    o.append(joint("gripper_joint", "fixed", last, "gripper_link", "0 0 0.06"))
    o.append(link("gripper_link", 0.2, "0 0 0.03", box(0.2, 0.04, 0.1, 0.06),
                  visuals=[visual(box_shape(0.04, 0.1, 0.06), "0 0 0.03", material="dark")]))
    o.append(joint("tool_joint", "fixed", "gripper_link", "tool_frame", "0 0 0.08"))
    o.append(link("tool_frame"))


def mecanum_arm():
    r, lx, ly = 0.0475, 0.228, 0.158
    o = header("mecanum_arm", "An omnidirectional base on four mecanum wheels (rollers at +-45 deg; the spin axes all +y)\n"
               "     with a 5-joint arm, as a KUKA youBot: 9 wheel-and-arm joints, 12 with the planar base.")
    o.append(link("base_footprint"))
    o.append(joint("base_footprint_joint", "fixed", "base_footprint", "base_link", f"0 0 {r + 0.034:g}"))
    o.append(link("base_link", 19.8, "0 0 0", box(19.8, 0.58, 0.38, 0.1),
                  visuals=[visual(box_shape(0.58, 0.38, 0.1), material="orange")]))
    for name, x, y in (("fl", lx, ly), ("fr", lx, -ly), ("rl", -lx, ly), ("rr", -lx, -ly)):
        o.append(joint(f"wheel_{name}_joint", "continuous", "base_link", f"wheel_{name}_link", f"{x} {y} -0.034",
                       "0 0 0", "0 1 0", dynamics=(0.05, 0.0)))
        o.append(wheel_link(f"wheel_{name}_link", 1.4, r, 0.05))
    five_joint_arm(o, "base_link", "0.143 0 0.046")
    o.append("</robot>\n")
    return "".join(o)


def omni3_arm():
    r, L = 0.05, 0.2
    o = header("omni3_arm", "A round base on three omni wheels 120 deg apart (rollers at 90 deg; each spin axis radial,\n"
               "     outward) with the 5-joint arm of mecanum_arm.urdf: 8 wheel-and-arm joints, 11 with the planar base.")
    o.append(link("base_footprint"))
    o.append(joint("base_footprint_joint", "fixed", "base_footprint", "base_link", f"0 0 {r + 0.03:g}"))
    o.append(link("base_link", 15.0, "0 0 0", cylinder(15.0, 0.25, 0.1),
                  visuals=[visual(cyl_shape(0.25, 0.1), material="white")]))
    for i, deg in enumerate((0, 120, 240), start=1):
        a = math.radians(deg)
        # the wheel's y axis (its spin axis) points outward along the radius at angle a
        o.append(joint(f"wheel_{i}_joint", "continuous", "base_link", f"wheel_{i}_link",
                       f"{L * math.cos(a):.6f} {L * math.sin(a):.6f} -0.03", f"0 0 {a - math.pi / 2:.12f}", "0 1 0",
                       dynamics=(0.05, 0.0)))
        o.append(wheel_link(f"wheel_{i}_link", 0.8, r, 0.04))
    five_joint_arm(o, "base_link", "0.1 0 0.05")
    o.append("</robot>\n")
    return "".join(o)


def castor_drive_arm():
    r, track, rc, trail = 0.0985, 0.2022, 0.025, 0.016
    o = header("castor_drive_arm", "A differential drive with two passive castors (a swivel and a wheel joint each) and a\n"
               "     6-joint arm of a UR5's dimensions on a column, as a TIAGo-style base: 12 joints, 15 with the planar base.")
    o.append(link("base_footprint"))
    o.append(joint("base_footprint_joint", "fixed", "base_footprint", "base_link", "0 0 0.0762"))
    o.append(link("base_link", 28.0, "0 0 0.06", cylinder(28.0, 0.27, 0.2),
                  visuals=[visual(cyl_shape(0.27, 0.2), "0 0 0.06", material="white")]))
    zc = r - 0.0762
    for side, y in (("left", track), ("right", -track)):
        o.append(joint(f"wheel_{side}_joint", "continuous", "base_link", f"wheel_{side}_link", f"0 {y} {zc:g}", "0 0 0",
                       "0 1 0", dynamics=(0.1, 0.0)))
        o.append(wheel_link(f"wheel_{side}_link", 1.82, r, 0.04))
    for side, x in (("front", 0.1695), ("rear", -0.1735)):
        swivel_z = rc + 0.035 - 0.0762  # the swivel joint 3.5 cm above the castor wheel's centre
        o.append(joint(f"caster_{side}_swivel_joint", "continuous", "base_link", f"caster_{side}_swivel_link",
                       f"{x} 0 {swivel_z:g}", "0 0 0", "0 0 1"))
        o.append(link(f"caster_{side}_swivel_link", 0.08, f"{-trail / 2:g} 0 -0.015", box(0.08, 0.04, 0.03, 0.04),
                      visuals=[visual(box_shape(0.04, 0.03, 0.04), f"{-trail / 2:g} 0 -0.015", material="grey")]))
        o.append(joint(f"caster_{side}_wheel_joint", "continuous", f"caster_{side}_swivel_link", f"caster_{side}_wheel_link",
                       f"{-trail:g} 0 -0.035", "0 0 0", "0 1 0"))
        o.append(wheel_link(f"caster_{side}_wheel_link", 0.09, rc, 0.015))
    o.append(joint("column_joint", "fixed", "base_link", "column_link", "-0.06 0 0.16"))
    o.append(link("column_link", 9.0, "0 0 0.25", box(9.0, 0.2, 0.2, 0.5),
                  visuals=[visual(box_shape(0.2, 0.2, 0.5), "0 0 0.25", material="white")]))
    lim = (-6.28, 6.28, 150, 3.15)
    small = (-6.28, 6.28, 28, 3.2)
    joints = [  # a UR5's geometry (its published DH lengths) as a URDF chain
        ("shoulder_pan", "0 0 1", "0 0 0.089159", "0 0 0", 3.7, "0 0 0", cylinder(3.7, 0.06, 0.15),
         [visual(cyl_shape(0.06, 0.15), material="grey")], lim),
        ("shoulder_lift", "0 1 0", "0 0.13585 0", f"0 {PI2} 0", 8.393, "0 0 0.28", cylinder(8.393, 0.06, 0.425),
         [visual(cyl_shape(0.055, 0.425), "0 0 0.2125", material="grey")], lim),
        ("elbow", "0 1 0", "0 -0.1197 0.425", "0 0 0", 2.275, "0 0 0.25", cylinder(2.275, 0.06, 0.39225),
         [visual(cyl_shape(0.045, 0.39225), "0 0 0.196", material="grey")], lim),
        ("wrist_1", "0 1 0", "0 0 0.39225", f"0 {PI2} 0", 1.219, "0 0.093 0", cylinder(1.219, 0.06, 0.12),
         [visual(cyl_shape(0.04, 0.09), "0 0.05 0", f"{PI2} 0 0", material="grey")], small),
        ("wrist_2", "0 0 1", "0 0.093 0", "0 0 0", 1.219, "0 0 0.09465", cylinder(1.219, 0.06, 0.12),
         [visual(cyl_shape(0.04, 0.09), "0 0 0.05", material="grey")], small),
        ("wrist_3", "0 1 0", "0 0 0.09465", "0 0 0", 0.1879, "0 0.0650 0", cylinder(0.1879, 0.0375, 0.0345),
         [visual(cyl_shape(0.0375, 0.03), "0 0.07 0", f"{PI2} 0 0", material="dark")], small),
    ]
    o.append(joint("arm_mount_joint", "fixed", "column_link", "arm_base_link", "0.05 0 0.5"))
    o.append(link("arm_base_link", 0.5, "0 0 0.02", cylinder(0.5, 0.075, 0.04),
                  visuals=[visual(cyl_shape(0.075, 0.04), "0 0 0.02", material="dark")]))
    last = chain(o, "arm_base_link", joints, "arm_")
    o.append(joint("tool_joint", "fixed", last, "tool_frame", "0 0.1 0", f"-{PI2} 0 0"))
    o.append(link("tool_frame"))
    o.append("</robot>\n")
    return "".join(o)


def powered_castors_arm():
    r, off, trail = 0.079, 0.2246, 0.049
    o = header("powered_castors_arm", "A base on four driven castors (a swivel and a wheel joint each, both driven), as a PR2,\n"
               "     with a torso lift and a 7-joint arm of a PR2 arm's dimensions: 16 joints, 19 with the planar base.")
    o.append(link("base_footprint"))
    o.append(joint("base_footprint_joint", "fixed", "base_footprint", "base_link", "0 0 0.051"))
    o.append(link("base_link", 116.0, "0 0 0.1", box(116.0, 0.65, 0.65, 0.25),
                  visuals=[visual(box_shape(0.65, 0.65, 0.25), "0 0 0.1", material="grey")]))
    for name, x, y in (("fl", off, off), ("fr", off, -off), ("bl", -off, off), ("br", -off, -off)):
        o.append(joint(f"{name}_caster_rotation_joint", "continuous", "base_link", f"{name}_caster_rotation_link",
                       f"{x} {y} 0.029", "0 0 0", "0 0 1", dynamics=(1.0, 0.0)))
        o.append(link(f"{name}_caster_rotation_link", 3.473, "0 0 0.07", box(3.473, 0.1, 0.1, 0.1),
                      visuals=[visual(box_shape(0.12, 0.1, 0.05), f"{-trail / 2:g} 0 0.0", material="dark")]))
        o.append(joint(f"{name}_caster_wheel_joint", "continuous", f"{name}_caster_rotation_link", f"{name}_caster_wheel_link",
                       f"{-trail:g} 0 {r - 0.08:g}", "0 0 0", "0 1 0", dynamics=(0.5, 0.0)))
        o.append(wheel_link(f"{name}_caster_wheel_link", 0.44, r, 0.034))
    o.append(joint("torso_lift_joint", "prismatic", "base_link", "torso_lift_link", "-0.05 0 0.739675", "0 0 0", "0 0 1",
                   (0.0, 0.33, 10000, 0.013), (20000.0, 10.0)))
    o.append(link("torso_lift_link", 36.45, "0 0 -0.1", box(36.45, 0.3, 0.6, 0.4),
                  visuals=[visual(box_shape(0.3, 0.6, 0.4), "0 0 -0.1", material="white")]))
    lim = (-2.2, 2.2, 30, 2.0)
    joints = [  # a PR2 right arm's geometry: shoulder pan/lift, upper-arm roll, elbow, forearm roll, wrist
        ("shoulder_pan", "0 0 1", "0 -0.188 0", "0 0 0", 25.8, "-0.0013 0.0016 -0.0256", box(25.8, 0.2, 0.2, 0.3),
         [visual(box_shape(0.2, 0.2, 0.3), "0 0 -0.05", material="white")], lim),
        ("shoulder_lift", "0 1 0", "0.1 0 0", "0 0 0", 2.75, "0.02 -0.05 0", box(2.75, 0.15, 0.15, 0.15),
         [visual(box_shape(0.12, 0.12, 0.12), material="grey")], lim),
        ("upper_arm_roll", "1 0 0", "0 0 0", "0 0 0", 6.12, "0.21 0 -0.005", box(6.12, 0.4, 0.12, 0.12),
         [visual(box_shape(0.4, 0.1, 0.1), "0.2 0 0", material="white")], lim),
        ("elbow_flex", "0 1 0", "0.4 0 0", "0 0 0", 1.9, "0.01 0 -0.013", box(1.9, 0.1, 0.1, 0.1),
         [visual(box_shape(0.1, 0.1, 0.1), material="grey")], lim),
        ("forearm_roll", "1 0 0", "0 0 0", "0 0 0", 2.69, "0.18 0 -0.005", box(2.69, 0.32, 0.1, 0.1),
         [visual(box_shape(0.32, 0.09, 0.09), "0.16 0 0", material="white")], lim),
        ("wrist_flex", "0 1 0", "0.321 0 0", "0 0 0", 0.61, "-0.0016 0 -0.0003", box(0.61, 0.06, 0.06, 0.06),
         [visual(box_shape(0.06, 0.06, 0.06), material="grey")], lim),
        ("wrist_roll", "1 0 0", "0 0 0", "0 0 0", 0.68, "0.056 0 0", box(0.68, 0.1, 0.1, 0.06),
         [visual(box_shape(0.1, 0.1, 0.06), "0.05 0 0", material="dark")], lim),
    ]
    last = chain(o, "torso_lift_link", joints, "r_")
    o.append(joint("r_gripper_tool_joint", "fixed", last, "r_gripper_tool_frame", "0.18 0 0"))
    o.append(link("r_gripper_tool_frame"))
    o.append("</robot>\n")
    return "".join(o)


def spin_joint(name, parent, child, xyz, effort=None, velocity=None, dynamics=None):
    """A continuous joint about the child's y axis (a wheel's axle): a `<limit>` with effort and
    velocity only when given (a continuous joint has no position limits)."""
    s = joint(name, "continuous", parent, child, xyz, "0 0 0", "0 1 0", dynamics=dynamics)
    if effort is not None:  # where joint() writes a <limit>: before <dynamics>
        at = s.find("    <dynamics") if dynamics else s.find("  </joint>")
        s = s[:at] + f'    <limit effort="{effort}" velocity="{velocity}"/>\n' + s[at:]
    return s


def tiago_style():
    r, track, rc, trail = 0.0985, 0.2022, 0.025, 0.016
    o = header("tiago_style", "A TIAGo-style robot after PAL Robotics' tiago_description (as example-robot-data ships it):\n"
               "     a round differential-drive base with four passive castors (a swivel and a wheel joint each), a\n"
               "     torso lift, a pan-tilt head, a 7-joint arm and a Hey5-style five-finger hand of 36 joints\n"
               "     (three motors, the thumb's 5, 7 per finger; independent coordinates, no mimic): 56 joints,\n"
               "     59 with the planar base. The published joint frames and limits; masses near the published ones.")
    o.append(link("base_footprint"))
    o.append(joint("base_footprint_joint", "fixed", "base_footprint", "base_link", f"0 0 {r:g}"))
    # the base's chassis, batteries, laser and cover in one round body
    o.append(link("base_link", 32.0, "0 0 0.03", cylinder(32.0, 0.27, 0.2),
                  visuals=[visual(cyl_shape(0.27, 0.2), "0 0 0.03", material="white")]))
    for side, y in (("left", track), ("right", -track)):  # the drive wheels' centres on base_link's origin height
        o.append(spin_joint(f"wheel_{side}_joint", "base_link", f"wheel_{side}_link", f"0 {y} 0", 6.0, 10.15, (0.1, 0.0)))
        o.append(wheel_link(f"wheel_{side}_link", 1.82, r, 0.04))
    swivel_z = -0.0335  # the swivel joints 4 cm above the castor wheels' centres, which are rc above the floor
    for name, x, y in (("front_left", 0.1695, 0.102), ("front_right", 0.1695, -0.102),
                       ("back_left", -0.1735, 0.102), ("back_right", -0.1735, -0.102)):
        o.append(joint(f"caster_{name}_1_joint", "continuous", "base_link", f"caster_{name}_1_link",
                       f"{x} {y} {swivel_z}", "0 0 0", "0 0 1"))
        o.append(link(f"caster_{name}_1_link", 0.1, f"{-trail / 2:g} 0 -0.02", box(0.1, 0.035, 0.03, 0.05),
                      visuals=[visual(box_shape(0.035, 0.03, 0.05), f"{-trail / 2:g} 0 -0.02", material="grey")]))
        o.append(spin_joint(f"caster_{name}_2_joint", f"caster_{name}_1_link", f"caster_{name}_2_link",
                            f"{-trail:g} 0 {rc - r - swivel_z:g}"))
        o.append(wheel_link(f"caster_{name}_2_link", 0.037, rc, 0.022))
    # the torso: a fixed lower body and column on the base, the lift sliding up inside it
    o.append(joint("torso_fixed_joint", "fixed", "base_link", "torso_fixed_link", "-0.062 0 0.193"))
    o.append(link("torso_fixed_link", 11.5, "0.02 0 0.14", box(11.5, 0.25, 0.3, 0.28),
                  visuals=[visual(box_shape(0.25, 0.3, 0.28), "0.02 0 0.14", material="white")]))
    o.append(joint("torso_fixed_column_joint", "fixed", "base_link", "torso_fixed_column_link", "-0.062 0 0.195"))
    o.append(link("torso_fixed_column_link", 2.5, "0 0 0.43", box(2.5, 0.15, 0.15, 0.3),
                  visuals=[visual(box_shape(0.15, 0.15, 0.3), "0 0 0.43", material="grey")]))
    o.append(joint("torso_lift_joint", "prismatic", "torso_fixed_link", "torso_lift_link", "0 0 0.597", "0 0 0", "0 0 1",
                   (0.0, 0.35, 2000, 0.07), (1000.0, 0.0)))
    o.append(link("torso_lift_link", 6.9, "0.04 0 -0.17", box(6.9, 0.26, 0.3, 0.34),
                  visuals=[visual(box_shape(0.26, 0.3, 0.34), "0.04 0 -0.17", material="white")]))
    # the head: pan about the torso's z, tilt about the pan link's y (written as TIAGo's: rpy, then axis z)
    o.append(joint("head_1_joint", "revolute", "torso_lift_link", "head_1_link", "0.182 0 0", "0 0 0", "0 0 1",
                   (-1.308996939, 1.308996939, 5.197, 3.0), (0.5, 1.0)))
    o.append(link("head_1_link", 0.62, "0 0 0.05", box(0.62, 0.08, 0.08, 0.1),
                  visuals=[visual(box_shape(0.08, 0.08, 0.1), "0 0 0.05", material="grey")]))
    o.append(joint("head_2_joint", "revolute", "head_1_link", "head_2_link", "0.005 0 0.098", f"{PI2} 0 0", "0 0 1",
                   (-1.0471975512, 0.785398163397, 2.77, 3.0), (0.5, 1.0)))
    o.append(link("head_2_link", 0.66, "0.045 0.055 0", box(0.66, 0.14, 0.12, 0.2),
                  visuals=[visual(box_shape(0.14, 0.12, 0.2), "0.045 0.055 0", material="white")]))
    o.append(joint("xtion_joint", "fixed", "head_2_link", "xtion_link", "0.0908 0.08 0", f"-{PI2} 0 0"))
    o.append(link("xtion_link", 0.22, "0 0 0", box(0.22, 0.035, 0.18, 0.025),
                  visuals=[visual(box_shape(0.035, 0.18, 0.025), material="dark")]))
    # the arm: TIAGo's joint frames (each joint about its own z); each link a box or cylinder from its joint
    # toward the next one
    lim = [(0.0, 2.74889357189, 39.0, 2.7), (-1.57079632679, 1.0908307825, 39.0, 3.66),
           (-3.53429173529, 1.57079632679, 17.86, 4.58), (-0.392699081699, 2.35619449019, 17.86, 4.58),
           (-2.09439510239, 2.09439510239, 3.0, 1.95), (-1.41371669412, 1.41371669412, 6.6, 1.76),
           (-2.09439510239, 2.09439510239, 6.6, 1.76)]
    joints = [
        ("1", "0 0 1", "0.15505 0.014 -0.151", f"0 0 -{PI2}", 2.08, "0.0625 0.01 -0.015", box(2.08, 0.155, 0.08, 0.09),
         [visual(box_shape(0.155, 0.08, 0.09), "0.0625 0.01 -0.015", material="white")], lim[0]),
        ("2", "0 0 1", "0.125 0.0165 -0.031", f"{PI2} 0 0", 1.79, "0.045 0 0", box(1.79, 0.12, 0.08, 0.08),
         [visual(box_shape(0.12, 0.08, 0.08), "0.045 0 0", material="grey")], lim[1]),
        ("3", "0 0 1", "0.0895 0 0.0015", f"-{PI2} 0 {PI2}", 2.28, "-0.01 -0.0135 -0.12", cylinder(2.28, 0.045, 0.24),
         [visual(cyl_shape(0.045, 0.24), "-0.01 -0.0135 -0.12", material="white")], lim[2]),
        ("4", "0 0 1", "-0.02 -0.027 -0.222", f"-{PI2} -{PI2} 0", 1.89, "-0.09 0.01 0.0135", box(1.89, 0.2, 0.08, 0.08),
         [visual(box_shape(0.2, 0.08, 0.08), "-0.09 0.01 0.0135", material="grey")], lim[3]),
        ("5", "0 0 1", "-0.162 0.02 0.027", f"0 -{PI2} 0", 1.07, "0 0 0.075", cylinder(1.07, 0.04, 0.15),
         [visual(cyl_shape(0.04, 0.15), "0 0 0.075", material="white")], lim[4]),
        ("6", "0 0 1", "0 0 0.15", f"0 -{PI2} -{PI2}", 0.29, "0 0 0", box(0.29, 0.06, 0.05, 0.05),
         [visual(box_shape(0.06, 0.05, 0.05), material="grey")], lim[5]),
        ("7", "0 0 1", "0 0 0", f"{PI2} 0 {PI2}", 0.06, "0 0 0.023", cylinder(0.06, 0.025, 0.046),
         [visual(cyl_shape(0.025, 0.046), "0 0 0.023", material="dark")], lim[6]),
    ]
    last = chain(o, "torso_lift_link", joints, "arm_")
    # the wrist: a tool flange and a force-torque sensor, then the palm (its x toward the fingers, along arm_7's z)
    o.append(joint("arm_tool_joint", "fixed", last, "arm_tool_link", "0 0 0.046"))
    o.append(link("arm_tool_link"))
    o.append(joint("wrist_ft_joint", "fixed", "arm_tool_link", "wrist_ft_link", "0 0 0"))
    o.append(link("wrist_ft_link", 0.2, "0 0 0.01", cylinder(0.2, 0.035, 0.02),
                  visuals=[visual(cyl_shape(0.035, 0.02), "0 0 0.01", material="dark")]))
    o.append(joint("wrist_palm_joint", "fixed", "wrist_ft_link", "hand_palm_link", "0 0 0.02057", f"-{PI2} -{PI2} 0"))
    o.append(link("hand_palm_link", 0.4, "0.06 0 0", box(0.4, 0.11, 0.035, 0.085),
                  visuals=[visual(box_shape(0.11, 0.035, 0.085), "0.06 0 0", material="dark")]))
    hand = (0.5, 0.0)  # the published damping; no friction
    # the three motors in the palm (thumb, index, middle-ring-little), their shafts along the palm's x
    for name, z, (lo, hi, v) in (("thumb", 0.025, (-2.61799387799, 6.28318530718, 3.35)),
                                 ("index", 0.0, (-3.05432619099, 6.80678408278, 3.35)),
                                 ("mrl", -0.025, (-2.53072741539, 9.25024503557, 3.56))):
        o.append(joint(f"hand_{name}_joint", "revolute", "hand_palm_link", f"hand_{name}_link", f"0.03 0 {z:g}",
                       "0 0 0", "1 0 0", (lo, hi, 2.0, v), hand))
        o.append(link(f"hand_{name}_link", 0.05, "0.02 0 0", cylinder(0.05, 0.008, 0.04), f"0 {PI2} 0",
                      visuals=[visual(cyl_shape(0.008, 0.04), "0.02 0 0", f"0 {PI2} 0", material="grey")]))
    flex = (0.0, 0.785398163397, 2.0, 2.0)
    # the thumb and four fingers: an abduction joint on the palm, then n flexions, each written as TIAGo's Hey5
    # writes it, a "virtual" joint and a "flex" joint 13 mm apart (the segments 13 mm and 9 mm long, the tip 20 mm)
    fingers = [  # (finger, abduction origin, rpy, limits, abduction link's length and mass, virtual_1 origin, rpy, n)
        ("thumb", "0.0901 0.0134 0.038", "0 -1.1344640138 0", (0.0, 1.57079632679, 2.0, 2.0), 0.0225, 0.014,
         "0.0225 0.003 0", "-1.14423785761 0 0", 2),
        ("index", "0.1265 0.0042 0.0265", f"-{PI2} -0.523598775598 0", (-0.523598775598, 0.523598775598, 2.0, 2.0),
         0.009, 0.018, "0.009 0 0", f"{PI2} 0 0", 3),
        ("middle", "0.1335 0.0042 0.007", f"-{PI2} 0 0", (-0.523598775598, 0.523598775598, 2.0, 2.0),
         0.009, 0.018, "0.009 0 0", f"{PI2} 0 0", 3),
        ("ring", "0.1265 0.0042 -0.0125", f"-{PI2} 0.261799387799 0", (-0.523598775598, 0.523598775598, 2.0, 2.0),
         0.009, 0.018, "0.009 0 0", f"{PI2} 0 0", 3),
        ("little", "0.1165 0.0042 -0.032", f"-{PI2} 0.523598775598 0", (-0.523598775598, 0.523598775598, 2.0, 2.0),
         0.009, 0.018, "0.009 0 0", f"{PI2} 0 0", 3),
    ]

    def segment(name, m, length):  # a phalanx from its joint along x, 15 mm wide and 12 mm thick
        return link(name, m, f"{length / 2:g} 0 0", box(m, length, 0.012, 0.015),
                    visuals=[visual(box_shape(length, 0.012, 0.015), f"{length / 2:g} 0 0", material="dark")])

    for finger, xyz, rpy, abd_lim, abd_len, abd_m, v1_xyz, v1_rpy, n in fingers:
        parent = f"hand_{finger}_abd_link"
        o.append(joint(f"hand_{finger}_abd_joint", "revolute", "hand_palm_link", parent, xyz, rpy, "0 0 1", abd_lim, hand))
        o.append(segment(parent, abd_m, abd_len))
        for i in range(1, n + 1):
            virtual, flexed = f"hand_{finger}_virtual_{i}_link", f"hand_{finger}_flex_{i}_link"
            o.append(joint(f"hand_{finger}_virtual_{i}_joint", "revolute", parent, virtual,
                           v1_xyz if i == 1 else "0.009 0 0", v1_rpy if i == 1 else "0 0 0", "0 0 1", flex, hand))
            o.append(segment(virtual, 0.01, 0.013))
            o.append(joint(f"hand_{finger}_flex_{i}_joint", "revolute", virtual, flexed, "0.013 0 0", "0 0 0", "0 0 1",
                           flex, hand))
            o.append(segment(flexed, 0.015, 0.02) if i == n else segment(flexed, 0.009, 0.009))
            parent = flexed
    o.append(joint("grasping_frame_joint", "fixed", "hand_palm_link", "hand_grasping_frame", "0.13 0.02 0"))
    o.append(link("hand_grasping_frame"))
    o.append("</robot>\n")
    return "".join(o)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "examples/urdf"
    for name, text in (("mecanum_arm", mecanum_arm()), ("omni3_arm", omni3_arm()),
                       ("castor_drive_arm", castor_drive_arm()), ("powered_castors_arm", powered_castors_arm()),
                       ("tiago_style", tiago_style())):
        with open(os.path.join(out, name + ".urdf"), "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
