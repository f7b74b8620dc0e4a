#!/usr/bin/env python3
"""Writes examples/urdf/mobile_manipulator.urdf: a realistic wheeled mobile manipulator made
for nhdyn's tests, examples and benchmarks, in the style of published robot descriptions.

    python3 scripts/mobile_manipulator_urdf.py > examples/urdf/mobile_manipulator.urdf

A base (footprint, then the chassis through a fixed joint) with two drive wheels and two
caster wheels (each a swivel and a wheel), a prismatic torso lift, a 7-joint arm on a fixed
mount with a gripper and a tool frame, and a pan-tilt head with a camera: 16 movable joints
in a tree. Every inertia is that of a solid box or cylinder, so physically valid.
"""
import math

PI2 = repr(math.pi / 2)


def box(m, x, y, z):
    return m * (y * y + z * z) / 12, m * (x * x + z * z) / 12, m * (x * x + y * y) / 12


def cylinder(m, r, h):  # axis along z
    side = m * (3 * r * r + h * h) / 12
    return side, side, m * r * r / 2


def inertial(m, com, I, rpy="0 0 0"):
    return (f'    <inertial>\n      <origin xyz="{com}" rpy="{rpy}"/>\n      <mass value="{m:g}"/>\n'
            f'      <inertia ixx="{I[0]:.6g}" ixy="0" ixz="0" iyy="{I[1]:.6g}" iyz="0" izz="{I[2]:.6g}"/>\n    </inertial>\n')


def link(name, m=None, com="0 0 0", I=None, rpy="0 0 0", shape=None):
    """A link; `shape` (a <box>/<cylinder> element, the solid its inertia is of) is drawn and
    collides where the inertia sits (origin com, rpy)."""
    s = f'  <link name="{name}">\n'
    if m is not None:
        s += inertial(m, com, I, rpy)
    if shape:
        origin = f'<origin xyz="{com}" rpy="{rpy}"/>'
        s += (f'    <visual>\n      {origin}\n      <geometry>{shape}</geometry>\n      <material name="grey"/>\n    </visual>\n'
              f'    <collision>{origin}<geometry>{shape}</geometry></collision>\n')
    return s + "  </link>\n"


def box_shape(x, y, z):
    return f'<box size="{x:g} {y:g} {z:g}"/>'


def cylinder_shape(r, h):
    return f'<cylinder radius="{r:g}" length="{h:g}"/>'


def joint(name, kind, parent, child, xyz, rpy="0 0 0", axis=None, limit=None, dynamics=None):
    s = (f'  <joint name="{name}" type="{kind}">\n    <parent link="{parent}"/>\n    <child link="{child}"/>\n'
         f'    <origin xyz="{xyz}" rpy="{rpy}"/>\n')
    if axis:
        s += f'    <axis xyz="{axis}"/>\n'
    if limit:
        s += f'    <limit lower="{limit[0]}" upper="{limit[1]}" effort="{limit[2]}" velocity="{limit[3]}"/>\n'
    if dynamics:
        s += f'    <dynamics damping="{dynamics[0]}" friction="{dynamics[1]}"/>\n'
    return s + "  </joint>\n"


def main():
    o = ['<?xml version="1.0"?>\n',
         '<!-- Written by scripts/mobile_manipulator_urdf.py for nhdyn (tests, examples, benchmarks).\n'
         '     16 movable joints: 2 drive wheels, 2 casters (swivel + wheel), torso lift, 7-joint arm,\n'
         '     pan-tilt head. Inertias of solid boxes and cylinders. -->\n',
         '<robot name="mobile_manipulator">\n',
         '  <material name="grey"><color rgba="0.6 0.6 0.6 1"/></material>\n']
    o.append(link("base_footprint"))
    o.append(joint("base_footprint_joint", "fixed", "base_footprint", "base_link", "0 0 0.12"))
    o.append(link("base_link", 40.0, "0 0 0.05", box(40.0, 0.6, 0.5, 0.25), shape=box_shape(0.6, 0.5, 0.25)))
    # drive wheels: one written with rpy and axis z, the other with axis y (both styles are common)
    o.append(joint("wheel_left_joint", "continuous", "base_link", "wheel_left_link", "0 0.26 -0.02",
                   f"-{PI2} 0 0", "0 0 1", dynamics=(0.1, 0.0)))
    o.append(link("wheel_left_link", 2.0, "0 0 0", cylinder(2.0, 0.1, 0.04), shape=cylinder_shape(0.1, 0.04)))
    o.append(joint("wheel_right_joint", "continuous", "base_link", "wheel_right_link", "0 -0.26 -0.02",
                   "0 0 0", "0 1 0", dynamics=(0.1, 0.0)))
    o.append(link("wheel_right_link", 2.0, "0 0 0", cylinder(2.0, 0.1, 0.04), f"{PI2} 0 0", shape=cylinder_shape(0.1, 0.04)))
    for side, x in (("front", 0.24), ("rear", -0.24)):
        o.append(joint(f"caster_{side}_swivel_joint", "continuous", "base_link", f"caster_{side}_swivel_link",
                       f"{x} 0 -0.05", "0 0 0", "0 0 1"))
        o.append(link(f"caster_{side}_swivel_link", 0.3, "-0.015 0 -0.02", box(0.3, 0.05, 0.04, 0.05), shape=box_shape(0.05, 0.04, 0.05)))
        o.append(joint(f"caster_{side}_wheel_joint", "continuous", f"caster_{side}_swivel_link",
                       f"caster_{side}_wheel_link", "-0.03 0 -0.03", "0 0 0", "0 1 0"))
        o.append(link(f"caster_{side}_wheel_link", 0.2, "0 0 0", cylinder(0.2, 0.04, 0.03), f"{PI2} 0 0", shape=cylinder_shape(0.04, 0.03)))
    o.append(joint("torso_lift_joint", "prismatic", "base_link", "torso_link", "-0.1 0 0.15", "0 0 0", "0 0 1",
                   (0.0, 0.35, 1000, 0.1), (100.0, 5.0)))
    o.append(link("torso_link", 10.0, "0 0 0.3", box(10.0, 0.25, 0.25, 0.6), shape=box_shape(0.25, 0.25, 0.6)))
    # the arm: a fixed mount with mass, then 7 joints (z, y, z, -y, z, y, z as on common 7-dof arms)
    o.append(joint("arm_mount_joint", "fixed", "torso_link", "arm_base_link", "0.15 0 0.5"))
    o.append(link("arm_base_link", 1.0, "0 0 0.03", cylinder(1.0, 0.06, 0.06), shape=cylinder_shape(0.06, 0.06)))
    arm = [  # (axis, origin in parent, rpy, mass, length)
        ("0 0 1", "0 0 0.06", "0 0 0", 3.0, 0.2),
        ("0 1 0", "0 0 0.2", "0 0 0", 3.0, 0.3),
        ("0 0 1", "0 0 0.3", "0 0 0", 2.5, 0.25),
        ("0 -1 0", "0.05 0 0.25", "0 0 0", 2.5, 0.25),
        ("0 0 1", "-0.05 0 0.25", "0 0 0", 1.5, 0.2),
        ("0 1 0", "0 0 0.2", "0 0 0", 1.5, 0.1),
        ("0 0 1", "0.08 0 0.1", "0 1.5707963267949 0", 0.5, 0.08),
    ]
    parent = "arm_base_link"
    for i, (axis, xyz, rpy, m, length) in enumerate(arm, start=1):
        child = f"arm_{i}_link"
        o.append(joint(f"arm_{i}_joint", "revolute", parent, child, xyz, rpy, axis,
                       (-2.7, 2.7, 80 if i < 5 else 20, 2.0), (0.5, 0.2)))
        o.append(link(child, m, f"0 0 {length / 2:g}", cylinder(m, 0.05, length), shape=cylinder_shape(0.05, length)))
        parent = child
    o.append(joint("gripper_joint", "fixed", "arm_7_link", "gripper_link", "0 0 0.08"))
    o.append(link("gripper_link", 0.6, "0 0 0.05", box(0.6, 0.08, 0.16, 0.1), shape=box_shape(0.08, 0.16, 0.1)))
    o.append(joint("tool_joint", "fixed", "gripper_link", "tool_frame", "0 0 0.15"))
    o.append(link("tool_frame"))
    # the head
    o.append(joint("head_pan_joint", "revolute", "torso_link", "head_pan_link", "0 0 0.65", "0 0 0", "0 0 1",
                   (-2.5, 2.5, 5, 3.0)))
    o.append(link("head_pan_link", 0.5, "0 0 0.04", box(0.5, 0.08, 0.08, 0.08), shape=box_shape(0.08, 0.08, 0.08)))
    o.append(joint("head_tilt_joint", "revolute", "head_pan_link", "head_tilt_link", "0 0 0.08", "0 0 0", "0 1 0",
                   (-1.0, 1.2, 5, 3.0)))
    o.append(link("head_tilt_link", 0.8, "0.03 0 0.02", box(0.8, 0.1, 0.2, 0.07), shape=box_shape(0.1, 0.2, 0.07)))
    o.append(joint("head_camera_joint", "fixed", "head_tilt_link", "head_camera_link", "0.06 0 0.03"))
    o.append(link("head_camera_link"))
    o.append('  <transmission name="arm_1_trans">\n    <type>transmission_interface/SimpleTransmission</type>\n'
             '    <joint name="arm_1_joint"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>\n'
             '    <actuator name="arm_1_motor"><mechanicalReduction>100</mechanicalReduction></actuator>\n  </transmission>\n')
    o.append('  <gazebo reference="base_link"><material>Gazebo/Grey</material></gazebo>\n')
    o.append("</robot>\n")
    print("".join(o), end="")


if __name__ == "__main__":
    main()
