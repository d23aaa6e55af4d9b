"""pymycobot 2.9.8's MyCobot class, unchanged, against the virtual robot in the seed dialect
(`--dialect seed`; tests/pymycobot_298.rs starts it and runs this file with the venv of 2.9.8,
`.venv-298`). Named `*_suite.py`, not `test_*.py`: the 4.0.7 suite's discovery must not pick it
up.

pymycobot 2.9.8 reads no reply to a set command (`_mesg(..., has_reply=False)`): against the
pymycobot dialect, where every command is answered, the unread status frames are what its next
query reads (`PymycobotDialect` below shows it). The seed dialect answers only queries, so
every call of a plain script comes out right. Joints and axes are numbered from 0 in the seed
dialect, as 2.9.8's own error.py allows ("ID of 0-5 or 1-6 are allowed"): `send_angle(0, ...)`
is J1, `send_coord(0, ...)` is x.

The calls of 2.9.8 that cannot be right in the seed dialect, and what they do instead:

* `resume()` sends 0x28, the seed dialect's stop: a paused move is ended, not resumed.
* `is_paused()` sends 0x27, the seed dialect's continue: a paused move goes on, and the call,
  which waits for a reply that never comes, returns -1.
* `send_coord(id, value, speed)` scales the value by `id <= 3`, meant for 1-based ids: with the
  seed dialect's 0-based ids x, y and z (0..2) are right and rx (3) is sent in tenths of a
  degree instead of hundredths. Only x, y and z are moved with it here; `send_coords` sets
  the whole pose.
* `is_in_position(data, 0)` (angles) sends the flag 0 as 0x2A's last byte, which the manual
  calls unused: the seed dialect always compares a pose. So `sync_send_angles`, which asks
  it, waits its full timeout. `is_in_position(coords, 1)` is right.

Those are pinned by `test_2_9_8_calls_that_mean_otherwise`, not taken as right.

2.9.8 waits only 0.1 s for a reply (common.read). The robot answers in milliseconds, but on a
loaded machine it can take longer; the call then returns "no answer" (-1, [] or None) and the
late reply waits in the input buffer, where the next call would read it. `ask` therefore asks
again once the line is quiet, as a script on a slow link must; a call that says "no answer"
before its 0.1 s are up has read a whole frame of another command instead, a reply nobody
should have sent, and fails the test unless an earlier reply was late. The retries are
counted and printed at the end.

The robot is found through the environment (tests/e2e/suite.rs sets it): MYCOBOT_PORT (the
serial device), MYCOBOT_VIEW (host:port of the 3D view, whose state stream shows the LED and
the arm as the simulation has them) and MYCOBOT_DIALECT (what the Basic speaks, `seed` or
`pymycobot`: each class runs against its own).
"""

import base64
import json
import math
import os
import socket
import struct
import time
import unittest

import pymycobot
from pymycobot.mycobot import MyCobot

from patience import PATIENCE, wait_until
from reference import rotation_error_deg

if pymycobot.__version__ != "2.9.8":
    raise ImportError(f"this suite is for pymycobot 2.9.8, not {pymycobot.__version__}")

PORT = os.environ.get("MYCOBOT_PORT", "/tmp/mycobot")
VIEW = os.environ.get("MYCOBOT_VIEW", "127.0.0.1:8280")
DIALECT = os.environ.get("MYCOBOT_DIALECT", "seed")

# Tolerances and timeouts as robot.py's (which imports 4.0.7's MyCobot280, so it cannot be used
# here): degrees for angles; coordinate moves as test_motion.py's wait_coords.
ANGLE_TOL = 0.2
POS_TOL_MM = 1.0
ROT_TOL_DEG = 0.5
MOVE_TIMEOUT = 6.0
# How long 2.9.8's read waits for a reply (common.read's wait_time).
READ_WINDOW = 0.1
# How long the line must stay quiet before a late reply counts as drained, how long a late
# reply is waited for, and how long after a late reply a frame of another command may still be
# a late one.
QUIET = 0.3
LATE_LIMIT = 1.0 * PATIENCE
LATE_WINDOW = 10.0
# How often a query is asked before giving up.
TRIES = 5

ZERO = [0.0] * 6
# The flange at the zero pose (test_motion.py's test_zero_pose_coordinates).
ZERO_POSE = [45.6, -63.4, 412.67, -90.0, 0.0, -90.0]
# A comfortable working pose for Cartesian moves: elbow bent, wrist away from its singularity.
WORK = [0, -30, -60, 0, 30, 0]
# A long slow move, to catch the arm on its way.
FAR = [90, 0, 0, 0, 0, 0]

_mc = None
# Queries asked again because their reply came after 2.9.8 stopped waiting.
late_replies = []


def mc():
    """The one shared MyCobot connection."""
    global _mc
    if _mc is None:
        _mc = MyCobot(PORT)
    return _mc


def _no_answer(value):
    return value is None or value == -1 or value == []


def _drain():
    """After a call gave up on its reply: waits for the rest of the reply to arrive (up to
    LATE_LIMIT s; a timed-out read leaves at least its last byte), then reads and drops
    whatever arrives until the line has been quiet for QUIET s."""
    port = mc()._serial_port
    start = time.monotonic()
    heard = False
    quiet_since = start
    while True:
        waiting = port.in_waiting
        now = time.monotonic()
        if waiting:
            port.read(waiting)
            heard = True
            quiet_since = now
        elif heard and now - quiet_since >= QUIET:
            return
        elif not heard and now - start >= LATE_LIMIT:
            return
        time.sleep(0.01)


def ask(name, *args):
    """Calls the query `name` of 2.9.8's MyCobot and returns its answer; asks again if the
    reply came too late for 2.9.8 (see the module doc)."""
    call = getattr(mc(), name)
    for _ in range(TRIES):
        sent = time.monotonic()
        value = call(*args)
        took = time.monotonic() - sent
        if not _no_answer(value):
            return value
        recent_late = late_replies and sent - late_replies[-1][1] < LATE_WINDOW
        if took < READ_WINDOW and not recent_late:
            raise AssertionError(
                f"{name}{args} returned {value!r} after {took * 1000:.0f} ms: it read a whole frame "
                "of another command, a reply nobody should have sent"
            )
        late_replies.append((name, time.monotonic(), took))
        _drain()
    raise AssertionError(f"{name}{args}: no answer in {TRIES} tries")


def tell(name, *args):
    """Calls the set command `name` of 2.9.8's MyCobot, which reads no reply and returns None."""
    value = getattr(mc(), name)(*args)
    if value is not None:
        raise AssertionError(f"{name}{args} returned {value!r}: 2.9.8 returns None")


def near(actual, expected, tol=ANGLE_TOL):
    return (
        isinstance(actual, list)
        and len(actual) == len(expected)
        and all(abs(a - e) <= tol for a, e in zip(actual, expected))
    )


def pose_near(actual, expected, pos_tol=POS_TOL_MM, rot_tol=ROT_TOL_DEG):
    return (
        isinstance(actual, list)
        and len(actual) == 6
        and math.dist(actual[:3], expected[:3]) <= pos_tol
        and rotation_error_deg(actual[3:], expected[3:]) <= rot_tol
    )


def view():
    """The simulation's state as the 3D view receives it (src/web/snapshot.rs, `to_json`): the
    latest snapshot, read off the view's WebSocket `/state` with the standard library."""
    host, port = VIEW.rsplit(":", 1)
    with socket.create_connection((host, int(port)), timeout=5.0 * PATIENCE) as sock:
        key = base64.b64encode(os.urandom(16)).decode()
        sock.sendall(
            (
                f"GET /state HTTP/1.1\r\nHost: {VIEW}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n"
            ).encode()
        )
        buf = b""
        while b"\r\n\r\n" not in buf:
            chunk = sock.recv(4096)
            if not chunk:
                raise AssertionError("the view closed the connection")
            buf += chunk
        head, buf = buf.split(b"\r\n\r\n", 1)

        def take(n):
            nonlocal buf
            while len(buf) < n:
                chunk = sock.recv(4096)
                if not chunk:
                    raise AssertionError("the view closed its state stream")
                buf += chunk
            out, buf = buf[:n], buf[n:]
            return out

        if not head.startswith(b"HTTP/1.1 101"):
            raise AssertionError(f"the view's state stream did not open: {head!r}")
        while True:
            first, second = take(2)
            length = second & 0x7F
            if length == 126:
                length = struct.unpack(">H", take(2))[0]
            elif length == 127:
                length = struct.unpack(">Q", take(8))[0]
            payload = take(length)
            if first & 0x0F == 1:  # a text message: the snapshot (pings are skipped)
                return json.loads(payload)


class ArmTestCase(unittest.TestCase):
    def assertAnglesClose(self, actual, expected, tol=ANGLE_TOL, msg=""):
        self.assertTrue(near(actual, expected, tol), f"{msg}: got {actual!r}, expected {expected}")

    def assertPoseClose(self, actual, expected, msg=""):
        self.assertTrue(pose_near(actual, expected), f"{msg}: got {actual!r}, expected {expected}")


@unittest.skipUnless(DIALECT == "seed", f"the robot speaks {DIALECT}")
class SeedDialect(ArmTestCase):
    """A plain script's calls, each result checked; every test starts powered on at zero."""

    def setUp(self):
        tell("power_on")
        self.assertTrue(wait_until(lambda: ask("is_power_on") == 1, 1.0), "not powered on")
        self.home()

    # ----- helpers a script would have

    def wait_stopped(self, timeout=MOVE_TIMEOUT):
        """Waits until the arm says it is not moving; returns its angles."""
        self.assertTrue(wait_until(lambda: ask("is_moving") == 0, timeout), "still moving")
        return ask("get_angles")

    def move_to(self, angles, speed=100, timeout=MOVE_TIMEOUT):
        """send_angles and wait for the arrival; returns the angles reached."""
        tell("send_angles", angles, speed)
        reached = wait_until(lambda: near(ask("get_angles"), angles) and ask("is_moving") == 0, timeout)
        self.assertTrue(reached, f"did not reach {angles}: at {ask('get_angles')}")
        return ask("get_angles")

    def home(self):
        if not near(ask("get_angles"), ZERO):
            self.move_to(ZERO)

    def wait_pose(self, target, timeout=MOVE_TIMEOUT):
        """Waits until the arm is at rest at the pose `target`; returns its coordinates."""
        arrived = wait_until(lambda: pose_near(ask("get_coords"), target) and ask("is_moving") == 0, timeout)
        self.assertTrue(arrived, f"did not reach {target}: at {ask('get_coords')}")
        return ask("get_coords")

    def start_slow_move(self):
        """Starts a long slow move of J1 to 90 degrees and waits until it is on its way."""
        tell("send_angles", FAR, 10)
        self.assertTrue(wait_until(lambda: ask("get_angles")[0] > 3, 2.0), "the move did not start")

    # ----- the calls

    def test_power_off_and_on(self):
        self.assertEqual(ask("is_power_on"), 1)
        self.assertEqual(ask("is_controller_connected"), 1)
        tell("power_off")
        self.assertEqual(ask("is_power_on"), 0)
        self.assertTrue(wait_until(lambda: view()["powered"] is False, 1.0), "the view shows it powered")
        # A powered-off arm does not move when told to.
        tell("send_angles", [20, 0, 0, 0, 0, 0], 100)
        time.sleep(0.6)
        self.assertAnglesClose(ask("get_angles"), ZERO, msg="moved while powered off")
        tell("power_on")
        self.assertEqual(ask("is_power_on"), 1)
        self.assertTrue(wait_until(lambda: view()["powered"] is True, 1.0), "the view shows it off")
        self.move_to([5, 0, 0, 0, 0, 0])

    def test_get_angles_get_coords_and_send_angles(self):
        self.assertAnglesClose(ask("get_angles"), ZERO, msg="get_angles at zero")
        self.assertPoseClose(ask("get_coords"), ZERO_POSE, msg="get_coords at zero")
        target = [10, 20, -30, 15, -25, 40]
        reached = self.move_to(target)
        self.assertAnglesClose(reached, target, msg="get_angles after send_angles")
        state = view()
        self.assertAnglesClose(state["angles_deg"], target, msg="the robot's own angles")
        # get_coords: what the robot computes for the pose, in 2.9.8's units (mm, degrees).
        self.assertPoseClose(ask("get_coords"), state["coords"], msg="get_coords vs the robot's pose")

    def test_send_angle_numbers_joints_from_0(self):
        for joint, value in ((0, 25.5), (2, -35.5), (5, 40.0)):
            self.home()
            tell("send_angle", joint, value, 100)
            expected = list(ZERO)
            expected[joint] = value
            reached = wait_until(lambda: near(ask("get_angles"), expected) and ask("is_moving") == 0, MOVE_TIMEOUT)
            self.assertTrue(reached, f"send_angle({joint}, {value}) did not move J{joint + 1} alone: {ask('get_angles')}")
        # 6, J6 numbered from 1, is no joint in the seed dialect: refused without a word.
        self.home()
        tell("send_angle", 6, 30, 100)
        time.sleep(0.5)
        self.assertAnglesClose(ask("get_angles"), ZERO, msg="send_angle(6, ...) moved a joint")
        self.assertEqual(ask("is_moving"), 0)

    def test_is_moving_during_and_after_a_move(self):
        self.assertEqual(ask("is_moving"), 0, "moving at rest")
        target = [60, 0, 0, 0, 0, 0]
        tell("send_angles", target, 30)
        self.assertTrue(wait_until(lambda: ask("is_moving") == 1, 1.0), "is_moving never said 1")
        reached = self.wait_stopped()
        self.assertAnglesClose(reached, target, msg="is_moving said 0 before the arrival")
        time.sleep(0.3)
        self.assertEqual(ask("is_moving"), 0, "moving again after the arrival")

    def test_send_coords_joint_and_linear(self):
        self.move_to(WORK)
        start = ask("get_coords")
        for mode, (dx, dy, dz) in ((0, (-10, 30, 10)), (1, (10, -30, -10))):
            target = [round(v, 1) for v in [start[0] + dx, start[1] + dy, start[2] + dz, *start[3:]]]
            tell("send_coords", target, 50, mode)
            self.assertPoseClose(self.wait_pose(target), target, msg=f"send_coords mode {mode}")
            self.assertPoseClose(view()["coords"], target, msg=f"the robot's pose, mode {mode}")

    def test_send_coord_moves_x_y_and_z(self):
        self.move_to(WORK)
        for axis, delta in ((0, 20.0), (1, 20.0), (2, -20.0)):
            target = list(ask("get_coords"))
            target[axis] = round(target[axis] + delta, 1)
            tell("send_coord", axis, target[axis], 50)
            self.assertPoseClose(self.wait_pose(target), target, msg=f"send_coord({axis}, ...)")

    def test_set_color_lights_the_led(self):
        self.assertEqual(view()["protocol"], "seed")
        for rgb in ((255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 0, 16), (0, 0, 0)):
            tell("set_color", *rgb)
            lit = wait_until(lambda: view()["led"] == list(rgb), 1.0, interval=0.05)
            self.assertTrue(lit, f"set_color{rgb}: the LED shows {view()['led']}")

    def wait_gripper(self, expected, tol=3):
        settled = wait_until(
            lambda: abs(ask("get_gripper_value") - expected) <= tol and ask("is_gripper_moving") == 0, 6.0
        )
        self.assertTrue(settled, f"gripper at {ask('get_gripper_value')}, expected {expected}")

    def settle_gripper(self, before):
        """Waits for a gripper move from `before` to start and to end; returns the value."""
        started = wait_until(
            lambda: ask("is_gripper_moving") == 1 or abs(ask("get_gripper_value") - before) > 3, 1.0
        )
        self.assertTrue(started, "the gripper did not start moving")
        self.assertTrue(wait_until(lambda: ask("is_gripper_moving") == 0, 6.0), "the gripper never stopped")
        return ask("get_gripper_value")

    def test_gripper(self):
        tell("set_gripper_value", 60, 100)
        self.wait_gripper(60)
        tell("set_gripper_value", 20, 100)
        self.wait_gripper(20)
        self.assertAlmostEqual(view()["gripper"], ask("get_gripper_value"), delta=3, msg="the robot's gripper")
        # A slow far move is seen on its way.
        tell("set_gripper_value", 100, 30)
        self.assertTrue(wait_until(lambda: ask("is_gripper_moving") == 1, 1.0), "is_gripper_moving never said 1")
        self.wait_gripper(100)
        tell("set_gripper_state", 1, 100)  # close
        closed = self.settle_gripper(100)
        tell("set_gripper_state", 0, 100)  # open
        opened = self.settle_gripper(closed)
        self.assertGreater(opened, closed + 30, f"open {opened} vs closed {closed}")
        self.assertEqual(ask("is_gripper_moving"), 0)

    def test_pause_holds_the_arm(self):
        self.start_slow_move()
        tell("pause")
        held = self.wait_stopped()[0]
        time.sleep(0.5)
        self.assertAlmostEqual(ask("get_angles")[0], held, delta=ANGLE_TOL, msg="moved while paused")
        self.assertLess(held, 85, "the move ended before the pause")
        self.assertEqual(ask("is_moving"), 0)
        tell("stop")  # 0x29: the paused move is dropped
        self.move_to([5, 0, 0, 0, 0, 0])

    def test_stop_stops_a_move(self):
        self.start_slow_move()
        tell("stop")
        stopped_at = self.wait_stopped(2.0)[0]
        time.sleep(0.5)
        self.assertAlmostEqual(ask("get_angles")[0], stopped_at, delta=ANGLE_TOL, msg="moved after stop")
        self.assertLess(stopped_at, 85, "stop did not stop the move")
        # The next move is taken.
        self.move_to([5, 0, 0, 0, 0, 0])

    def test_release_all_servos_then_power_on(self):
        tell("release_all_servos")
        self.assertTrue(wait_until(lambda: ask("is_all_servo_enable") == 0, 1.0), "servos still holding")
        tell("power_on")
        self.assertTrue(wait_until(lambda: ask("is_all_servo_enable") == 1, 1.0), "servos not holding again")
        self.assertEqual(ask("is_power_on"), 1)
        self.move_to([0, 10, -10, 0, 0, 0])

    def test_2_9_8_calls_that_mean_otherwise(self):
        """Pinned, not right (module doc): is_paused() continues, resume() stops, and
        is_in_position with angles compares a pose."""
        self.start_slow_move()
        tell("pause")
        held = self.wait_stopped()[0]
        # is_paused() sends 0x27, continue: no reply (-1 after its 0.1 s), and the arm goes on.
        self.assertEqual(mc().is_paused(), -1)
        self.assertTrue(wait_until(lambda: ask("get_angles")[0] > held + 2, 2.0), "is_paused did not continue the move")
        tell("pause")
        held = self.wait_stopped()[0]
        # resume() sends 0x28, stop: the paused move is over, and a continue finds none.
        tell("resume")
        time.sleep(1.0)
        self.assertAlmostEqual(ask("get_angles")[0], held, delta=ANGLE_TOL, msg="moved after resume()")
        self.assertEqual(ask("is_moving"), 0)
        self.assertEqual(mc().is_paused(), -1)
        time.sleep(1.0)
        self.assertAlmostEqual(ask("get_angles")[0], held, delta=ANGLE_TOL, msg="a stopped move came back")
        self.assertEqual(ask("is_moving"), 0)
        # is_in_position: 1 compares the pose, as 2.9.8 means; 0 (angles) is read as a pose too.
        angles = self.move_to(WORK)
        self.assertEqual(ask("is_in_position", ask("get_coords"), 1), 1)
        self.assertEqual(ask("is_in_position", angles, 0), 0)

    def test_set_commands_get_no_reply(self):
        """After each set command of the tests above, nothing comes back on the line."""
        port = mc()._serial_port
        coords = ask("get_coords")
        calls = [
            ("power_on",),
            ("set_color", 0, 0, 255),
            ("set_gripper_value", 50, 100),
            ("set_gripper_state", 0, 100),
            ("send_angles", [5, 0, 0, 0, 0, 0], 100),
            ("send_angle", 0, 0, 100),
            ("send_coords", coords, 50, 0),
            ("send_coords", coords, 50, 1),
            ("send_coord", 2, coords[2], 50),
            ("pause",),
            ("resume",),
            ("stop",),
            ("release_all_servos",),
            ("power_off",),
            ("power_on",),
        ]
        time.sleep(QUIET)
        self.assertEqual(port.in_waiting, 0, "bytes waiting before the first set command")
        for name, *args in calls:
            tell(name, *args)
            time.sleep(QUIET)
            waiting = port.in_waiting
            self.assertEqual(waiting, 0, f"{name}{tuple(args)} was answered: {port.read(waiting).hex(' ')}")
        time.sleep(1.0)
        self.assertEqual(port.in_waiting, 0, "a late answer")


@unittest.skipUnless(DIALECT == "pymycobot", f"the robot speaks {DIALECT}")
class PymycobotDialect(ArmTestCase):
    """The same calls against the pymycobot dialect go wrong, which is why the seed dialect
    exists: every set command's `01` status stays unread, and each query reads the oldest
    frame waiting, an earlier reply, instead of its own."""

    def test_unread_status_frames_corrupt_the_next_reads(self):
        arm = mc()
        # A query alone is right in both dialects (this robot was just started).
        self.assertEqual(arm.is_power_on(), 1)
        self.assertIsNone(arm.power_on())
        # It reads power_on's status frame (0x10): not its own, so "no answer".
        self.assertEqual(arm.is_power_on(), -1)
        # It reads is_power_on's reply: again not its own.
        self.assertEqual(arm.get_angles(), [])
        # The arm moves, but get_angles reads an earlier reply: never where the arm is.
        target = [20, 0, 0, 0, 0, 0]
        self.assertIsNone(arm.send_angles(target, 100))
        self.assertTrue(wait_until(lambda: near(view()["angles_deg"], target), MOVE_TIMEOUT), "the arm did not move")
        stale = arm.get_angles()
        self.assertTrue(stale == [] or near(stale, ZERO), f"get_angles -> {stale!r}, not a stale reply")


def tearDownModule():
    if late_replies:
        print(f"\n{len(late_replies)} replies came after 2.9.8 stopped waiting (asked again):")
        for name, _, took in late_replies:
            print(f"  {name}: gave up after {took * 1000:.0f} ms")


if __name__ == "__main__":
    unittest.main()
