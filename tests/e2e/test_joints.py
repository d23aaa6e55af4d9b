"""Encoders, joint limits and servo queries."""

import time
import unittest

from robot import DEFAULT_MAX, DEFAULT_MIN, RobotTestCase, wait_until

STEPS_PER_DEG = 4096 / 360


class EncoderTest(RobotTestCase):
    def test_zero_pose_is_encoder_2048(self):
        self.home()
        encoders = self.mc.get_encoders()
        self.assertIsInstance(encoders, list, f"get_encoders -> {encoders!r}")
        self.assertEqual(len(encoders), 6)
        for joint, value in enumerate(encoders, start=1):
            self.assertLessEqual(abs(value - 2048), 3, f"joint {joint} encoder {value} at 0 deg")
            self.assertEqual(self.mc.get_encoder(joint), value)

    def test_set_encoders_moves_the_joints(self):
        self.home()
        target = [2048 + 100, 2048 - 200, 2048 + 300, 2048 - 150, 2048 + 250, 2048 + 400]
        self.assertEqual(self.mc.set_encoders(target, 100), 1)
        arrived = wait_until(
            lambda: all(abs(a - t) <= 3 for a, t in zip(self.mc.get_encoders(), target)) and self.mc.is_moving() == 0,
            6.0,
        )
        self.assertTrue(arrived, f"encoders {self.mc.get_encoders()} vs {target}")
        expected_angles = [(t - 2048) / STEPS_PER_DEG for t in target]
        self.assertAnglesClose(self.mc.get_angles(), expected_angles, tol=0.3, msg="angles of the encoder targets")
        self.home()

    def test_set_encoder_moves_one_joint(self):
        self.home()
        self.assertEqual(self.mc.set_encoder(6, 2048 + 512, 100), 1)
        arrived = wait_until(lambda: abs(self.mc.get_encoder(6) - 2560) <= 3 and self.mc.is_moving() == 0, 4.0)
        self.assertTrue(arrived, f"joint 6 encoder {self.mc.get_encoder(6)}")
        self.assertAlmostEqual(self.mc.get_angles()[5], 45.0, delta=0.3)
        self.home()


    def test_set_encoders_drag_moves_the_joints(self):
        self.home()
        target = [2048 + 200, 2048, 2048 - 200, 2048, 2048, 2048 + 300]
        self.assertEqual(self.mc.set_encoders_drag(target, [1000] * 6), 1)
        arrived = wait_until(
            lambda: all(abs(a - t) <= 3 for a, t in zip(self.mc.get_encoders(), target)) and self.mc.is_moving() == 0,
            6.0,
        )
        self.assertTrue(arrived, f"encoders {self.mc.get_encoders()} vs {target}")
        self.home()

    def test_servo_calibration_makes_the_current_position_zero(self):
        self.home()
        self.assertEqual(self.mc.send_angle(6, 20, 100), 1)
        self.assertTrue(wait_until(lambda: abs(self.mc.get_angles()[5] - 20) <= 0.2 and self.mc.is_moving() == 0, 4.0))
        try:
            self.assertEqual(self.mc.set_servo_calibration(6), 1)
            self.assertAlmostEqual(self.mc.get_angles()[5], 0.0, delta=0.2, msg="not zero after calibration")
            self.assertLessEqual(abs(self.mc.get_encoder(6) - 2048), 2)
        finally:
            # Undo: the old zero is now at -20 deg; calibrate there again.
            self.mc.send_angle(6, -20, 100)
            wait_until(lambda: abs(self.mc.get_angles()[5] + 20) <= 0.2 and self.mc.is_moving() == 0, 4.0)
            self.mc.set_servo_calibration(6)
        self.assertAlmostEqual(self.mc.get_angles()[5], 0.0, delta=0.3)
        self.home()


class LimitTest(RobotTestCase):
    def tearDown(self):
        for joint in range(1, 7):
            self.mc.set_joint_min(joint, int(DEFAULT_MIN[joint - 1]))
            self.mc.set_joint_max(joint, int(DEFAULT_MAX[joint - 1]))

    def test_factory_limits(self):
        for joint in range(1, 7):
            self.assertEqual(self.mc.get_joint_min_angle(joint), DEFAULT_MIN[joint - 1], f"joint {joint} min")
            self.assertEqual(self.mc.get_joint_max_angle(joint), DEFAULT_MAX[joint - 1], f"joint {joint} max")

    def test_set_limits_read_back_and_out_of_limit_move_is_refused(self):
        self.home()
        self.assertEqual(self.mc.set_joint_max(1, 30), 1)
        self.assertEqual(self.mc.set_joint_min(1, -20), 1)
        self.assertEqual(self.mc.get_joint_max_angle(1), 30.0)
        self.assertEqual(self.mc.get_joint_min_angle(1), -20.0)

        self.mc.send_angle(1, 50, 100)
        self.assertEqual(self.mc.get_error_information(), 1, "error code after joint 1 was sent past its max")
        time.sleep(0.6)
        self.assertLessEqual(self.mc.get_angles()[0], 30.2, "moved past the user's max limit")
        self.mc.clear_error_information()
        self.mc.send_angles([-40, 0, 0, 0, 0, 0], 100)
        self.assertEqual(self.mc.get_error_information(), 1, "error code after joint 1 was sent past its min")
        time.sleep(0.6)
        self.assertGreaterEqual(self.mc.get_angles()[0], -20.2, "moved past the user's min limit")

        # Inside the new limits it still moves.
        self.mc.clear_error_information()
        self.move_to_angles([25, 0, 0, 0, 0, 0])
        self.home()

    def test_factory_limit_is_enforced_for_clients_that_do_not_check(self):
        # pymycobot refuses 170 deg client-side; send the raw request like other clients would.
        self.home()
        frame = [0xFE, 0xFE, 0x06, 0x21, 0x01, 0x42, 0x68, 0x64, 0xFA]  # joint 1 to 170.00 deg
        port = self.mc._serial_port
        with self.mc.lock:
            port.reset_input_buffer()
            port.write(bytes(frame))
            time.sleep(0.2)
            port.read(port.in_waiting)
        time.sleep(0.5)
        self.assertLessEqual(self.mc.get_angles()[0], 168.2)
        self.home()


class ServoQueryTest(RobotTestCase):
    def test_servos_enabled_and_release_focus(self):
        self.home()
        self.assertEqual(self.mc.is_all_servo_enable(), 1)
        for joint in range(1, 7):
            self.assertEqual(self.mc.is_servo_enable(joint), 1, f"joint {joint}")
        try:
            self.assertEqual(self.mc.release_servo(4), 1)
            self.assertEqual(self.mc.is_servo_enable(4), 0)
            self.assertEqual(self.mc.is_all_servo_enable(), 0)
        finally:
            self.assertEqual(self.mc.focus_servo(4), 1)
        self.assertEqual(self.mc.is_servo_enable(4), 1)
        self.assertEqual(self.mc.is_all_servo_enable(), 1)

    def test_release_all_servos_then_power_on(self):
        self.assertEqual(self.mc.release_all_servos(), 1)
        self.assertEqual(self.mc.is_all_servo_enable(), 0)
        self.assertEqual(self.mc.power_on(), 1)
        self.assertEqual(self.mc.is_all_servo_enable(), 1)

    def test_voltages_temperatures_status(self):
        volts = self.mc.get_servo_voltages()
        self.assertIsInstance(volts, list, f"get_servo_voltages -> {volts!r}")
        self.assertEqual(len(volts), 6)
        for v in volts:
            self.assertTrue(5.0 <= v <= 14.0, f"implausible servo voltage {v} V in {volts}")
        temps = self.mc.get_servo_temps()
        self.assertIsInstance(temps, list, f"get_servo_temps -> {temps!r}")
        self.assertEqual(len(temps), 6)
        for t in temps:
            self.assertTrue(10 <= t <= 70, f"implausible servo temperature {t} C in {temps}")
        status = self.mc.get_servo_status()
        self.assertEqual(status, [0] * 6, "healthy servos report no fault bits")

    def test_servo_speeds_while_moving(self):
        self.home()
        idle = self.mc.get_servo_speeds()
        self.assertIsInstance(idle, list, f"get_servo_speeds -> {idle!r}")
        self.assertEqual(len(idle), 6)
        self.assertTrue(all(s == 0 for s in idle), f"speeds at rest: {idle}")
        self.mc.send_angles([60, 0, 0, 0, 0, 0], 50)
        moving = wait_until(lambda: self.mc.get_servo_speeds()[0] != 0, 2.0)
        self.assertTrue(moving, "servo 1 speed stayed 0 during a move")
        self.wait_stopped()
        self.home()

    def test_servo_data_read_and_write(self):
        # Register 5 is the servo id; 56 (2 bytes) the present position = the encoder.
        for servo in (1, 4, 7):
            self.assertEqual(self.mc.get_servo_data(servo, 5), servo, f"servo {servo} id register")
        self.home()
        self.assertLessEqual(abs(self.mc.get_servo_data(2, 56, 1) - self.mc.get_encoder(2)), 2)
        # Register 21 is the P gain.
        original = self.mc.get_servo_data(3, 21)
        self.assertIsInstance(original, int)
        try:
            self.assertEqual(self.mc.set_servo_data(3, 21, 20), 1)
            self.assertEqual(self.mc.get_servo_data(3, 21), 20)
        finally:
            self.mc.set_servo_data(3, 21, original)
        self.assertEqual(self.mc.get_servo_data(3, 21), original)


if __name__ == "__main__":
    unittest.main()
