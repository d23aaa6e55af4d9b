"""Jogging: continuous jogs run until stopped, incremental jogs move by exactly the increment."""

import time
import unittest

from robot import RobotTestCase, fk, position_error_mm, wait_until

WORK = [0, -30, -60, 0, 30, 0]


class JogTest(RobotTestCase):
    def test_jog_angle_runs_until_stop(self):
        self.home()
        self.assertEqual(self.mc.jog_angle(1, 1, 30), 1)
        self.assertTrue(wait_until(lambda: self.mc.get_angles()[0] > 3, 2.0), "jog did not move joint 1")
        self.assertEqual(self.mc.stop(), 1)
        self.wait_stopped(2.0)
        stopped = self.mc.get_angles()
        time.sleep(0.3)
        self.assertAnglesClose(self.mc.get_angles(), stopped, msg="kept moving after stop")
        self.assertGreater(stopped[0], 3)
        self.assertAnglesClose(stopped[1:], [0] * 5, msg="other joints moved")

        self.assertEqual(self.mc.jog_angle(1, 0, 30), 1)
        self.assertTrue(wait_until(lambda: self.mc.get_angles()[0] < stopped[0] - 3, 2.0), "negative jog")
        self.mc.stop()
        self.wait_stopped(2.0)
        self.home()

    def test_jog_increment_angle_moves_by_the_increment(self):
        self.move_to_angles(WORK)
        self.assertEqual(self.mc.jog_increment_angle(3, 12.5, 100), 1)
        expected = list(WORK)
        expected[2] += 12.5
        self.assertTrue(
            wait_until(lambda: self._within(self.mc.get_angles(), expected, 0.2) and self.mc.is_moving() == 0, 3.0),
            f"expected {expected}, at {self.mc.get_angles()}",
        )
        self.home()

    def test_jog_coord_moves_along_z_until_stop(self):
        self.move_to_angles(WORK)
        start = self.mc.get_coords()
        self.assertEqual(self.mc.jog_coord(3, 0, 20), 1)
        self.assertTrue(wait_until(lambda: self.mc.get_coords()[2] < start[2] - 5, 3.0), "z did not decrease")
        self.assertEqual(self.mc.stop(), 1)
        self.wait_stopped(2.0)
        end = self.mc.get_coords()
        # Only z changed, orientation held.
        self.assertLessEqual(abs(end[0] - start[0]), 1.0, f"x drifted: {start} -> {end}")
        self.assertLessEqual(abs(end[1] - start[1]), 1.0, f"y drifted: {start} -> {end}")
        self.assertLessEqual(position_error_mm(end, fk(self.mc.get_angles())), 0.5)
        self.home()

    def test_jog_increment_coord_moves_by_the_increment(self):
        self.move_to_angles(WORK)
        start = self.mc.get_coords()
        self.assertEqual(self.mc.jog_increment_coord(1, 15, 100), 1)
        target = list(start)
        target[0] += 15

        def arrived():
            c = self.mc.get_coords()
            return isinstance(c, list) and position_error_mm(c, target) <= 1.0 and self.mc.is_moving() == 0

        self.assertTrue(wait_until(arrived, 3.0), f"expected {target}, at {self.mc.get_coords()}")
        self.home()

    def test_jog_rpy_turns_about_a_base_axis_until_stop(self):
        self.move_to_angles(WORK)
        start = self.mc.get_coords()
        self.assertEqual(self.mc.jog_rpy(3, 1, 20), 1)
        self.assertTrue(
            wait_until(lambda: abs(self.mc.get_coords()[5] - start[5]) > 2.0, 3.0), "rz did not change"
        )
        self.mc.stop()
        self.wait_stopped(2.0)
        end = self.mc.get_coords()
        self.assertLessEqual(position_error_mm(end, start), 1.0, f"position drifted: {start} -> {end}")
        self.home()


if __name__ == "__main__":
    unittest.main()
