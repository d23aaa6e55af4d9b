"""Gripper, LEDs, the Atom's pins and the Basic's IO."""

import unittest

from robot import RobotTestCase, wait_until


class GripperTest(RobotTestCase):
    def wait_gripper(self, expected, tol=3, timeout=6.0):
        settled = wait_until(
            lambda: abs(self.mc.get_gripper_value() - expected) <= tol and self.mc.is_gripper_moving() == 0, timeout
        )
        self.assertTrue(settled, f"gripper at {self.mc.get_gripper_value()}, expected {expected}")

    def settle(self, before):
        """Waits for a gripper move that started from `before` to begin and then to end."""
        started = wait_until(
            lambda: self.mc.is_gripper_moving() == 1 or abs(self.mc.get_gripper_value() - before) > 3, 1.0
        )
        self.assertTrue(started, "the gripper did not start moving")
        self.assertTrue(wait_until(lambda: self.mc.is_gripper_moving() == 0, 6.0), "the gripper never stopped")
        return self.mc.get_gripper_value()

    def test_gripper_value_and_state(self):
        self.assertEqual(self.mc.set_gripper_value(60, 100), 1)
        self.wait_gripper(60)
        self.assertEqual(self.mc.set_gripper_value(20, 100), 1)
        self.wait_gripper(20)

        self.assertEqual(self.mc.set_gripper_state(0, 100), 1)  # open
        opened = self.settle(20)
        self.assertEqual(self.mc.set_gripper_state(1, 100), 1)  # close
        closed = self.settle(opened)
        self.assertGreater(opened, closed + 30, f"open {opened} vs closed {closed}")

    def test_gripper_reports_moving_while_it_moves(self):
        self.mc.set_gripper_value(0, 100)
        self.wait_gripper(0)
        self.assertEqual(self.mc.set_gripper_value(100, 30), 1)
        self.assertEqual(self.mc.is_gripper_moving(), 1, "not moving right after a far gripper command")
        self.assertTrue(wait_until(lambda: 10 < self.mc.get_gripper_value() < 90, 3.0), "no intermediate value")
        self.assertEqual(self.mc.is_gripper_moving(), 1, "not moving half-way")
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
        # The virtual arm has no ToF sensor fitted: -1 is a valid answer then, so check that a
        # real reply frame came back rather than pymycobot's -1 for "no reply".
        port = self.mc._serial_port
        with self.mc.lock:
            port.reset_input_buffer()
            port.write(bytes([0xFE, 0xFE, 0x02, 0xC0, 0xFA]))
            reply = wait_until(lambda: port.in_waiting >= 7 and port.read(port.in_waiting), 0.5)
        self.assertTrue(reply, "no reply to get_tof_distance")
        self.assertEqual(reply[:4], bytes([0xFE, 0xFE, 0x04, 0xC0]), reply.hex(" "))
        distance = self.mc.get_tof_distance()
        self.assertTrue(distance == -1 or distance >= 0, distance)


if __name__ == "__main__":
    unittest.main()
