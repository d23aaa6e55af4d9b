"""Shared helpers for the end-to-end tests: one pymycobot connection to the virtual robot, an
f64 forward-kinematics reference built from docs/kinematics.md, and waiting helpers.

The robot is started by tests/pymycobot.rs (or by hand: `cargo run --release -- --pty-link
/tmp/mycobot`) and found through the environment:

* MYCOBOT_PORT  the serial device or symlink (default /tmp/mycobot)
* MYCOBOT_TCP   host:port of the TCP server, for test_tcp.py (skipped when unset)
"""

import math
import os
import struct
import time
import unittest

from pymycobot import MyCobot280

PORT = os.environ.get("MYCOBOT_PORT", "/tmp/mycobot")

# The factory joint limits (degrees) from kinematics.md / protocol.md.
DEFAULT_MIN = [-168.0, -140.0, -150.0, -150.0, -155.0, -180.0]
DEFAULT_MAX = [168.0, 140.0, 150.0, 150.0, 160.0, 180.0]

# How close a reported angle must be to the commanded one once the arm has arrived (degrees).
ANGLE_TOL = 0.2
# Coordinates reported vs. the f64 reference of the reported angles (mm, degrees).
POS_TOL_MM = 0.5
ROT_TOL_DEG = 0.2
# Longest any short test move may take (s); moves in the tests are at most ~90 deg at speed 100.
MOVE_TIMEOUT = 6.0

_arm = None
# What the robot reported when this suite first connected: (is_power_on, get_angles).
first_contact = None


def arm():
    """The one shared MyCobot280 connection (opening costs 1.5 s in pymycobot)."""
    global _arm, first_contact
    if _arm is None:
        _arm = MyCobot280(PORT)
        first_contact = (_arm.is_power_on(), _arm.get_angles())
    return _arm


def frame(cmd, *data):
    """A raw host frame, for requests pymycobot itself would refuse to send."""
    return bytes([0xFE, 0xFE, len(data) + 2, cmd, *data, 0xFA])


def i16(value):
    """A big-endian int16 as two bytes."""
    return list(struct.pack(">h", value))


def wait_until(predicate, timeout, interval=0.02):
    """Polls predicate() until it returns a truthy value; returns it, or the last value."""
    deadline = time.monotonic() + timeout
    value = predicate()
    while not value and time.monotonic() < deadline:
        time.sleep(interval)
        value = predicate()
    return value


# ---------------------------------------------------------------- f64 kinematics reference

# Standard DH (kinematics.md): (d mm, a mm, alpha deg, theta offset deg) per joint.
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


class RobotTestCase(unittest.TestCase):
    """Base class: a powered, error-free arm in the base/flange frames before every test."""

    def setUp(self):
        self.mc = arm()
        if self.mc.is_power_on() != 1:
            self.assertEqual(self.mc.power_on(), 1)
        self.mc.clear_error_information()

    # ----- assertions a user would make

    def assertAnglesClose(self, actual, expected, tol=ANGLE_TOL, msg=""):
        self.assertIsInstance(actual, list, f"{msg}: got {actual!r}")
        self.assertEqual(len(actual), len(expected), f"{msg}: got {actual!r}")
        worst = max(abs(a - e) for a, e in zip(actual, expected))
        self.assertLessEqual(worst, tol, f"{msg}: got {actual}, expected {expected}")

    def assertPoseClose(self, actual, expected, pos_tol=POS_TOL_MM, rot_tol=ROT_TOL_DEG, msg=""):
        self.assertIsInstance(actual, list, f"{msg}: got {actual!r}")
        self.assertEqual(len(actual), 6, f"{msg}: got {actual!r}")
        self.assertLessEqual(
            position_error_mm(actual, expected), pos_tol, f"{msg}: position {actual} vs {expected}"
        )
        self.assertLessEqual(
            rotation_error_deg(actual[3:], expected[3:]), rot_tol, f"{msg}: orientation {actual} vs {expected}"
        )

    def send_raw(self, request):
        """Writes one raw request; returns whatever came back within 0.3 s."""
        port = self.mc._serial_port
        with self.mc.lock:
            port.reset_input_buffer()
            port.write(request)
            time.sleep(0.3)
            return port.read(port.in_waiting)

    # ----- motion helpers

    def wait_stopped(self, timeout=MOVE_TIMEOUT):
        """Waits until the arm reports it is not moving; returns the final angles."""
        stopped = wait_until(lambda: self.mc.is_moving() == 0, timeout)
        self.assertTrue(stopped, f"still moving after {timeout} s")
        return self.mc.get_angles()

    def move_to_angles(self, angles, speed=100, timeout=MOVE_TIMEOUT):
        """send_angles and wait for the arrival, like a user's script does."""
        self.assertEqual(self.mc.send_angles(angles, speed), 1, f"send_angles({angles}) not accepted")
        reached = wait_until(
            lambda: self._within(self.mc.get_angles(), angles, ANGLE_TOL) and self.mc.is_moving() == 0,
            timeout,
        )
        self.assertTrue(reached, f"did not reach {angles} in {timeout} s: at {self.mc.get_angles()}")
        return self.mc.get_angles()

    def home(self):
        if not self._within(self.mc.get_angles(), [0] * 6, ANGLE_TOL):
            self.move_to_angles([0, 0, 0, 0, 0, 0])

    @staticmethod
    def _within(actual, expected, tol):
        return (
            isinstance(actual, list)
            and len(actual) == len(expected)
            and all(abs(a - e) <= tol for a, e in zip(actual, expected))
        )
