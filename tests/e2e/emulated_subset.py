"""The pymycobot 4.0.7 subset run against the exact board images on emulated chips
(tests/emulated.rs starts them with tools/emulate): status, versions, angle and coordinate
moves, a line, jog and stop, IO, bad input and errors.

Not part of the virtual robot's suite (the name does not start with `test_`): the emulator
reads every GPIO input as 0 and runs slower than a chip, so only what holds there is checked.

EMULATED_BOARDS says what runs: `arm` (the default), both boards, through the emulated Basic's
USB serial; `atom`, the Atom alone (tools/emulate --atom-only), through its own USB serial. The
moves run on the Atom alone: with both boards' emulators on a machine of two cores the Atom's
servo answers come too late for its 50 ms freshness rule and moves stop on 21..26
(docs/boards.md, "Servo answers miss the Atom's deadline", item 4). What needs the Basic runs
on the whole arm only.

    MYCOBOT_PORT=/tmp/emulated python tests/e2e/emulated_subset.py -v
    EMULATED_BOARDS=atom MYCOBOT_PORT=/tmp/emulated-atom python tests/e2e/emulated_subset.py -v
"""

import os
import time
import unittest

from robot import RobotTestCase, position_error_mm, wait_until
from test_bad_input import BAD_REQUESTS

BOARDS = os.environ.get("EMULATED_BOARDS", "arm")
WHOLE_ARM_MOVES = (
    "moves run on the emulated Atom alone: on two cores the whole emulated arm's servo answers "
    "come too late (docs/boards.md, 'Servo answers miss the Atom's deadline', item 4)"
)
NEEDS_THE_BASIC = "needs the Basic: run on the whole emulated arm"


def off_segment_mm(p, a, b):
    """Distance in mm of point p from the segment a-b (x, y, z)."""
    ab = [b[i] - a[i] for i in range(3)]
    ap = [p[i] - a[i] for i in range(3)]
    length2 = sum(c * c for c in ab) or 1.0
    t = max(0.0, min(1.0, sum(ab[i] * ap[i] for i in range(3)) / length2))
    return sum((ap[i] - t * ab[i]) ** 2 for i in range(3)) ** 0.5


@unittest.skipIf(BOARDS == "atom", NEEDS_THE_BASIC)
class StatusAndVersions(RobotTestCase):
    def test_powered_on_and_connected(self):
        self.assertEqual(self.mc.is_power_on(), 1)
        self.assertEqual(self.mc.is_controller_connected(), 1)

    def test_versions(self):
        system = self.mc.get_system_version()
        self.assertIsInstance(system, float, f"get_system_version answered {system!r}")
        self.assertGreater(system, 0)
        basic = self.mc.get_basic_version()
        self.assertIsInstance(basic, float, f"get_basic_version answered {basic!r}")
        self.assertGreater(basic, 0)


@unittest.skipIf(BOARDS == "arm", WHOLE_ARM_MOVES)
class Moves(RobotTestCase):
    def test_angles_then_coordinates(self):
        target = [10.0, -20.0, 30.0, 0.0, 15.0, 0.0]
        self.move_to_angles(target, speed=50)
        self.assertAnglesClose(self.mc.get_angles(), target)
        pose = self.mc.get_coords()
        self.assertIsInstance(pose, list, f"get_coords answered {pose!r}")
        self.home()
        self.assertEqual(self.mc.send_coords(pose, 50, 0), 1)
        arrived = wait_until(
            lambda: isinstance(c := self.mc.get_coords(), list)
            and position_error_mm(c, pose) <= 1.0
            and self.mc.is_moving() == 0,
            10.0,
        )
        self.assertTrue(arrived, f"not at {pose}: at {self.mc.get_coords()}")
        self.assertPoseClose(self.mc.get_coords(), pose, pos_tol=1.0, rot_tol=0.5)
        self.assertAnglesClose(self.mc.get_angles(), target, tol=0.5)
        self.home()

    def test_a_line_stays_on_its_line_and_a_finished_move_stays_finished(self):
        # Where the motion benchmark's lines start, away from the singularities.
        self.move_to_angles([10.0, -30.0, -50.0, -10.0, 10.0, 20.0], speed=50)
        start = self.mc.get_coords()
        self.assertIsInstance(start, list, f"get_coords answered {start!r}")
        end = [start[0] - 40, start[1] - 40, start[2] + 20] + start[3:]
        self.assertEqual(
            self.mc.send_coords(end, 30, 1), 1, f"refused, error {self.mc.get_error_information()}"
        )
        worst = 0.0
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            now = self.mc.get_coords()
            if isinstance(now, list):
                worst = max(worst, off_segment_mm(now, start, end))
                if position_error_mm(now, end) <= 1.0 and self.mc.is_moving() == 0:
                    break
            time.sleep(0.05)
        self.assertLessEqual(position_error_mm(self.mc.get_coords(), end), 1.0, "not at the end")
        self.assertLessEqual(worst, 1.0, f"left the line by {worst:.2f} mm")
        done = self.mc.get_angles()
        time.sleep(1.0)
        self.assertAnglesClose(self.mc.get_angles(), done, tol=0.5, msg="moved after it finished")
        self.home()

    def test_jog_runs_until_stop(self):
        self.home()
        self.assertEqual(self.mc.jog_angle(1, 1, 30), 1)
        self.assertTrue(wait_until(lambda: self.mc.get_angles()[0] > 3, 3.0), "the jog did not move")
        self.assertEqual(self.mc.stop(), 1)
        self.wait_stopped(3.0)
        stopped = self.mc.get_angles()
        time.sleep(0.5)
        self.assertAnglesClose(self.mc.get_angles(), stopped, msg="kept moving after stop")
        self.assertAnglesClose(stopped[1:], [0] * 5, msg="other joints moved")
        self.home()


@unittest.skipIf(BOARDS == "atom", NEEDS_THE_BASIC)
class InputsAndOutputs(RobotTestCase):
    def test_basic_and_atom_pins_are_answered(self):
        # The emulator has no pins to look at: each command must be taken and answered.
        self.assertIn(self.mc.get_basic_input(35), (0, 1))
        self.mc.set_basic_output(2, 1)
        self.mc.set_basic_output(2, 0)
        self.mc.set_pin_mode(23, 1)
        self.mc.set_digital_output(23, 1)
        self.assertIn(self.mc.get_digital_input(23), (0, 1))
        self.assertEqual(self.mc.get_error_information(), 0)
        self.assertEqual(self.mc.is_power_on(), 1, "still answering after the pin commands")

    def test_set_color_is_answered_and_the_atom_goes_on(self):
        # The LEDs' RMT transmission has a 2 ms deadline (docs/boards.md, "Waits and their
        # bounds"): where the emulator has no RMT (the C3 machine) the colour is answered 0
        # instead of hanging the Atom.
        for rgb in [(0, 250, 0), (255, 0, 254)]:
            self.assertIn(self.mc.set_color(*rgb), (0, 1), f"set_color{rgb}")
        self.assertEqual(self.mc.is_power_on(), 1, "still answering after set_color")
        angles = self.mc.get_angles()
        self.assertTrue(isinstance(angles, list) and len(angles) == 6, f"get_angles: {angles!r}")


@unittest.skipIf(BOARDS == "atom", NEEDS_THE_BASIC)
class BadInputAndErrors(RobotTestCase):
    def test_bad_requests_change_nothing(self):
        self.home()
        for name, request in BAD_REQUESTS.items():
            with self.subTest(request=name):
                reply = self.send_raw(request)
                self.assertNotEqual(reply, request, f"{name}: the request was echoed")
        self.mc._serial_port.write(bytes(range(256)))  # garbage on the line
        time.sleep(0.3)
        self.assertAnglesClose(self.mc.get_angles(), [0] * 6, msg="the arm moved")
        self.assertEqual(self.mc.is_power_on(), 1)

    def test_an_out_of_limit_angle_is_refused_with_its_joint(self):
        self.home()
        self.mc.clear_error_information()
        self.send_raw(BAD_REQUESTS["send_angles J5 at 170 deg"])
        self.assertEqual(self.mc.get_error_information(), 5)
        self.mc.clear_error_information()
        self.assertTrue(wait_until(lambda: self.mc.get_error_information() == 0, 2.0))
        self.assertAnglesClose(self.mc.get_angles(), [0] * 6, msg="the arm moved")


if __name__ == "__main__":
    unittest.main()
