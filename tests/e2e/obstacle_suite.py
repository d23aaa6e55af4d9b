"""Collision protection with the real client, against a robot started with obstacles in joint
2's way at 30 degrees and joint 3's at -40 (`--obstacle 2:30 --obstacle 3:-40`;
tests/pymycobot.rs starts it). pymycobot 4.0.7's
MyCobot280 has no collision methods: the settings go as raw frames (docs/protocol.md section
7), everything else through MyCobot280's own methods."""

import time

from robot import RobotTestCase, frame, wait_until

OBSTACLE_DEG = 30.0


class ObstacleTest(RobotTestCase):
    def setUp(self):
        super().setUp()
        self.assertEqual(self.send_raw(frame(0x74, 1)), frame(0x74, 1), "protection on")
        self.home()

    def tearDown(self):
        self.send_raw(frame(0x74, 1))
        self.mc.clear_error_information()

    def move_into_the_obstacle(self):
        self.assertEqual(self.mc.send_angle(2, 60, 50), 1, "the move is accepted")
        return self.wait_stopped()

    def test_a_move_into_the_obstacle_stops_and_reports_a_collision(self):
        angles = self.move_into_the_obstacle()
        self.assertEqual(self.mc.get_error_information(), 16, "collision while moving joints")
        self.assertAlmostEqual(angles[1], OBSTACLE_DEG, delta=1.0, msg=f"stopped at the obstacle: {angles}")
        # Motion is refused with the code until the host clears it.
        self.assertEqual(self.mc.send_angle(2, 50, 50), 0)
        self.assertEqual(self.mc.send_angles([0, 10, 0, 0, 0, 0], 50), 0)
        self.assertEqual(self.mc.get_error_information(), 16)
        time.sleep(0.5)
        self.assertAlmostEqual(self.mc.get_angles()[1], angles[1], delta=0.2, msg="nothing moved")

    def test_after_clearing_the_arm_moves_away_from_the_obstacle(self):
        self.move_into_the_obstacle()
        self.assertEqual(self.mc.clear_error_information(), 1)
        self.assertEqual(self.mc.get_error_information(), 0)
        self.move_to_angles([0, -10, 0, 0, 0, 0], speed=50)
        self.assertEqual(self.mc.get_error_information(), 0, "moving away raises nothing")

    def test_a_line_into_an_obstacle_is_a_cartesian_collision(self):
        self.move_to_angles([0, -20, -30, -10, 0, 0], speed=80)
        through = self.mc.angles_to_coords([0, 80, -30, -10, 0, 0])
        self.assertEqual(self.mc.send_coords(through, 50, 1), 1, "the line is accepted")
        angles = self.wait_stopped()
        self.assertEqual(self.mc.get_error_information(), 17, "collision in a line")
        self.assertAlmostEqual(angles[2], -40.0, delta=1.0, msg=f"joint 3 stopped at its obstacle: {angles}")
        self.assertEqual(self.mc.clear_error_information(), 1)
        self.move_to_angles([0, 0, 0, 0, 0, 0], speed=50)

    def test_power_on_also_ends_the_refusal(self):
        self.move_into_the_obstacle()
        self.assertEqual(self.mc.power_on(), 1)
        self.assertEqual(self.mc.get_error_information(), 0, "and clears the code")
        self.move_to_angles([0, 0, 0, 0, 0, 0], speed=50)

    def test_with_protection_off_the_arm_presses_on_as_before(self):
        self.assertEqual(self.send_raw(frame(0x74, 0)), frame(0x74, 1))
        self.assertEqual(self.send_raw(frame(0xFD)), frame(0xFD, 0))
        self.assertEqual(self.mc.send_angle(2, 60, 50), 1)
        pressing = wait_until(lambda: abs(self.mc.get_angles()[1] - OBSTACLE_DEG) < 1.0, 3.0)
        self.assertTrue(pressing, f"at the obstacle: {self.mc.get_angles()}")
        time.sleep(0.5)
        self.assertEqual(self.mc.get_error_information(), 0, "no collision reported")
        self.assertEqual(self.mc.is_moving(), 1, "still pushing towards 60 deg")
        self.move_to_angles([0, 0, 0, 0, 0, 0], speed=50)

    def test_thresholds_are_set_per_joint_and_bad_values_change_nothing(self):
        self.assertEqual(self.send_raw(frame(0x76)), frame(0x76, *[100] * 6))
        for bad in [(0, 100), (7, 100), (2, 49), (2, 251)]:
            self.assertEqual(self.send_raw(frame(0x75, *bad)), frame(0x75, 0), f"{bad}")
        self.assertEqual(self.send_raw(frame(0x74, 2)), frame(0x74, 0))
        self.assertEqual(self.send_raw(frame(0x75, 2, 250)), frame(0x75, 1))
        self.assertEqual(self.send_raw(frame(0x76)), frame(0x76, 100, 250, 100, 100, 100, 100))
        # The hardest threshold still feels the obstacle.
        self.move_into_the_obstacle()
        self.assertEqual(self.mc.get_error_information(), 16)
        self.assertEqual(self.send_raw(frame(0x75, 2, 100)), frame(0x75, 1))
