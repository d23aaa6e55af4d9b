"""The links themselves: the pseudo-terminal survives clients coming and going and line noise;
the TCP server speaks the same protocol to MyCobot280Socket."""

import os
import time
import unittest

import serial
from pymycobot import MyCobot280, MyCobot280Socket

from robot import PATIENCE, PORT, RobotTestCase, arm, wait_until

GET_ANGLES = bytes([0xFE, 0xFE, 0x02, 0x20, 0xFA])


def read_frame(port, timeout=1.0):
    """Reads bytes until one complete FE FE LEN .. frame arrived, for up to `timeout` s
    (PATIENCE times that on a busy machine); returns (junk, frame)."""
    deadline = time.monotonic() + timeout * PATIENCE
    buf = b""
    while time.monotonic() < deadline:
        buf += port.read(port.in_waiting or 1)
        start = buf.find(b"\xfe\xfe")
        if start >= 0 and len(buf) >= start + 3 and len(buf) >= start + 3 + buf[start + 2]:
            end = start + 3 + buf[start + 2]
            return buf[:start], buf[start:end]
    return buf, None


class PtyTest(unittest.TestCase):
    def raw_port(self):
        # Callers hold the shared client's lock while they use it, so no pymycobot request
        # interleaves with theirs.
        return serial.Serial(PORT, 115200, timeout=0.05)

    def test_raw_request_gets_one_reply_and_no_echo(self):
        with arm().lock, self.raw_port() as port:
            port.reset_input_buffer()
            port.write(GET_ANGLES)
            junk, frame = read_frame(port)
            self.assertIsNotNone(frame, f"no reply, got {junk!r}")
            self.assertEqual(junk, b"", "bytes before the reply (an echo?)")
            self.assertNotEqual(frame, GET_ANGLES, "the request was echoed")
            self.assertEqual(frame[3], 0x20)
            self.assertEqual(len(frame), 17, f"reply {frame.hex(' ')}")
            self.assertEqual(frame[-1], 0xFA)
            time.sleep(0.05)
            self.assertEqual(port.read(port.in_waiting), b"", "more than one reply")

    def test_line_noise_and_a_truncated_frame_do_not_block_the_next_request(self):
        with arm().lock, self.raw_port() as port:
            port.reset_input_buffer()
            port.write(bytes([0x00, 0xFF, 0xFA, 0x13, 0x0D, 0x0A, 0xFE, 0xFE, 0x06, 0x22, 0x01]))
            time.sleep(0.01)  # > 2 ms: the half frame is dropped by the gap rule
            port.write(GET_ANGLES)
            _, frame = read_frame(port)
            self.assertIsNotNone(frame, "no reply after line noise")
            self.assertEqual(frame[3], 0x20)

    def test_clients_can_close_and_reopen_the_port(self):
        for _ in range(2):
            with self.raw_port() as port, arm().lock:
                port.reset_input_buffer()
                port.write(GET_ANGLES)
                _, frame = read_frame(port)
                self.assertIsNotNone(frame, "no reply after reopening")
        # A second full pymycobot client, opened after the first closed, works too.
        second = MyCobot280(PORT)
        try:
            self.assertEqual(len(second.get_angles()), 6)
        finally:
            second.close()
        self.assertEqual(len(arm().get_angles()), 6)


@unittest.skipUnless(os.environ.get("MYCOBOT_TCP"), "MYCOBOT_TCP not set")
class TcpTest(RobotTestCase):
    def socket_client(self):
        host, port = os.environ["MYCOBOT_TCP"].rsplit(":", 1)
        return MyCobot280Socket(host, int(port))

    def test_socket_client_reads_and_moves_the_arm(self):
        self.home()
        client = self.socket_client()
        try:
            self.assertEqual(client.get_angles(), [0.0] * 6)
            target = [15, -10, 20, 5, -15, 30]
            self.assertEqual(client.send_angles(target, 100), 1)
            reached = wait_until(
                lambda: self._within(client.get_angles(), target, 0.2) and client.is_moving() == 0, 6.0
            )
            self.assertTrue(reached, f"TCP client sees {client.get_angles()}")
            self.assertAnglesClose(self.mc.get_angles(), target, msg="the serial client sees the same arm")
        finally:
            client.sock.close()
        # A client disconnecting does not stop the robot; the next one is served.
        again = self.socket_client()
        try:
            self.assertEqual(again.is_power_on(), 1)
        finally:
            again.sock.close()
        self.home()


if __name__ == "__main__":
    unittest.main()
