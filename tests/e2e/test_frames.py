"""Tool and world frames change the coordinates the arm reports and follows."""

import unittest

from robot import RobotTestCase, fk, position_error_mm, rotation_error_deg, wait_until

WORK = [0, -30, -60, 0, 30, 0]
TOOL = [0.0, 0.0, 50.0, 0.0, 0.0, 0.0]
WORLD = [100.0, -50.0, 20.0, 0.0, 0.0, 90.0]
ZERO = [0.0] * 6


class FrameTest(RobotTestCase):
    def tearDown(self):
        self.mc.set_end_type(0)
        self.mc.set_reference_frame(0)
        self.mc.set_tool_reference(ZERO)
        self.mc.set_world_reference(ZERO)
        self.mc.set_movement_type(0)

    def test_references_read_back(self):
        self.assertEqual(self.mc.set_tool_reference(TOOL), 1)
        self.assertEqual(self.mc.get_tool_reference(), TOOL)
        self.assertEqual(self.mc.set_world_reference(WORLD), 1)
        self.assertEqual(self.mc.get_world_reference(), WORLD)
        for setter, getter in (
            (self.mc.set_end_type, self.mc.get_end_type),
            (self.mc.set_reference_frame, self.mc.get_reference_frame),
            (self.mc.set_movement_type, self.mc.get_movement_type),
        ):
            for value in (1, 0):
                self.assertEqual(setter(value), 1)
                self.assertEqual(getter(), value)

    def test_tool_end_type_reports_the_tool_tip(self):
        self.home()
        self.mc.set_tool_reference(TOOL)
        flange = self.mc.get_coords()
        self.assertEqual(self.mc.set_end_type(1), 1)
        self.assertPoseClose(self.mc.get_coords(), [95.6, -63.4, 412.67, -90.0, 0.0, -90.0], msg="tool tip at zero")
        self.move_to_angles(WORK)
        angles = self.mc.get_angles()
        self.assertPoseClose(self.mc.get_coords(), fk(angles, tool=TOOL), msg="tool tip at WORK")
        self.assertEqual(self.mc.set_end_type(0), 1)
        self.assertPoseClose(self.mc.get_coords(), fk(angles), msg="flange again")
        self.assertNotEqual(flange, self.mc.get_coords())
        self.home()

    def test_world_reference_frame_shifts_reported_coords(self):
        self.move_to_angles(WORK)
        angles = self.mc.get_angles()
        self.mc.set_world_reference(WORLD)
        self.assertEqual(self.mc.set_reference_frame(1), 1)
        self.assertPoseClose(self.mc.get_coords(), fk(angles, world=WORLD), msg="flange in world frame")
        self.mc.set_tool_reference(TOOL)
        self.mc.set_end_type(1)
        self.assertPoseClose(self.mc.get_coords(), fk(angles, tool=TOOL, world=WORLD), msg="tool in world frame")
        self.home()

    def test_send_coords_moves_the_tool_tip_in_the_world_frame(self):
        self.move_to_angles(WORK)
        self.mc.set_tool_reference(TOOL)
        self.mc.set_world_reference(WORLD)
        self.mc.set_end_type(1)
        self.mc.set_reference_frame(1)
        target = [round(v, 1) for v in fk([15, -20, -70, 10, 40, 10], tool=TOOL, world=WORLD)]
        self.assertEqual(self.mc.send_coords(target, 100, 0), 1)

        def arrived():
            c = self.mc.get_coords()
            return (
                isinstance(c, list)
                and position_error_mm(c, target) <= 1.0
                and rotation_error_deg(c[3:], target[3:]) <= 0.5
                and self.mc.is_moving() == 0
            )

        self.assertTrue(wait_until(arrived, 6.0), f"tool tip at {self.mc.get_coords()}, wanted {target}")
        tip = fk(self.mc.get_angles(), tool=TOOL, world=WORLD)
        self.assertLessEqual(position_error_mm(tip, target), 1.0, "reference FK of the reached angles")
        self.home()


if __name__ == "__main__":
    unittest.main()
