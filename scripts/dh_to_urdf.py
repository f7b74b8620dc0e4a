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


def main():
    model = json.load(open(sys.argv[1]))
    links = model["links"]
    g = model.get("gravity", [0, 0, -9.81])
    out = ['<?xml version="1.0"?>',
           f'<!-- {model["name"]}: written by scripts/dh_to_urdf.py from its standard-DH model',
           f'     (examples/models/{model["name"]}.json). Gravity in the base frame: [{xyz(g)}]',
           '     (not part of URDF: load with that gravity). -->',
           f'<robot name="{model["name"]}">',
           '  <link name="base"/>']
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
        out.append(f'  <link name="link{i}">\n    <inertial>\n      <origin xyz="{xyz(pc)}" rpy="{num(alpha)} 0 0"/>\n'
                   f'      <mass value="{num(L["mass"])}"/>\n'
                   f'      <inertia ixx="{num(I[0][0])}" ixy="{num(I[0][1])}" ixz="{num(I[0][2])}" '
                   f'iyy="{num(I[1][1])}" iyz="{num(I[1][2])}" izz="{num(I[2][2])}"/>\n    </inertial>\n  </link>')
        prev_a, prev_alpha = a, alpha
    out.append("</robot>")
    print("\n".join(out))


if __name__ == "__main__":
    main()
