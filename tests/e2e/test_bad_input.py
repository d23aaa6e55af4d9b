"""Requests other clients might send that pymycobot never would: out-of-range values, wrong
lengths, unknown commands. The arm must stay put, keep answering, and say what was wrong."""

import time
import unittest

from robot import RobotTestCase, frame, i16, wait_until

ZERO_ANGLES = sum((i16(0) for _ in range(6)), [])

BAD_REQUESTS = {
    "send_angle joint 0": frame(0x21, 0, *i16(1000), 50),
    "send_angle joint 9": frame(0x21, 9, *i16(1000), 50),
    "send_angle 327.67 deg": frame(0x21, 1, *i16(32767), 50),
    "send_angle -327.68 deg": frame(0x21, 2, *i16(-32768), 50),
    "send_angle speed 0": frame(0x21, 1, *i16(1000), 0),
    "send_angle speed 255": frame(0x21, 1, *i16(1000), 255),
    "send_angles truncated": frame(0x22, *ZERO_ANGLES[:7]),
    "send_angles J5 at 170 deg": frame(0x22, *ZERO_ANGLES[:8], *i16(17000), *i16(0), 50),
    "send_coords x = 3276.7 mm": frame(0x25, *i16(32767), *i16(0), *i16(2000), *i16(-9000), *i16(0), *i16(-9000), 50, 0),
    "send_coords mode 7": frame(0x25, *i16(1500), *i16(-634), *i16(3000), *i16(-9000), *i16(0), *i16(-9000), 50, 7),
    "jog_angle joint 8": frame(0x30, 8, 1, 50),
    "jog_angle direction 5": frame(0x30, 1, 5, 50),
    "set_encoder 9999 steps": frame(0x3A, 1, *i16(9999), 50),
    "set_joint_max joint 0": frame(0x4D, 0, *i16(900)),
    "set_joint_min above max": frame(0x4C, 1, *i16(1700)),
    "set_servo_data servo 200": frame(0x52, 200, 40, 0),
    "get_servo_data servo 0": frame(0x53, 0, 56),
    "unknown command 0x9F": frame(0x9F, 1, 2, 3),
    "empty data for get_encoder": frame(0x3B),
}


class BadInputTest(RobotTestCase):
    def test_the_arm_stays_put_and_keeps_answering(self):
        self.home()
        for name, request in BAD_REQUESTS.items():
            with self.subTest(request=name):
                self.mc.clear_error_information()
                reply = self.send_raw(request)
                self.assertNotEqual(reply, request, f"{name}: the request was echoed")
                self.assertAnglesClose(self.mc.get_angles(), [0] * 6, msg=f"{name}: the arm moved")
                self.assertEqual(self.mc.is_power_on(), 1, f"{name}: the arm lost power")
                self.assertEqual(self.mc.get_joint_max_angle(1), 168.0, f"{name}: joint 1 limit changed")
                self.assertEqual(self.mc.get_joint_min_angle(1), -168.0, f"{name}: joint 1 limit changed")
        self.mc.clear_error_information()

    def test_an_out_of_limit_angle_reports_the_joint(self):
        self.home()
        self.mc.clear_error_information()
        self.send_raw(BAD_REQUESTS["send_angles J5 at 170 deg"])
        self.assertEqual(self.mc.get_error_information(), 5)
        self.mc.clear_error_information()
        self.assertTrue(wait_until(lambda: self.mc.get_error_information() == 0, 1.0))


if __name__ == "__main__":
    unittest.main()
