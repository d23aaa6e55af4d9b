"""Every MyCobot280 method a script may call gets a real answer (pymycobot returns -1 when the
firmware stays silent), and the simple ones answer what they should."""

import math
import unittest

from robot import RobotTestCase, wait_until

# (method, arguments, check of the result) for calls that leave the arm where it is.
QUERIES = [
    ("get_modify_version", (), lambda r: isinstance(r, int) and r >= 0),
    ("get_reboot_count", (), lambda r: isinstance(r, int) and r >= 0),
    ("check_async_or_sync", (), lambda r: r in (0, 1)),
    ("read_next_error", (), lambda r: r == [0] * 7),
    ("is_paused", (), lambda r: r == 0),
    ("get_transponder_mode", (), lambda r: r == 0),
    ("set_transponder_mode", (0,), lambda r: r == 1),
    ("set_vision_mode", (0,), lambda r: r == 1),
    ("focus_all_servos", (), lambda r: r == 1),
    ("joint_brake", (2,), lambda r: r == 1),
    ("backup_servo_params", (3,), lambda r: r == 1),
    ("restore_servo_params", (3,), lambda r: r == 1),
    ("is_torque_gripper", (), lambda r: r in (9, 40)),
    ("get_HTS_gripper_torque", (), lambda r: isinstance(r, int) and r >= 0),
    ("get_gripper_protect_current", (), lambda r: isinstance(r, int) and r >= 0),
    ("set_HTS_gripper_torque", (300,), lambda r: r == 1),
    ("set_gripper_protect_current", (300,), lambda r: r == 1),
    ("init_gripper", (), lambda r: r == 1),
    ("clear_queue", (), lambda r: r == 1),
]


class EveryCommandTest(RobotTestCase):
    def test_queries_and_settings_answer(self):
        for name, args, check in QUERIES:
            with self.subTest(call=name):
                result = getattr(self.mc, name)(*args)
                self.assertNotEqual(result, -1, f"{name}{args}: no answer")
                self.assertTrue(check(result), f"{name}{args} -> {result!r}")

    def test_planned_target_and_radians(self):
        self.home()
        self.assertAnglesClose(self.mc.get_angles_plan(), [0] * 6, msg="get_angles_plan at rest")
        self.assertPoseClose(self.mc.get_coords_plan(), self.mc.get_coords(), msg="get_coords_plan at rest")
        target = [0.3, -0.2, 0.4, -0.1, 0.25, 0.5]
        self.assertEqual(self.mc.send_radians(target, 100), 1)
        arrived = wait_until(
            lambda: all(abs(a - t) <= 0.005 for a, t in zip(self.mc.get_radians(), target))
            and self.mc.is_moving() == 0,
            4.0,
        )
        self.assertTrue(arrived, f"get_radians {self.mc.get_radians()} vs {target}")
        self.assertAnglesClose(self.mc.get_angles(), [math.degrees(t) for t in target], tol=0.3)
        self.assertEqual(self.mc.go_home(), 1)
        self.assertTrue(
            wait_until(lambda: self._within(self.mc.get_angles(), [0] * 6, 0.2) and self.mc.is_moving() == 0, 4.0),
            f"go_home ended at {self.mc.get_angles()}",
        )


if __name__ == "__main__":
    unittest.main()
