"""Status and system commands, as a user checks the arm before working with it."""

import unittest

import robot
from robot import RobotTestCase, wait_until


class StatusTest(RobotTestCase):
    def test_starts_powered_on_with_all_joints_at_zero(self):
        if not robot.FRESH and not robot.looks_fresh(robot.first_contact):
            self.skipTest(
                "the robot was used before this run (reset since): its start-up state is checked "
                "on a robot started for the run (MYCOBOT_FRESH=1)"
            )
        powered, angles = robot.first_contact
        self.assertEqual(powered, 1, "not powered on at start-up")
        self.assertAnglesClose(angles, [0] * 6, msg="angles at start-up")

    def test_versions_are_reported(self):
        system = self.mc.get_system_version()
        self.assertIsInstance(system, float, f"get_system_version -> {system!r}")
        self.assertGreater(system, 0)
        basic = self.mc.get_basic_version()
        self.assertIsInstance(basic, float, f"get_basic_version -> {basic!r}")
        self.assertGreater(basic, 0)
        modify = self.mc.get_modify_version()
        self.assertIsInstance(modify, int, f"get_modify_version -> {modify!r}")
        self.assertGreaterEqual(modify, 0)

    def test_controller_is_connected(self):
        self.assertEqual(self.mc.is_controller_connected(), 1)

    def test_power_off_and_on(self):
        self.home()
        self.assertEqual(self.mc.power_off(), 1)
        try:
            self.assertEqual(self.mc.is_power_on(), 0)
            self.assertEqual(self.mc.is_all_servo_enable(), 0)
            # A powered-off arm must not move when told to.
            self.mc.send_angles([20, 0, 0, 0, 0, 0], 100)
            moved = wait_until(lambda: abs(self.mc.get_angles()[0]) > 1.0, 0.6)
            self.assertFalse(moved, "the arm moved while powered off")
        finally:
            self.assertEqual(self.mc.power_on(), 1)
        self.assertEqual(self.mc.is_power_on(), 1)
        self.assertEqual(self.mc.is_all_servo_enable(), 1)
        # And moves again once powered on.
        self.move_to_angles([5, 0, 0, 0, 0, 0])
        self.home()

    def test_fresh_mode_round_trip(self):
        original = self.mc.get_fresh_mode()
        self.assertIn(original, (0, 1))
        try:
            for mode in (1, 0, 1):
                self.assertEqual(self.mc.set_fresh_mode(mode), 1)
                self.assertEqual(self.mc.get_fresh_mode(), mode)
        finally:
            self.mc.set_fresh_mode(original)

    def test_free_mode_round_trip(self):
        try:
            self.assertEqual(self.mc.set_free_mode(1), 1)
            self.assertEqual(self.mc.is_free_mode(), 1)
        finally:
            self.assertEqual(self.mc.set_free_mode(0), 1)
        self.assertEqual(self.mc.is_free_mode(), 0)

    def test_error_information_starts_clear(self):
        self.assertEqual(self.mc.clear_error_information(), 1)
        self.assertEqual(self.mc.get_error_information(), 0)

    def test_healthy_servos_report_no_error(self):
        errors = self.mc.read_next_error()
        self.assertIsInstance(errors, list, f"read_next_error -> {errors!r}")
        self.assertTrue(all(e == 0 for e in errors), f"read_next_error -> {errors}")

    def test_reboot_count_and_queue_commands_answer(self):
        count = self.mc.get_reboot_count()
        self.assertIsInstance(count, int)
        self.assertGreaterEqual(count, 0)
        self.assertEqual(self.mc.clear_queue(), 1)
        self.assertIn(self.mc.check_async_or_sync(), (0, 1))


if __name__ == "__main__":
    unittest.main()
