#!/usr/bin/env python3
"""Writes a standard-DH JSON model (docs/model-format.md) as a URDF file with the same
kinematics and inertia, so that the URDF path can be checked against the DH kernels
(tests/test_urdf.cpp) and users see how the two describe one robot.

    python3 scripts/dh_to_urdf.py examples/models/puma560.json > examples/urdf/puma560.urdf

URDF link i's frame is joint i's moved frame; DH frame i is that frame times Tx(a_i)Rx(alpha_i).
So joint i's <origin> in link i-1 is Tx(a_{i-1})Rx(alpha_{i-1}) Rz(theta_i) Tz(d_i) (without the
first factor for i = 1, whose parent is the base link, DH frame 0), its axis is z, and link i's
<inertial> sits at Tx(a_i)Rx(alpha_i) com_i with rpy (alpha_i, 0, 0). Revolute DH joints become
`continuous` (DH rows carry no limits). Gravity is not part of a URDF: the model's is written in
a comment, and a loader must be given it.

Each link is drawn (<visual>, for `nhdyn view` and other viewers; no effect on the dynamics)
as the DH parameters place it: a drum along its revolute joint's axis, a rod along x_i for
a_i and one along the next joint's axis for d_{i+1}; the base link carries the rod of d_1.
Sizes follow the model's longest a or d.
"""
import json
import math
import sys


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def rot_x(t):
    c, s = math.cos(t), math.sin(t)
    return [[1, 0, 0], [0, c, -s], [0, s, c]]


def rot_z(t):
    c, s = math.cos(t), math.sin(t)
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def rpy(R):
    """URDF's roll, pitch, yaw of R = Rz(yaw) Ry(pitch) Rx(roll)."""
    pitch = math.asin(max(-1.0, min(1.0, -R[2][0])))
    if abs(math.cos(pitch)) > 1e-9:
        return math.atan2(R[2][1], R[2][2]), pitch, math.atan2(R[1][0], R[0][0])
    return 0.0, pitch, math.atan2(-R[0][1], R[1][1])  # gimbal lock: roll folded into yaw


def num(x):
    """The shortest decimal that reads back to the same double ("1" for 1.0)."""
    if x == 0:
        return "0"  # also -0
    s = repr(float(x))
    return s[:-2] if s.endswith(".0") else s


def xyz(v):
    return " ".join(num(x) for x in v)


def rod(start, direction_rpy, length, radius, material, axis):
    """A <visual> cylinder from `start` to start + length·axis (axis a unit vector, length
    signed), its own z turned onto the axis by `direction_rpy`."""
    if abs(length) < 1e-9:
        return ""
    centre = [start[k] + axis[k] * length / 2 for k in range(3)]
    return (f'    <visual>\n      <origin xyz="{xyz(centre)}" rpy="{xyz(direction_rpy)}"/>\n'
            f'      <geometry><cylinder radius="{num(radius)}" length="{num(abs(length))}"/></geometry>\n'
            f'      <material name="{material}"/>\n    </visual>\n')


def main():
    model = json.load(open(sys.argv[1]))
    links = model["links"]
    size = max([abs(L["a"]) for L in links] + [abs(L["d"]) for L in links] + [0.05])
    r = round(0.06 * size, 4)
    g = model.get("gravity", [0, 0, -9.81])
    out = ['<?xml version="1.0"?>',
           f'<!-- {model["name"]}: written by scripts/dh_to_urdf.py from its standard-DH model',
           f'     (examples/models/{model["name"]}.json). Gravity in the base frame: [{xyz(g)}]',
           '     (not part of URDF: load with that gravity). -->',
           f'<robot name="{model["name"]}">',
           '  <material name="rod"><color rgba="0.62 0.66 0.72 1"/></material>',
           '  <material name="joint"><color rgba="0.93 0.55 0.15 1"/></material>']
    d1 = links[0]["d"] if links[0]["joint"] == "revolute" else 0.0
    base_rod = rod([0, 0, 0], [0, 0, 0], d1, r, "rod", [0, 0, 1])
    out.append('  <link name="base"/>' if not base_rod else f'  <link name="base">\n{base_rod}  </link>')
    prev_a, prev_alpha = 0.0, 0.0
    for i, L in enumerate(links, start=1):
        R = matmul(rot_x(prev_alpha), rot_z(L["theta"]))
        p = [prev_a, -math.sin(prev_alpha) * L["d"], math.cos(prev_alpha) * L["d"]]
        parent = "base" if i == 1 else f"link{i - 1}"
        kind = "continuous" if L["joint"] == "revolute" else "prismatic"
        limit = '\n    <limit lower="-1000" upper="1000" effort="1e9" velocity="1e9"/>' if kind == "prismatic" else ""
        out.append(f'  <joint name="joint{i}" type="{kind}">\n    <parent link="{parent}"/><child link="link{i}"/>\n'
                   f'    <origin xyz="{xyz(p)}" rpy="{xyz(rpy(R))}"/>\n    <axis xyz="0 0 1"/>{limit}\n  </joint>')
        a, alpha = L["a"], L["alpha"]
        c = L["com"]
        Rc = rot_x(alpha)
        pc = [a + c[0], Rc[1][1] * c[1] + Rc[1][2] * c[2], Rc[2][1] * c[1] + Rc[2][2] * c[2]]
        I = L["inertia"]
        visuals = ""
        if L["joint"] == "revolute":
            visuals += rod([0, 0, -1.5 * r], [0, 0, 0], 3 * r, 2 * r, "joint", [0, 0, 1])
        visuals += rod([0, 0, 0], [0, math.pi / 2, 0], a, r, "rod", [1, 0, 0])
        if i < len(links) and links[i]["joint"] == "revolute":  # the next joint's d, along its axis
            visuals += rod([a, 0, 0], [alpha, 0, 0], links[i]["d"], r, "rod", [0, -math.sin(alpha), math.cos(alpha)])
        out.append(f'  <link name="link{i}">\n    <inertial>\n      <origin xyz="{xyz(pc)}" rpy="{num(alpha)} 0 0"/>\n'
                   f'      <mass value="{num(L["mass"])}"/>\n'
                   f'      <inertia ixx="{num(I[0][0])}" ixy="{num(I[0][1])}" ixz="{num(I[0][2])}" '
                   f'iyy="{num(I[1][1])}" iyz="{num(I[1][2])}" izz="{num(I[2][2])}"/>\n    </inertial>\n'
                   f'{visuals}  </link>')
        prev_a, prev_alpha = a, alpha
    out.append("</robot>")
    print("\n".join(out))


if __name__ == "__main__":
    main()
