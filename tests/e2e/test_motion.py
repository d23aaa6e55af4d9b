"""Moves by angles and by coordinates: the arm must actually arrive where it was told, and the
coordinates it reports must be the forward kinematics of the angles it reports."""

import math
import time
import unittest

from robot import MOVE_TIMEOUT, PATIENCE, POS_TOL_MM, RobotTestCase, fk, position_error_mm, rotation_error_deg, wait_until

POSE_A = [10, 20, -30, 15, -25, 40]
# A comfortable working pose: elbow bent, wrist away from its singularity.
WORK = [0, -30, -60, 0, 30, 0]


class AngleMoveTest(RobotTestCase):
    def test_send_angles_arrives_and_coords_match_forward_kinematics(self):
        reached = self.move_to_angles(POSE_A)
        self.assertAnglesClose(reached, POSE_A, msg="get_angles after arrival")
        coords = self.mc.get_coords()
        self.assertPoseClose(coords, fk(reached), msg="get_coords vs f64 FK of get_angles")
        both = self.mc.get_angles_coords()
        self.assertIsInstance(both, list, f"get_angles_coords -> {both!r}")
        self.assertEqual(len(both), 12)
        self.assertAnglesClose(both[:6], reached, tol=0.1, msg="get_angles_coords angles")
        self.assertPoseClose(both[6:], coords, msg="get_angles_coords coords")
        self.home()

    def test_zero_pose_coordinates(self):
        self.home()
        self.assertPoseClose(self.mc.get_coords(), [45.6, -63.4, 412.67, -90.0, 0.0, -90.0], msg="zero pose")

    def test_send_angle_moves_one_joint_only(self):
        self.home()
        self.assertEqual(self.mc.send_angle(2, -35.5, 100), 1)
        reached = wait_until(lambda: abs(self.mc.get_angles()[1] + 35.5) <= 0.2 and self.mc.is_moving() == 0, MOVE_TIMEOUT)
        self.assertTrue(reached, f"joint 2 did not reach -35.5: {self.mc.get_angles()}")
        self.assertAnglesClose(self.mc.get_angles(), [0, -35.5, 0, 0, 0, 0])
        self.home()

    def test_every_joint_reaches_both_ends_of_a_wide_move(self):
        target = [-60, 45, 70, -80, 90, -120]
        self.assertAnglesClose(self.move_to_angles(target, timeout=8), target)
        self.home()

    def test_is_in_position_and_planned_target(self):
        self.home()
        target = [30, 0, 0, 0, 0, 0]
        self.assertEqual(self.mc.send_angles(target, 20), 1)
        self.assertTrue(wait_until(lambda: self.mc.is_moving() == 1, 1.0), "is_moving never became 1")
        self.assertAnglesClose(self.mc.get_angles_plan(), target, msg="get_angles_plan during the move")
        self.assertEqual(self.mc.is_in_position(target, 0), 0, "in position while still moving")
        self.wait_stopped()
        self.assertEqual(self.mc.is_in_position(target, 0), 1)
        self.assertEqual(self.mc.is_in_position([0, 0, 0, 0, 0, 0], 0), 0)
        self.assertEqual(self.mc.is_in_position(fk(self.mc.get_angles()), 1), 1)
        self.home()

    def test_angles_to_coords_and_inverse_kinematics_agree_with_reference(self):
        for angles in ([0, 0, 0, 0, 0, 0], POSE_A, WORK, [-90, -45, 100, -30, 60, 170]):
            coords = self.mc.angles_to_coords(angles)
            self.assertPoseClose(coords, fk(angles), msg=f"angles_to_coords({angles})")
        target = fk(WORK)
        solution = self.mc.solve_inv_kinematics([round(v, 1) for v in target], [5, -25, -55, 5, 25, 5])
        self.assertIsInstance(solution, list, f"solve_inv_kinematics -> {solution!r}")
        self.assertPoseClose(fk(solution), target, msg="FK of the IK solution")
        self.assertAnglesClose(solution, WORK, tol=1.0, msg="IK picks the branch nearest the seed")


class CoordMoveTest(RobotTestCase):
    def start_from(self, angles):
        self.move_to_angles(angles)
        return self.mc.get_coords()

    def wait_coords(self, target, timeout=MOVE_TIMEOUT):
        def arrived():
            c = self.mc.get_coords()
            return (
                isinstance(c, list)
                and position_error_mm(c, target) <= 1.0
                and rotation_error_deg(c[3:], target[3:]) <= 0.5
                and self.mc.is_moving() == 0
            )

        self.assertTrue(wait_until(arrived, timeout), f"did not reach {target}: at {self.mc.get_coords()}")
        coords = self.mc.get_coords()
        self.assertPoseClose(coords, fk(self.mc.get_angles()), msg="reported coords vs FK of reported angles")
        return coords

    def test_send_coords_joint_interpolated(self):
        self.start_from(WORK)
        target = [round(v, 1) for v in fk([20, -20, -70, 10, 40, 10])]
        self.assertEqual(self.mc.send_coords(target, 100, 0), 1)
        self.wait_coords(target)
        self.home()

    def test_send_coords_linear_follows_a_straight_line(self):
        start = self.start_from(WORK)
        target = list(start)
        target[0] += 40.0
        target[2] -= 30.0
        target = [round(v, 1) for v in target]
        self.assertEqual(self.mc.send_coords(target, 30, 1), 1)
        samples = []
        deadline = time.monotonic() + MOVE_TIMEOUT * PATIENCE
        while time.monotonic() < deadline:
            c = self.mc.get_coords()
            if isinstance(c, list):
                samples.append(c)
            if self.mc.is_moving() == 0 and len(samples) > 3:
                break
        self.wait_coords(target)
        # Every sampled point lies on the segment from start to target.
        direction = [t - s for t, s in zip(target[:3], start[:3])]
        length = math.sqrt(sum(d * d for d in direction))
        for c in samples:
            rel = [p - s for p, s in zip(c[:3], start[:3])]
            along = sum(r * d for r, d in zip(rel, direction)) / length
            off_line = math.sqrt(max(0.0, sum(r * r for r in rel) - along * along))
            # A joint-interpolated arc between these poses strays ~10 mm; servo tracking lag
            # behind the streamed waypoints accounts for ~2 mm.
            self.assertLessEqual(off_line, 3.0, f"left the straight line at {c}")
            self.assertGreaterEqual(along, -1.0)
            self.assertLessEqual(along, length + 1.0)
        self.assertGreater(len(samples), 3, "too few samples during the linear move")
        self.home()

    def test_send_coord_moves_along_one_axis(self):
        start = self.start_from(WORK)
        target = list(start)
        target[2] = round(start[2] - 25.0, 1)
        self.assertEqual(self.mc.send_coord(3, target[2], 100), 1)
        self.wait_coords(target)
        self.home()

    def test_sync_send_coords_returns_at_the_target(self):
        for mode, angles in ((0, [20, -20, -70, 10, 40, 10]), (1, [5, -35, -55, 5, 35, 5])):
            self.start_from(WORK)
            target = [round(v, 1) for v in fk(angles)]
            self.mc.sync_send_coords(target, 50, mode, timeout=8)
            coords = self.mc.get_coords()
            self.assertLessEqual(position_error_mm(coords, target), 1.0, f"mode {mode}: {coords} vs {target}")
            self.assertLessEqual(rotation_error_deg(coords[3:], target[3:]), 0.5, f"mode {mode}: {coords}")
        self.home()

    def test_unreachable_coords_are_refused_with_error_32(self):
        before = self.start_from(WORK)
        angles_before = self.mc.get_angles()
        self.mc.clear_error_information()
        self.mc.send_coords([250.0, 250.0, 300.0, -90.0, 0.0, -90.0], 100, 0)
        self.assertEqual(self.mc.get_error_information(), 32)
        time.sleep(0.3)
        self.assertAnglesClose(self.mc.get_angles(), angles_before, tol=0.2, msg="the arm moved anyway")
        self.assertLessEqual(position_error_mm(self.mc.get_coords(), before), POS_TOL_MM)
        self.assertEqual(self.mc.clear_error_information(), 1)
        self.assertEqual(self.mc.get_error_information(), 0)
        self.home()


class QueueTest(RobotTestCase):
    def max_joint1_during(self, first, second):
        """Sends two moves back to back; returns the largest joint-1 angle seen until rest."""
        self.assertEqual(self.mc.send_angles(first, 100), 1)
        self.assertEqual(self.mc.send_angles(second, 100), 1)
        highest = 0.0
        deadline = time.monotonic() + MOVE_TIMEOUT * PATIENCE
        while time.monotonic() < deadline:
            highest = max(highest, self.mc.get_angles()[0])
            if self._within(self.mc.get_angles(), second, 0.2) and self.mc.is_moving() == 0:
                return highest
        self.fail(f"did not reach {second}: at {self.mc.get_angles()}")

    def test_fresh_mode_decides_between_queueing_and_preempting(self):
        original = self.mc.get_fresh_mode()
        first, second = [40, 0, 0, 0, 0, 0], [0, 20, 0, 0, 0, 0]
        try:
            self.home()
            self.mc.set_fresh_mode(0)
            # The peak at 40 is passed at low speed; a busy client polls it up to ~100 ms apart,
            # about a degree below it. Fresh mode preempts below 30.
            self.assertGreaterEqual(self.max_joint1_during(first, second), 38.5, "queue mode skipped a move")
            self.home()
            self.mc.set_fresh_mode(1)
            self.assertLess(self.max_joint1_during(first, second), 30, "fresh mode did not preempt")
        finally:
            self.mc.set_fresh_mode(original)
        self.home()

    def test_sync_send_angles_returns_once_arrived(self):
        # pymycobot's sync_send_angles polls is_in_position and returns when it answers 1, so
        # the firmware must not call a pose reached while the arm is still on its way.
        for speed in (80, 30):
            self.home()
            target = [-20, 15, -25, 10, 20, -30]
            self.mc.sync_send_angles(target, speed, timeout=8)
            self.assertAnglesClose(self.mc.get_angles(), target, msg=f"right after sync_send_angles at speed {speed}")
        self.home()


class PauseStopTest(RobotTestCase):
    def test_pause_resume_and_stop(self):
        self.home()
        target = [90, 0, 0, 0, 0, 0]
        self.assertEqual(self.mc.send_angles(target, 10), 1)
        self.assertTrue(wait_until(lambda: self.mc.get_angles()[0] > 3, 2.0), "move did not start")
        self.assertEqual(self.mc.pause(), 1)
        self.assertEqual(self.mc.is_paused(), 1)
        held = self.wait_stopped()[0]
        time.sleep(0.3)
        self.assertAlmostEqual(self.mc.get_angles()[0], held, delta=0.2, msg="moved while paused")
        self.assertLess(held, 85)

        self.assertEqual(self.mc.resume(), 1)
        self.assertEqual(self.mc.is_paused(), 0)
        self.assertTrue(wait_until(lambda: self.mc.get_angles()[0] > held + 2, 2.0), "did not resume")

        self.assertEqual(self.mc.stop(), 1)
        self.wait_stopped(2.0)
        stopped_at = self.mc.get_angles()[0]
        time.sleep(0.3)
        self.assertAlmostEqual(self.mc.get_angles()[0], stopped_at, delta=0.2, msg="moved after stop")
        self.assertLess(stopped_at, 85, "stop did not stop the move")
        self.home()


if __name__ == "__main__":
    unittest.main()
