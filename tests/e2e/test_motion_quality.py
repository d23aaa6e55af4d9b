"""How the arm moves, as a user driving it with pymycobot sees it: it stops close to where stop
was sent (no coasting, no swinging back), a stream of send_angles is followed closely and
without stopping between targets (the mycobot_ros way), and straight lines are straight.

The figures behind these bounds come from `cargo bench --bench motion` (virtual time, exact
shaft positions); here they are checked through the client, in real time, with slack for the
client's timing and the 0.01 deg / 0.1 mm resolution of what the arm reports."""

import math
import time

from robot import RobotTestCase, wait_until

# The servos brake at 1000 deg/s^2 at most (docs/motion.md): from 150 deg/s a joint needs
# 11.25 deg to stop; from 75 deg/s, 2.8 deg.
STOP_TRAVEL_FULL_SPEED_DEG = 14.0
STOP_TRAVEL_HALF_SPEED_DEG = 4.5


def sine(t):
    """The stream's joint angles (degrees) at t seconds: a 0.4 Hz sine on every joint."""
    amplitude = [40, 25, 30, 35, 30, 45]
    centre = [0, -20, -40, 10, 0, 0]
    return [c + a * math.sin(2 * math.pi * 0.4 * t + j * 0.7) for j, (c, a) in enumerate(zip(centre, amplitude))]


def distance_to_segment(p, a, b):
    ab = [bb - aa for aa, bb in zip(a, b)]
    ap = [pp - aa for aa, pp in zip(a, p)]
    length2 = sum(v * v for v in ab)
    t = max(0.0, min(1.0, sum(x * y for x, y in zip(ap, ab)) / length2)) if length2 else 0.0
    return math.dist(p, [aa + t * v for aa, v in zip(a, ab)])


class StopTest(RobotTestCase):
    def stop_jog(self, speed, limit_deg):
        self.move_to_angles([-120, 0, 0, 0, 0, 0], timeout=8)
        self.assertEqual(self.mc.jog_angle(1, 1, speed), 1)
        time.sleep(1.2)
        at_stop = self.mc.get_angles()[0]
        self.assertEqual(self.mc.stop(), 1)
        seen = [self.mc.get_angles()[0] for _ in range(60)]
        rest = self.wait_stopped()[0]
        furthest = max(seen + [rest])
        self.assertGreater(at_stop, -100, f"the jog moved joint 1: {at_stop}")
        self.assertLessEqual(
            furthest - at_stop, limit_deg, f"joint 1 went on {furthest - at_stop:.1f} deg after stop at {at_stop}"
        )
        self.assertGreaterEqual(rest, furthest - 0.3, f"joint 1 swung back from {furthest} to {rest}")
        self.home()

    def test_stop_during_a_full_speed_jog_stops_within_the_servos_braking_distance(self):
        self.stop_jog(100, STOP_TRAVEL_FULL_SPEED_DEG)

    def test_stop_during_a_half_speed_jog_stops_within_a_few_degrees(self):
        self.stop_jog(50, STOP_TRAVEL_HALF_SPEED_DEG)

    def test_pause_during_a_fast_move_stops_close_and_resume_finishes_it(self):
        self.move_to_angles([-120, 0, 0, 0, 0, 0], timeout=8)
        self.assertEqual(self.mc.send_angles([120, 0, 0, 0, 0, 0], 100), 1)
        time.sleep(1.0)
        at_pause = self.mc.get_angles()[0]
        self.assertEqual(self.mc.pause(), 1)
        rest = self.wait_stopped()[0]
        self.assertLessEqual(rest - at_pause, STOP_TRAVEL_FULL_SPEED_DEG, f"paused at {at_pause}, rested at {rest}")
        self.assertEqual(self.mc.is_paused(), 1)
        self.assertEqual(self.mc.resume(), 1)
        self.assertTrue(
            wait_until(lambda: abs(self.mc.get_angles()[0] - 120) <= 0.2 and self.mc.is_moving() == 0, 6),
            f"the resumed move did not finish: {self.mc.get_angles()}",
        )
        self.home()


class StreamTest(RobotTestCase):
    def test_a_50_hz_stream_of_send_angles_is_followed_closely(self):
        self.assertEqual(self.mc.set_fresh_mode(1), 1)
        self.move_to_angles([round(a, 1) for a in sine(0)], timeout=8)
        period = 0.02
        sent = []  # (time, angles) of each target
        read = []  # (time, angles) the arm reported
        start = time.monotonic()
        next_at = start
        while time.monotonic() - start < 4.0:
            now = time.monotonic()
            if now >= next_at:
                target = [round(a, 2) for a in sine(now - start)]
                self.mc.send_angles(target, 100)
                sent.append((now - start, target))
                next_at += period
            angles = self.mc.get_angles()
            if isinstance(angles, list) and len(angles) == 6:
                read.append((time.monotonic() - start, angles))
        last_target = sent[-1][1]
        steady = [(t, q) for t, q in read if t >= 1.0]

        def residual(lag):
            errors = [q[j] - sine(t - lag)[j] for t, q in steady for j in range(6)]
            return math.sqrt(sum(e * e for e in errors) / len(errors))

        lag = min((l / 1000 for l in range(0, 301, 2)), key=residual)
        rms = residual(lag)
        self.assertLessEqual(lag, period + 0.06, f"the arm trails the stream by {lag * 1000:.0f} ms")
        self.assertLessEqual(rms, 0.5, f"{rms:.2f} deg RMS off the stream after removing a {lag * 1000:.0f} ms lag")
        # The stream stops: the arm comes to rest at its last target.
        end = self.wait_stopped()
        self.assertAnglesClose(end, last_target, tol=0.3, msg="rest after the stream")
        self.home()


class LineTest(RobotTestCase):
    def test_send_coords_mode_1_draws_a_straight_line(self):
        self.move_to_angles([10, -30, -50, -10, 10, 20])
        start = self.mc.get_coords()
        target = [start[0] - 60, start[1] + 80, start[2] - 40] + start[3:]
        self.assertEqual(self.mc.send_coords(target, 50, 1), 1)
        positions = []
        deadline = time.monotonic() + 8
        while time.monotonic() < deadline:
            coords = self.mc.get_coords()
            if isinstance(coords, list) and len(coords) == 6:
                positions.append(coords[:3])
            if self.mc.is_moving() == 0 and len(positions) > 20:
                break
        self.assertGreater(len(positions), 50, "too few samples during the line")
        worst = max(distance_to_segment(p, start[:3], target[:3]) for p in positions)
        # Reported coordinates are the forward kinematics of whole encoder steps (0.088 deg):
        # up to ~0.3 mm of that is the reading, not the arm.
        self.assertLessEqual(worst, 0.6, f"the flange left the straight line by {worst:.2f} mm")
        self.assertLessEqual(math.dist(positions[-1], target[:3]), 0.5, f"ended at {positions[-1]}")
        self.home()
