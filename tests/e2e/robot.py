"""Shared helpers for the end-to-end tests: one pymycobot connection to the virtual robot, an
f64 forward-kinematics reference of the arm's DH table (kinematics-core's), and waiting
helpers.

The robot is started by tests/pymycobot.rs (or by hand: `cargo run --release -- --pty-link
/tmp/mycobot`) and found through the environment:

* MYCOBOT_PORT   the serial device or symlink (default /tmp/mycobot)
* MYCOBOT_TCP    host:port of the TCP server, for the TCP tests (skipped when unset)
* MYCOBOT_FRESH  1 if the robot was started just for this run (tests/pymycobot.rs sets it)

On first contact the suite notes the robot's start-up state, then resets what the tests rely
on (`reset`): a robot someone has used works too. Its start-up state is checked only when it
looks fresh or MYCOBOT_FRESH says it must be.
"""

import os
import socket
import struct
import time
import unittest

from pymycobot import MyCobot280

from patience import PATIENCE, wait_until  # noqa: F401 (the tests import both from here)
from reference import fk, position_error_mm, rotation_error_deg  # noqa: F401 (fk: for the tests)

PORT = os.environ.get("MYCOBOT_PORT", "/tmp/mycobot")
FRESH = os.environ.get("MYCOBOT_FRESH") == "1"

# The factory joint limits (degrees): firmware-atom's FACTORY_LIMITS, docs/protocol.md.
DEFAULT_MIN = [-168.0, -140.0, -150.0, -150.0, -155.0, -180.0]
DEFAULT_MAX = [168.0, 140.0, 150.0, 150.0, 160.0, 180.0]

# How close a reported angle must be to the commanded one once the arm has arrived (degrees).
ANGLE_TOL = 0.2
# Coordinates reported vs. the f64 reference of the reported angles (mm, degrees).
POS_TOL_MM = 0.5
ROT_TOL_DEG = 0.2
# Longest any short test move may take (s); moves in the tests are at most ~90 deg at speed 100.
MOVE_TIMEOUT = 6.0
# Longest the reset's move home may take (s): from anywhere in the factory range at speed 100.
HOME_TIMEOUT = 15.0

_arm = None
# What the robot reported when this suite first connected, before the reset:
# (is_power_on, get_angles).
first_contact = None


def arm():
    """The one shared MyCobot280 connection (opening costs 1.5 s in pymycobot). The first call
    notes the robot's start-up state and resets it."""
    global _arm, first_contact
    if _arm is None:
        _arm = MyCobot280(PORT)
        first_contact = (_arm.is_power_on(), _arm.get_angles())
        reset(_arm)
    return _arm


def looks_fresh(contact):
    """True if a first contact shows the state a robot starts in: powered on, joints at 0."""
    powered, angles = contact
    return powered == 1 and isinstance(angles, list) and all(abs(a) <= ANGLE_TOL for a in angles)


def reset(mc):
    """Puts the robot into the state the tests start from, whatever was done to it before:
    framed transponder mode, powered on with every servo holding, no error, free mode off,
    fresh mode on, collision protection on (the default), default speed 100 %, factory joint limits, flange in the base frame with no
    tool or world offset, joint-interpolated moves, and all joints at 0. What it cannot undo:
    a servo whose zero was moved (set_servo_calibration) stays so; restart the robot."""
    zero = [0.0] * 6
    mc.set_transponder_mode(0)
    mc.stop()
    steps = [
        ("power_on", mc.power_on()),
        ("clear_error_information", mc.clear_error_information()),
        ("set_free_mode(0)", mc.set_free_mode(0)),
        ("set_fresh_mode(1)", mc.set_fresh_mode(1)),
        ("set collision mode 1 (0x74)", _raw_ack(mc, frame(0x74, 1))),
        ("set speed 100 (0x41)", _raw_ack(mc, frame(0x41, 100))),
        ("set_end_type(0)", mc.set_end_type(0)),
        ("set_reference_frame(0)", mc.set_reference_frame(0)),
        ("set_movement_type(0)", mc.set_movement_type(0)),
        ("set_tool_reference(0)", mc.set_tool_reference(zero)),
        ("set_world_reference(0)", mc.set_world_reference(zero)),
    ]
    for joint in range(1, 7):
        steps.append((f"set_joint_min({joint})", mc.set_joint_min(joint, int(DEFAULT_MIN[joint - 1]))))
        steps.append((f"set_joint_max({joint})", mc.set_joint_max(joint, int(DEFAULT_MAX[joint - 1]))))
    refused = [name for name, answer in steps if answer != 1]
    if refused:
        raise RuntimeError(f"cannot reset the robot on {PORT}: refused {refused}; restart it")
    if not _near(mc.get_angles(), zero):
        mc.send_angles(zero, 100)
        home = wait_until(lambda: _near(mc.get_angles(), zero) and mc.is_moving() == 0, HOME_TIMEOUT)
        if not home:
            raise RuntimeError(f"cannot reset the robot on {PORT}: not at 0 after {HOME_TIMEOUT} s")
    mc.clear_error_information()


def _raw_ack(mc, request):
    """Sends a raw request pymycobot 4.0.7 has no method for; returns its status byte, or None."""
    port = mc._serial_port
    with mc.lock:
        port.reset_input_buffer()
        port.write(request)
        reply = b""
        deadline = time.monotonic() + 0.5 * PATIENCE
        while len(reply) < 6 and time.monotonic() < deadline:
            reply += port.read(6 - len(reply))
    ok = len(reply) == 6 and reply[:4] == bytes([0xFE, 0xFE, 0x03, request[3]]) and reply[5] == 0xFA
    return reply[4] if ok else None


def _whole_frame(data):
    """True once `data` holds a whole FE FE LEN .. frame from its first FE FE on."""
    start = data.find(b"\xfe\xfe")
    return start >= 0 and len(data) >= start + 3 and len(data) >= start + 3 + data[start + 2]


def _near(angles, expected):
    return (
        isinstance(angles, list)
        and len(angles) == len(expected)
        and all(abs(a - e) <= ANGLE_TOL for a, e in zip(angles, expected))
    )


def tcp_address():
    """(host, port) of the robot's TCP server, from MYCOBOT_TCP."""
    host, port = os.environ["MYCOBOT_TCP"].rsplit(":", 1)
    return host, int(port)


def raw_client(timeout=1.0):
    """A plain TCP connection to the robot, reads timing out after `timeout` s."""
    sock = socket.create_connection(tcp_address())
    sock.settimeout(timeout)
    return sock


def frame(cmd, *data):
    """A raw host frame, for requests pymycobot itself would refuse to send."""
    return bytes([0xFE, 0xFE, len(data) + 2, cmd, *data, 0xFA])


def i16(value):
    """A big-endian int16 as two bytes."""
    return list(struct.pack(">h", value))


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

    def send_raw(self, request, timeout=0.3):
        """Writes one raw request; returns what came back: the bytes up to the first whole
        frame, or whatever came within `timeout` s (PATIENCE times that on a busy machine)."""
        port = self.mc._serial_port
        with self.mc.lock:
            port.reset_input_buffer()
            port.write(request)
            reply = b""
            deadline = time.monotonic() + timeout * PATIENCE
            while not _whole_frame(reply) and time.monotonic() < deadline:
                time.sleep(0.005)
                reply += port.read(port.in_waiting)
            return reply

    # ----- motion helpers

    def wait_stopped(self, timeout=MOVE_TIMEOUT):
        """Waits until the arm reports it is not moving; returns the final angles."""
        stopped = wait_until(lambda: self.mc.is_moving() == 0, timeout)
        self.assertTrue(stopped, f"still moving after {timeout * PATIENCE} s")
        return self.mc.get_angles()

    def move_to_angles(self, angles, speed=100, timeout=MOVE_TIMEOUT):
        """send_angles and wait for the arrival, like a user's script does."""
        self.assertEqual(self.mc.send_angles(angles, speed), 1, f"send_angles({angles}) not accepted")
        reached = wait_until(
            lambda: self._within(self.mc.get_angles(), angles, ANGLE_TOL) and self.mc.is_moving() == 0,
            timeout,
        )
        self.assertTrue(reached, f"did not reach {angles} in {timeout * PATIENCE} s: at {self.mc.get_angles()}")
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
