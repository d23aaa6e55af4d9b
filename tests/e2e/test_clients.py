"""Several clients on the arm at once: the serial client on the pseudo-terminal and
MyCobot280Socket clients over TCP (each TCP client is a host link of its own on the Basic), one
more client sending garbage. Each gets exactly its own answers; clients beyond the Basic's limit
are turned away; transparent mode belongs to the client that switched it on."""

import os
import random
import socket
import threading
import time
import unittest

from pymycobot import MyCobot280Socket

from robot import RobotTestCase, raw_client, tcp_address

# Network clients the Basic serves at once: firmware_basic::MAX_HOST_LINKS (8) minus the USB link.
MAX_NETWORK_CLIENTS = 7
# Requests each client sends in the crowd test (the tester saw about 1 reply in 300 cross).
REQUESTS = 500
# A pose with a different encoder on each of joints 1..4.
POSE = [20, -40, 60, -80, 30, 0]


def frame(cmd, *data):
    return bytes([0xFE, 0xFE, len(data) + 2, cmd, *data, 0xFA])


def read_frame(sock):
    """One reply frame (a reply arrives in one piece), or b"" if none came in time."""
    try:
        return sock.recv(1024)
    except socket.timeout:
        return b""


def read_for(sock, seconds):
    """Everything that arrives within `seconds`."""
    got = b""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        got += read_frame(sock)
    return got


def socket_clients(n):
    """n MyCobot280Socket clients, opened in parallel (each waits 1.5 s after connecting)."""
    clients = [None] * n
    host, port = tcp_address()

    def open_one(i):
        clients[i] = MyCobot280Socket(host, port)

    threads = [threading.Thread(target=open_one, args=(i,)) for i in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return clients


def garbage(rng):
    """Noise that never forms a frame (no FA), half the time ending in an unfinished frame."""
    noise = bytes(rng.randrange(0xFA) for _ in range(rng.randrange(1, 24)))
    return noise + (bytes([0xFE, 0xFE, rng.randrange(9, 64)]) if rng.random() < 0.5 else b"")


@unittest.skipUnless(os.environ.get("MYCOBOT_TCP"), "MYCOBOT_TCP not set")
class ClientsTest(RobotTestCase):
    def test_four_clients_and_a_garbage_sender_each_read_their_own_joint(self):
        self.move_to_angles(POSE)
        expected = {joint: self.mc.get_encoder(joint) for joint in range(1, 5)}
        self.assertEqual(len(set(expected.values())), 4, f"joints read alike: {expected}")

        sockets = socket_clients(3)
        clients = [self.mc] + sockets
        wrong = {joint: [] for joint in expected}
        done = threading.Event()

        def ask(client, joint):
            for _ in range(REQUESTS):
                value = client.get_encoder(joint)
                if value != expected[joint]:
                    wrong[joint].append(value)

        noise = raw_client(timeout=0.01)
        garbage_received = []

        def send_garbage():
            rng = random.Random(11)
            while not done.is_set():
                noise.sendall(garbage(rng))
                try:
                    garbage_received.append(noise.recv(1024))
                except socket.timeout:
                    pass

        askers = [threading.Thread(target=ask, args=(c, j)) for c, j in zip(clients, expected)]
        pest = threading.Thread(target=send_garbage)
        pest.start()
        started = time.monotonic()
        for t in askers:
            t.start()
        for t in askers:
            t.join()
        done.set()
        pest.join()
        elapsed = time.monotonic() - started
        noise.close()
        for client in sockets:
            client.sock.close()

        for joint, values in wrong.items():
            self.assertEqual(values, [], f"client of joint {joint}: {len(values)} of {REQUESTS} wrong")
        self.assertEqual(b"".join(garbage_received), b"", "the garbage sender got someone's reply")
        print(f"\n  4 clients x {REQUESTS} get_encoder + a garbage sender: 0 wrong, {elapsed:.1f} s")
        self.home()

    def test_a_client_beyond_the_limit_is_turned_away_and_the_next_one_served(self):
        crowd = []
        try:
            for _ in range(MAX_NETWORK_CLIENTS):
                sock = raw_client()
                sock.sendall(frame(0xC1))
                self.assertEqual(read_frame(sock)[3:4], b"\xc1", "a client within the limit")
                crowd.append(sock)
            refused = socket_clients(1)[0]
            with self.assertRaises((BrokenPipeError, ConnectionResetError)):
                refused.get_basic_version()
            refused.sock.close()
            crowd.pop().close()
            time.sleep(0.05)
            newcomer = socket_clients(1)[0]
            try:
                self.assertEqual(newcomer.is_power_on(), 1)
            finally:
                newcomer.sock.close()
        finally:
            for sock in crowd:
                sock.close()

    def test_transparent_mode_belongs_to_the_client_that_switched_it_on(self):
        owner = raw_client()
        other = socket_clients(1)[0]
        try:
            owner.sendall(frame(0xC2, 1))
            # The answer, then the bus's raw bytes (the Atom polling its servos).
            self.assertTrue(read_frame(owner).startswith(frame(0xC2, 1)))
            # The owner talks to servo 3 directly: READ its ID register.
            ping = bytes([0xFF, 0xFF, 0x03, 0x04, 0x02, 0x05, 0x01])
            ping += bytes([~sum(ping[2:]) & 0xFF])
            servo_answer = b"\xff\xff\x03\x03\x00\x03"
            answer = b""
            for _ in range(5):  # the Atom shares the wire: a try may collide
                owner.sendall(ping)
                answer = read_for(owner, 0.1)
                if servo_answer in answer:
                    break
            self.assertIn(servo_answer, answer, "servo 3 answered through the Basic")
            # The other client: the Basic's own commands still answered, the Atom not reached
            # (pymycobot gives up with -1), the mode not its to change, and no raw bytes.
            self.assertGreater(other.get_basic_version(), 0)
            self.assertEqual(other.is_power_on(), -1)
            other.sock.sendall(frame(0xC2, 0))
            self.assertEqual(read_frame(other.sock), frame(0xC2, 0))
            # Back to framed mode: everyone served again.
            owner.sendall(frame(0xC2, 0))
            self.assertTrue(read_for(owner, 0.1).endswith(frame(0xC2, 1)), "the owner's way back")
            self.assertEqual(other.is_power_on(), 1)
            self.assertEqual(self.mc.is_power_on(), 1)
        finally:
            owner.close()
            other.sock.close()
        self.home()


if __name__ == "__main__":
    unittest.main()
