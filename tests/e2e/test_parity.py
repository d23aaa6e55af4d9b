"""Vendor parity (issue 12) as a pymycobot 4.0.7 user calls it: drag teaching, the Connect-4
kit's servo, gripper_stop and the gripper after a release, input pull-ups, send_coord axes."""

import time
import unittest

from robot import RobotTestCase, wait_until

STEPS_PER_DEG = 4096 / 360


class DragTeachingTest(RobotTestCase):
    def read_all(self, count):
        points = [self.mc.drag_get_record_data() for _ in range(count)]
        for i, point in enumerate(points):
            self.assertIsInstance(point, list, f"point {i}: {point!r}")
            encoders, speeds = point
            self.assertEqual((len(encoders), len(speeds)), (6, 6), f"point {i}: {point!r}")
            self.assertTrue(all(0 <= s <= 6000 for s in speeds), f"point {i} speeds {speeds}")
        self.assertEqual(self.mc.drag_get_record_data(), -1, "after the last point")
        return points

    def test_a_recorded_move_reads_back_in_order_and_replays(self):
        self.home()
        self.assertEqual(self.mc.drag_clear_record_data(), 0)
        self.assertEqual(self.mc.drag_get_record_len(), 0)
        self.assertEqual(self.mc.drag_get_record_data(), -1, "nothing recorded")
        self.assertEqual(self.mc.drag_start_record(), 0)
        # No hand on the virtual arm: a commanded move is recorded the same way.
        self.assertEqual(self.mc.send_angles([30, -20, 0, 0, 0, 0], 50), 1)
        self.wait_stopped()
        time.sleep(0.3)
        count = self.mc.drag_end_record()
        self.assertGreater(count, 10, "20 points a second for over a second")
        time.sleep(0.3)
        self.assertEqual(self.mc.drag_get_record_len(), count, "nothing recorded after the end")

        points = self.read_all(count)
        first, last = points[0][0], points[-1][0]
        self.assertLessEqual(abs(first[0] - 2048), 3, f"starts at 0 deg: {first}")
        self.assertLessEqual(abs(last[0] - (2048 + 30 * STEPS_PER_DEG)), 3, f"ends at 30 deg: {last}")
        joint1 = [p[0][0] for p in points]
        self.assertEqual(joint1, sorted(joint1), "joint 1 in recording order")
        self.assertGreater(max(p[1][0] for p in points), 100, "joint 1's speed recorded")

        # Replay: back to the start, then the points as a 20 Hz stream of set_encoders.
        self.home()
        for encoders, _speeds in points:
            self.assertEqual(self.mc.set_encoders(encoders, 100), 1)
            time.sleep(0.05)
        arrived = wait_until(
            lambda: all(abs(a - t) <= 3 for a, t in zip(self.mc.get_encoders(), last)) and self.mc.is_moving() == 0,
            6.0,
        )
        self.assertTrue(arrived, f"replay ended at {self.mc.get_encoders()}, recorded {last}")
        # set_encoders_drag refuses speed 0 (a joint at rest): give those a speed of their own.
        self.home()
        encoders, speeds = points[len(points) // 2]
        self.assertEqual(self.mc.set_encoders_drag(encoders, [max(s, 200) for s in speeds]), 1)
        self.assertTrue(
            wait_until(lambda: abs(self.mc.get_encoders()[0] - encoders[0]) <= 3 and self.mc.is_moving() == 0, 6.0)
        )
        self.assertEqual(self.mc.drag_clear_record_data(), 0)
        self.assertEqual(self.mc.drag_get_record_len(), 0)
        self.home()

    def test_a_released_arm_is_recorded_where_it_rests(self):
        self.home()
        self.assertEqual(self.mc.drag_clear_record_data(), 0)
        self.assertEqual(self.mc.release_all_servos(), 1)
        try:
            self.assertEqual(self.mc.drag_start_record(), 0)
            time.sleep(0.6)
            count = self.mc.drag_end_record()
            self.assertGreaterEqual(count, 8, "20 points a second")
            for encoders, speeds in self.read_all(count):
                self.assertTrue(all(abs(e - 2048) <= 3 for e in encoders), f"{encoders}")
                self.assertEqual(speeds, [0] * 6)
        finally:
            self.assertEqual(self.mc.power_on(), 1)
            self.mc.drag_clear_record_data()


class ConnectFourServoTest(RobotTestCase):
    def test_move_round_and_set_four_pieces_zero_answer_done(self):
        self.assertEqual(self.mc.move_round(), 1)
        time.sleep(0.2)
        self.assertEqual(self.mc.set_four_pieces_zero(), 1)
        self.assertEqual(self.mc.move_round(), 1)
        time.sleep(0.7)
        self.assertEqual(self.mc.set_four_pieces_zero(), 1)


class GripperParityTest(RobotTestCase):
    def wait_gripper(self, expected, tol=2, timeout=6.0):
        settled = wait_until(
            lambda: abs(self.mc.get_gripper_value() - expected) <= tol and self.mc.is_gripper_moving() == 0, timeout
        )
        self.assertTrue(settled, f"gripper at {self.mc.get_gripper_value()}, expected {expected}")

    def test_gripper_stop_holds_where_it_is(self):
        self.assertEqual(self.mc.set_gripper_value(0, 100), 1)
        self.wait_gripper(0)
        self.assertEqual(self.mc.set_gripper_value(100, 30), 1)
        time.sleep(0.4)
        self.assertEqual(self.mc.gripper_stop(), 1)
        self.assertTrue(wait_until(lambda: self.mc.is_gripper_moving() == 0, 0.3), "the gripper did not stop")
        stopped = self.mc.get_gripper_value()
        self.assertTrue(5 < stopped < 95, f"stopped at {stopped}")
        time.sleep(2.5)
        self.assertEqual(self.mc.get_gripper_value(), stopped, "the gripper crept on after gripper_stop")
        self.assertEqual(self.mc.is_gripper_moving(), 0)
        # Stopped at rest, it stays.
        self.assertEqual(self.mc.gripper_stop(), 1)
        time.sleep(1.0)
        self.assertEqual(self.mc.get_gripper_value(), stopped)

    def test_the_first_command_after_a_release_moves_the_gripper(self):
        self.assertEqual(self.mc.set_gripper_value(80, 100), 1)
        self.wait_gripper(80)
        self.assertEqual(self.mc.set_gripper_state(254, 50), 1)
        time.sleep(0.2)
        self.assertEqual(self.mc.set_gripper_value(40, 80), 1)
        self.wait_gripper(40)
        self.assertEqual(self.mc.set_gripper_state(254, 50), 1)
        time.sleep(0.2)
        self.assertEqual(self.mc.set_gripper_state(1, 80), 1)
        self.wait_gripper(0)


class PinPullTest(RobotTestCase):
    def test_an_input_with_its_pull_up_reads_high(self):
        self.assertEqual(self.mc.set_pin_mode(22, 2), 1)
        self.assertEqual(self.mc.get_digital_input(22), 1, "open input with pull-up")
        self.assertEqual(self.mc.set_pin_mode(22, 0), 1)
        self.assertEqual(self.mc.get_digital_input(22), 0, "floating input")


class SendCoordAxisTest(RobotTestCase):
    def test_axes_1_to_6_are_x_to_rz(self):
        self.move_to_angles([0, -30, -60, 0, 0, 0])
        start = self.mc.get_coords()
        self.assertEqual(self.mc.send_coord(1, round(start[0] - 20, 1), 50), 1)
        self.assertTrue(wait_until(lambda: abs(self.mc.get_coords()[0] - (start[0] - 20)) <= 1.0, 6.0))
        self.wait_stopped()
        moved = self.mc.get_coords()
        self.assertLessEqual(abs(moved[1] - start[1]), 1.0, f"y kept: {start} -> {moved}")
        self.assertEqual(self.mc.send_coord(3, round(moved[2] - 20, 1), 50), 1)
        self.assertTrue(wait_until(lambda: abs(self.mc.get_coords()[2] - (moved[2] - 20)) <= 1.0, 6.0))
        self.wait_stopped()
        self.home()


if __name__ == "__main__":
    unittest.main()
