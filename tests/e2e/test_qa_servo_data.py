"""Servo register writes with the width given explicitly, as pymycobot documents them."""

import unittest

from robot import RobotTestCase


class ServoDataModeTest(RobotTestCase):
    def test_one_byte_write_with_explicit_mode_0(self):
        # set_servo_data(id, addr, value, 0) sends the value in two bytes with the width flag 0
        # ("value is one byte"); the servo must receive the byte, not ignore the write.
        original = self.mc.get_servo_data(3, 21)
        try:
            self.mc.set_servo_data(3, 21, 25, 0)
            self.assertEqual(self.mc.get_servo_data(3, 21), 25)
            self.assertEqual(self.mc.get_error_information(), 0)
        finally:
            self.mc.set_servo_data(3, 21, original)
        self.assertEqual(self.mc.get_servo_data(3, 21), original)

    def test_two_byte_write_with_mode_1(self):
        original = self.mc.get_servo_data(3, 44, 1)
        try:
            self.mc.set_servo_data(3, 44, 1000, 1)
            self.assertEqual(self.mc.get_servo_data(3, 44, 1), 1000)
        finally:
            self.mc.set_servo_data(3, 44, original, 1)


if __name__ == "__main__":
    unittest.main()
