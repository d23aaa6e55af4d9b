"""The Basic's Wi-Fi settings through pymycobot 4.0.7, as the vendor documents them (over the
USB serial) and over TCP (MyCobot280Socket has the same calls): set_ssid_pwd / get_ssid_pwd /
set_server_port round-trip, and bad input is refused with 00 and changes nothing. The USB client
and TCP clients at the same time. (Keeping the settings across a restart of the virtual robot is
tests/pymycobot_wifi.rs: it restarts the binary.)"""

import os
import socket
import threading
import time
import unittest

from pymycobot import MyCobot280Socket

from robot import RobotTestCase, frame, raw_client, tcp_address

ACK = frame(0xB0, 1)
NAK = frame(0xB0, 0)


def read_for(sock, seconds):
    got = b""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            got += sock.recv(1024)
        except socket.timeout:
            pass
    return got


def raw_set_text(sock, text):
    """set_ssid_pwd's two writes on a raw socket; returns what came back to each, within
    pymycobot's 50 ms reads."""
    sock.sendall(frame(0xB0))
    first = read_for(sock, 0.05)
    time.sleep(0.02)
    sock.sendall(text)
    return first, read_for(sock, 0.05)


def ssid_pwd(mc):
    """get_ssid_pwd, asked once more if pymycobot gave up before the answer came (a busy machine
    holds it up past pymycobot's read timeout, and pymycobot then fails to parse what it has)."""
    try:
        return mc.get_ssid_pwd()
    except (UnicodeDecodeError, ValueError, IndexError):
        time.sleep(0.1)
        return mc.get_ssid_pwd()


class WifiSettingsTest(RobotTestCase):
    def tearDown(self):
        # The suite's robot keeps its flash in a scratch file; leave the defaults' port.
        self.mc.set_server_port(9000)

    def test_set_and_get_over_the_usb_serial(self):
        self.assertEqual(self.mc.set_ssid_pwd("robots", "12345678"), 1)
        self.assertEqual(ssid_pwd(self.mc), ("robots", "12345678"))
        self.assertEqual(self.mc.set_server_port(9001), 1)
        # A get straight after a set: the set's answer came in time, nothing is left over.
        self.assertEqual(self.mc.set_ssid_pwd("lab-2", "abcdefgh"), 1)
        self.assertEqual(ssid_pwd(self.mc), ("lab-2", "abcdefgh"))
        self.assertEqual(self.mc.get_basic_version() > 0, True)

    @unittest.skipUnless(os.environ.get("MYCOBOT_TCP"), "MYCOBOT_TCP not set")
    def test_set_and_get_over_tcp_while_the_usb_client_works(self):
        client = MyCobot280Socket(*tcp_address())
        stop = threading.Event()
        wrong = []

        def usb_client():
            while not stop.is_set():
                angles = self.mc.get_angles()
                if not isinstance(angles, list) or len(angles) != 6:
                    wrong.append(angles)

        usb = threading.Thread(target=usb_client)
        usb.start()
        try:
            for i in range(5):
                ssid = f"net-{i}"
                self.assertEqual(client.set_ssid_pwd(ssid, "12345678"), 1)
                self.assertEqual(client.get_ssid_pwd(), (ssid, "12345678"))
            self.assertEqual(client.set_server_port(9002), 1)
            self.assertEqual(client.get_basic_version() > 0, True)
        finally:
            stop.set()
            usb.join()
            client.sock.close()
        self.assertEqual(wrong, [], "the USB client's answers while TCP set Wi-Fi")
        self.assertEqual(ssid_pwd(self.mc), ("net-4", "12345678"))

    @unittest.skipUnless(os.environ.get("MYCOBOT_TCP"), "MYCOBOT_TCP not set")
    def test_bad_input_is_refused_with_00_and_changes_nothing(self):
        self.assertEqual(self.mc.set_ssid_pwd("keep", "12345678"), 1)
        sock = raw_client(timeout=0.5)
        try:
            for text in [
                b"'" + b"s" * 33 + b"'(12345678)",  # SSID over 32 bytes
                b"'keep'(" + b"p" * 64 + b")",  # 64 characters, not a hexadecimal key
                b"'keep'(" + b"p" * 65 + b")",  # password over 64 bytes
                b"''(12345678)",  # empty SSID
                b"'keep'(short)",  # no WPA passphrase
                b"'keep' (12345678)",  # not pymycobot's layout
            ]:
                first, second = raw_set_text(sock, text)
                self.assertEqual((first, second), (ACK, NAK), text)
            # Bytes that cannot begin the text are no text: garbage for the framer, unanswered.
            self.assertEqual(raw_set_text(sock, b"keep 12345678"), (ACK, b""))
            sock.sendall(frame(0xB2, 0, 0))
            self.assertEqual(read_for(sock, 0.1), frame(0xB2, 0), "port 0")
        finally:
            sock.close()
        # pymycobot returns 1 from set_ssid_pwd whatever the Basic says; the settings tell.
        self.assertEqual(self.mc.set_ssid_pwd("x" * 33, "12345678"), 1)
        self.assertEqual(self.mc.set_server_port(0), 0)
        self.assertEqual(ssid_pwd(self.mc), ("keep", "12345678"))


if __name__ == "__main__":
    unittest.main()
