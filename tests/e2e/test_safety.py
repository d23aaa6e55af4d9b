"""What a careless or hostile client cannot do: widen a joint beyond the arm's factory range,
move a joint's zero or switch a protection off with a raw register write, make a joint creep
with a zero drag speed, or mistake "no solution" for a solution."""

import time

from robot import DEFAULT_MAX, DEFAULT_MIN, RobotTestCase, frame, i16


class LimitTest(RobotTestCase):
    def tearDown(self):
        for joint in range(1, 7):
            self.mc.set_joint_min(joint, int(DEFAULT_MIN[joint - 1]))
            self.mc.set_joint_max(joint, int(DEFAULT_MAX[joint - 1]))

    def test_a_limit_beyond_the_factory_range_is_refused_and_changes_nothing(self):
        # pymycobot refuses -170 itself; a raw client (the tester's FE FE 05 4C 02 F9 5C FA) may not.
        self.assertEqual(self.send_raw(frame(0x4C, 2, *i16(-1700))), frame(0x4C, 0))
        self.assertEqual(self.mc.get_error_information(), 2, "0x07 names the joint")
        self.assertEqual(self.mc.get_joint_min_angle(2), -140.0)
        self.assertEqual(self.send_raw(frame(0x21, 2, *i16(-15500), 50)), frame(0x21, 0), "past the factory range")
        time.sleep(0.3)
        self.assertLess(abs(self.mc.get_angles()[1]), 1.0, "joint 2 did not move")

    def test_a_limit_can_be_narrowed_and_restored(self):
        self.assertEqual(self.mc.set_joint_max(1, 30), 1)
        self.assertEqual(self.mc.send_angle(1, 40, 50), 0)
        self.assertEqual(self.mc.set_joint_max(1, 168), 1)
        self.assertEqual(self.mc.get_joint_max_angle(1), 168.0)


class RawWriteTest(RobotTestCase):
    def test_the_homing_offset_cannot_be_written(self):
        self.home()
        before = self.mc.get_servo_data(1, 31, 1)
        self.assertEqual(self.mc.set_servo_data(1, 31, 1000, 1), 0)
        time.sleep(0.1)
        self.assertEqual(self.mc.get_servo_data(1, 31, 1), before, "the zero stayed where it was")
        self.assertLess(abs(self.mc.get_angles()[0]), 0.2, "get_angles did not jump")

    def test_protection_and_identity_registers_cannot_be_written(self):
        for address, value in [(5, 9), (9, 0), (13, 100), (33, 1), (36, 100), (55, 0)]:
            self.assertEqual(self.mc.set_servo_data(2, address, value), 0, f"register {address}")
        self.assertEqual(self.mc.set_servo_data(2, 11, 4095, 1), 0, "the servo's own angle limit")

    def test_tuning_registers_can_be_written(self):
        p = self.mc.get_servo_data(3, 21)
        self.assertEqual(self.mc.set_servo_data(3, 21, 12), 1)
        time.sleep(0.1)
        self.assertEqual(self.mc.get_servo_data(3, 21), 12)
        self.assertEqual(self.mc.set_servo_data(3, 21, p), 1)


class DragSpeedTest(RobotTestCase):
    def test_a_drag_with_zero_speeds_is_refused_and_nothing_creeps(self):
        self.home()
        self.assertEqual(self.mc.set_encoders_drag([2500] * 6, [0] * 6), 0)
        time.sleep(0.5)
        self.assertEqual(self.mc.is_moving(), 0)
        self.assertLess(max(abs(a) for a in self.mc.get_angles()), 0.2)


class InverseKinematicsTest(RobotTestCase):
    def test_an_unreachable_pose_answers_no_solution_not_angles(self):
        answer = self.mc.solve_inv_kinematics([500, 500, 500, 0, 0, 0], [0, 0, 0, 0, 0, 0])
        self.assertNotIsInstance(answer, list, f"solve_inv_kinematics -> {answer!r}")
        self.assertEqual(answer, 0)
        self.assertEqual(self.mc.get_error_information(), 32)


class BackupTest(RobotTestCase):
    def test_restore_brings_back_the_parameters_of_a_backup(self):
        self.assertEqual(self.mc.backup_servo_params(4), 1)
        original = self.mc.get_servo_data(4, 21)
        self.assertEqual(self.mc.set_servo_data(4, 21, original + 7), 1)
        time.sleep(0.1)
        self.assertEqual(self.mc.get_servo_data(4, 21), original + 7)
        self.assertEqual(self.mc.restore_servo_params(4), 1)
        time.sleep(0.1)
        self.assertEqual(self.mc.get_servo_data(4, 21), original, "the backed-up P gain is back")
        self.assertEqual(self.mc.is_servo_enable(4), 1, "the servo still holds")
