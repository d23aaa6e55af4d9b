"""The f64 kinematics reference of the arm's DH table (kinematics-core's), for both end-to-end
suites: the pymycobot 4.0.7 one (robot.py re-exports it) and the 2.9.8 one
(seed_298_suite.py), which cannot import robot.py (it imports 4.0.7's MyCobot280)."""

import math

# Standard DH (kinematics-core's ArmGeometry::MYCOBOT_280): (d mm, a mm, alpha deg, theta
# offset deg) per joint.
DH = [
    (131.22, 0.0, 90.0, 0.0),
    (0.0, -110.4, 0.0, -90.0),
    (0.0, -96.0, 0.0, 0.0),
    (63.4, 0.0, 90.0, -90.0),
    (75.05, 0.0, -90.0, 90.0),
    (45.6, 0.0, 0.0, 0.0),
]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def dh_link(q_deg, d, a, alpha_deg, offset_deg):
    t = math.radians(q_deg + offset_deg)
    al = math.radians(alpha_deg)
    ct, st, ca, sa = math.cos(t), math.sin(t), math.cos(al), math.sin(al)
    return [
        [ct, -st * ca, st * sa, a * ct],
        [st, ct * ca, -ct * sa, a * st],
        [0.0, sa, ca, d],
        [0.0, 0.0, 0.0, 1.0],
    ]


def rpy_matrix(rx, ry, rz):
    """R = Rz(rz) * Ry(ry) * Rx(rx), degrees."""
    a, b, c = math.radians(rx), math.radians(ry), math.radians(rz)
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    return [
        [cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa],
        [sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa],
        [-sb, cb * sa, cb * ca],
    ]


def pose_matrix(coords):
    """4x4 transform of an (x, y, z, rx, ry, rz) pose."""
    r = rpy_matrix(*coords[3:6])
    return [r[0] + [coords[0]], r[1] + [coords[1]], r[2] + [coords[2]], [0.0, 0.0, 0.0, 1.0]]


def matrix_pose(m):
    """(x, y, z, rx, ry, rz) of a 4x4 transform."""
    ry = math.degrees(math.atan2(-m[2][0], math.hypot(m[0][0], m[1][0])))
    rx = math.degrees(math.atan2(m[2][1], m[2][2]))
    rz = math.degrees(math.atan2(m[1][0], m[0][0]))
    return [m[0][3], m[1][3], m[2][3], rx, ry, rz]


def flange_matrix(angles_deg):
    m = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
    for q, (d, a, alpha, offset) in zip(angles_deg, DH):
        m = matmul(m, dh_link(q, d, a, alpha, offset))
    return m


def fk(angles_deg, tool=None, world=None):
    """Reference pose (x, y, z mm, rx, ry, rz deg) of the flange, or of the tool tip in the
    world frame when tool/world poses are given (T_world_tool = T_world_base T_base_flange
    T_flange_tool)."""
    m = flange_matrix(angles_deg)
    if tool is not None:
        m = matmul(m, pose_matrix(tool))
    if world is not None:
        m = matmul(pose_matrix(world), m)
    return matrix_pose(m)


def rotation_error_deg(rpy_a, rpy_b):
    """Angle of the rotation between two RPY orientations (robust at ry = +-90)."""
    a, b = rpy_matrix(*rpy_a), rpy_matrix(*rpy_b)
    trace = sum(a[k][i] * b[k][i] for i in range(3) for k in range(3))
    return math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1.0) / 2.0))))


def position_error_mm(a, b):
    return math.dist(a[:3], b[:3])
