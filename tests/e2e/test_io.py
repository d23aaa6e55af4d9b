"""Gripper, LEDs, the Atom's pins and the Basic's IO."""

import unittest

from robot import RobotTestCase, wait_until


class GripperTest(RobotTestCase):
    def wait_gripper(self, expected, tol=3):
        settled = wait_until(
            lambda: self.mc.is_gripper_moving() == 0 and abs(self.mc.get_gripper_value() - expected) <= tol, 4.0
        )
        self.assertTrue(settled, f"gripper at {self.mc.get_gripper_value()}, expected {expected}")

    def test_gripper_value_and_state(self):
        self.assertEqual(self.mc.set_gripper_value(60, 100), 1)
        self.wait_gripper(60)
        self.assertEqual(self.mc.set_gripper_value(20, 100), 1)
        self.wait_gripper(20)

        self.assertEqual(self.mc.set_gripper_state(0, 100), 1)  # open
        self.assertTrue(wait_until(lambda: self.mc.is_gripper_moving() == 0, 4.0))
        opened = self.mc.get_gripper_value()
        self.assertEqual(self.mc.set_gripper_state(1, 100), 1)  # close
        self.assertTrue(wait_until(lambda: self.mc.is_gripper_moving() == 0, 4.0))
        closed = self.mc.get_gripper_value()
        self.assertGreater(opened, closed + 30, f"open {opened} vs closed {closed}")

    def test_gripper_reports_moving_while_it_moves(self):
        self.mc.set_gripper_value(0, 100)
        self.wait_gripper(0)
        self.assertEqual(self.mc.set_gripper_value(100, 10), 1)
        self.assertTrue(wait_until(lambda: self.mc.is_gripper_moving() == 1, 1.0), "is_gripper_moving stayed 0")
        self.wait_gripper(100)


class AtomIoTest(RobotTestCase):
    def test_set_color_is_accepted(self):
        for rgb in ((255, 0, 0), (0, 255, 0), (0, 0, 255), (0, 0, 0)):
            self.assertEqual(self.mc.set_color(*rgb), 1, f"set_color{rgb}")

    def test_output_pin_reads_back_its_level(self):
        for pin in (19, 22, 23, 33):
            self.assertEqual(self.mc.set_pin_mode(pin, 1), 1, f"pin {pin} mode")
            for level in (1, 0):
                self.assertEqual(self.mc.set_digital_output(pin, level), 1)
                self.assertEqual(self.mc.get_digital_input(pin), level, f"pin {pin} level {level}")

    def test_input_pin_answers_a_level(self):
        self.assertEqual(self.mc.set_pin_mode(23, 2), 1)
        self.assertIn(self.mc.get_digital_input(23), (0, 1))
        self.assertIn(self.mc.get_digital_input(39), (0, 1))  # the Atom's button

    def test_pwm_output_is_accepted(self):
        self.assertEqual(self.mc.set_pwm_output(22, 1000, 128), 1)
        self.assertEqual(self.mc.set_pwm_output(22, 1000, 0), 1)


class BasicIoTest(RobotTestCase):
    def test_basic_outputs_and_inputs(self):
        for pin in (2, 5):
            for level in (1, 0):
                self.assertEqual(self.mc.set_basic_output(pin, level), 1, f"set_basic_output({pin}, {level})")
        for pin in (35, 36):
            self.assertIn(self.mc.get_basic_input(pin), (0, 1), f"get_basic_input({pin})")

    def test_tof_distance_answers(self):
        distance = self.mc.get_tof_distance()
        self.assertIsInstance(distance, int)
        self.assertGreaterEqual(distance, 0)


if __name__ == "__main__":
    unittest.main()
