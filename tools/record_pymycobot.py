#!/usr/bin/env python3
"""Record the exact request frames pymycobot's MyCobot280 sends, for every API method.

MyCobot280 runs unchanged; only `serial.Serial` is replaced by a fake port that records what
is written and answers each frame with a plausible reply carrying the request's CMD (so no
call waits for pymycobot's 0.5 s timeout or resends). Calls use representative and edge
arguments: limits, negative values, values whose bytes are 0xFE / 0xFA.

Output (default protocol-core/tests/data/pymycobot_requests.txt): one line per frame,
`<hex bytes> | <call>`. Writes that are not frames (set_ssid_pwd sends the SSID as raw text)
are recorded as `# raw <hex> | <call>`. Run with the project's venv:

    .venv/bin/python tools/record_pymycobot.py [output]
"""
import os
import sys
import time

import serial

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, "..", "protocol-core", "tests", "data", "pymycobot_requests.txt")


class FakeSerial:
    """Just enough of serial.Serial for MyCobot280: records writes, answers each frame."""

    def __init__(self, *args, **kwargs):
        self.port = None
        self.baudrate = 115200
        self.timeout = 0.1
        self.rts = False
        self.rx = bytearray()
        self.writes = []

    def open(self):
        pass

    def close(self):
        pass

    def isOpen(self):
        return True

    is_open = property(lambda self: True)

    def reset_input_buffer(self):
        self.rx.clear()

    def inWaiting(self):
        return len(self.rx)

    in_waiting = property(lambda self: len(self.rx))

    def write(self, data):
        data = bytes(data)
        self.writes.append(data)
        if len(data) >= 5 and data[0] == 0xFE and data[1] == 0xFE:
            self.rx += reply_for(data[3])
        return len(data)

    def read(self, n=1):
        out = bytes(self.rx[:n])
        del self.rx[:n]
        return out


def reply_for(cmd):
    """A plausible reply: the status byte 01 for most, 12 bytes for list getters, pin+level
    for 0x62/0xA1, joint+limit for 0x4A/0x4B, so pymycobot's callers (sync_send_angles...)
    finish at once."""
    if cmd == 0xB1:
        return b"ssid: mynet password: secret"  # pymycobot reads this one as text
    data = [1]
    if cmd in (0x20, 0x23, 0x3D, 0x82, 0x84, 0xE1, 0xE2, 0xF6, 0xF7, 0x8D):
        data = [0] * 12
    elif cmd == 0xD5:
        data = [0] * 24
    elif cmd in (0x62, 0xA1, 0x50):
        data = [1, 1]
    elif cmd in (0x4A, 0x4B):
        data = [1, 0, 10]
    elif cmd == 0x15:
        data = [0] * 7
    elif cmd in (0xE3, 0xE4, 0xE5):
        data = [0] * 6
    return bytes([0xFE, 0xFE, len(data) + 2, cmd] + data + [0xFA])


A_MIN = [-168, -140, -150, -150, -155, -180]
A_MAX = [168, 140, 150, 150, 160, 180]
C_EDGE = [-281.45, 281.45, -70, -180, 180, -0.02]  # -0.02 deg -> 0xFFFE
C_HOME = [156.5, -63.4, 304.2, -175.6, -0.6, -89.9]  # -0.6 mm... -> 0xFFFA in rx? see file
FE_FA = [-0.06, -0.02, 2.50, -1.30, 0, 0]  # -6 (FF FA), -2 (FF FE), 250 (00 FA), -130 (FF 7E)

CALLS = [
    # status and system
    ("get_system_version", ()), ("get_modify_version", ()), ("power_on", ()), ("power_off", ()),
    ("is_power_on", ()), ("release_all_servos", ()), ("release_all_servos", (1,)),
    ("release_all_servos", (0,)), ("is_controller_connected", ()), ("read_next_error", ()),
    ("set_fresh_mode", (0,)), ("set_fresh_mode", (1,)), ("get_fresh_mode", ()),
    ("set_free_mode", (0,)), ("set_free_mode", (1,)), ("is_free_mode", ()),
    ("set_vision_mode", (0,)), ("set_vision_mode", (1,)), ("get_reboot_count", ()),
    ("clear_queue", ()), ("check_async_or_sync", ()), ("get_error_information", ()),
    ("clear_error_information", ()),
    # motion
    ("get_angles", ()), ("get_radians", ()), ("send_angle", (1, -168, 1)),
    ("send_angle", (6, 180, 100)), ("send_angle", (2, -0.02, 50)), ("send_angle", (5, 2.5, 50)),
    ("send_angles", ([0, 0, 0, 0, 0, 0], 50)), ("send_angles", (A_MIN, 100)),
    ("send_angles", (A_MAX, 1)), ("send_angles", (FE_FA, 50)),
    ("send_radians", ([0.5, -0.5, 1.0, -1.0, 2.0, -3.14], 50)),
    ("get_coords", ()), ("send_coord", (1, -0.6, 50)), ("send_coord", (2, 25, 1)),
    ("send_coord", (3, 412.67, 10)), ("send_coord", (4, -180, 100)), ("send_coord", (6, -0.02, 30)),
    ("send_coords", (C_HOME, 50)), ("send_coords", (C_EDGE, 100, 0)), ("send_coords", (C_HOME, 1, 1)),
    ("angles_to_coords", (FE_FA,)), ("angles_to_coords", (A_MIN,)),
    ("solve_inv_kinematics", (C_HOME, FE_FA)),
    ("pause", ()), ("is_paused", ()), ("resume", ()), ("stop", ()),
    ("is_in_position", (A_MAX, 0)), ("is_in_position", (C_EDGE, 1)), ("is_moving", ()),
    ("get_angles_coords", ()), ("get_angles_plan", ()), ("get_coords_plan", ()),
    ("move_round", ()), ("set_four_pieces_zero", ()), ("go_home", ()),
    ("sync_send_angles", (FE_FA, 40)), ("sync_send_coords", (C_HOME, 40, 1)),
    # jog
    ("jog_angle", (1, 0, 50)), ("jog_angle", (6, 1, 100)), ("jog_rpy", (1, 1, 50)),
    ("jog_rpy", (3, 0, 10)), ("jog_coord", (1, 0, 50)), ("jog_coord", (6, 1, 1)),
    ("jog_increment", (2, 5, 20)), ("jog_increment_angle", (1, -10.5, 50)),
    ("jog_increment_angle", (6, -0.06, 100)), ("jog_increment_coord", (1, -0.6, 50)),
    ("jog_increment_coord", (4, 15, 20)),
    # encoders and limits
    ("set_encoder", (1, 2048, 50)), ("set_encoder", (7, 0, 1)), ("set_encoder", (6, 4096, 100)),
    ("set_encoder", (3, 250, 20)), ("get_encoder", (1,)), ("get_encoder", (7,)),
    ("set_encoders", ([2048] * 6, 50)), ("set_encoders", ([0, 4096, 250, 1, 4094, 2048], 100)),
    ("get_encoders", ()), ("set_encoders_drag", ([2048, 0, 4096, 250, 254, 2000], [0, 6000, 250, 1, 100, 3000])),
    ("get_joint_min_angle", (1,)), ("get_joint_max_angle", (6,)), ("set_joint_min", (1, -168)),
    ("set_joint_max", (2, 140)), ("set_joint_min", (6, -180)), ("set_joint_max", (5, 160)),
    # servos
    ("is_servo_enable", (1,)), ("is_servo_enable", (6,)), ("is_all_servo_enable", ()),
    ("set_servo_data", (1, 21, 10)), ("set_servo_data", (7, 42, 2048, 1)),
    ("set_servo_data", (2, 254, 250)), ("get_servo_data", (1, 56)), ("get_servo_data", (1, 56, 1)),
    ("get_servo_data", (2, 21, 0)), ("is_torque_gripper", ()), ("set_servo_calibration", (1,)),
    ("set_servo_calibration", (6,)), ("joint_brake", (2,)), ("release_servo", (1,)),
    ("release_servo", (1, 1)), ("release_servo", (6, 0)), ("focus_servo", (1,)),
    ("focus_all_servos", ()), ("get_servo_speeds", ()), ("get_servo_voltages", ()),
    ("get_servo_status", ()), ("get_servo_temps", ()), ("backup_servo_params", (254,)),
    ("backup_servo_params", (1,)), ("restore_servo_params", (254,)), ("restore_servo_params", (6,)),
    # Atom IO, LED, gripper
    ("set_pin_mode", (19, 1)), ("set_pin_mode", (39, 0)), ("set_pin_mode", (22, 2)),
    ("set_digital_output", (23, 1)), ("set_digital_output", (33, 0)), ("get_digital_input", (39,)),
    ("get_digital_input", (19,)), ("set_pwm_output", (22, 1000, 128)), ("set_pwm_output", (33, 250, 255)),
    ("get_gripper_value", ()), ("get_gripper_value", (1,)), ("set_gripper_state", (0, 50)),
    ("set_gripper_state", (1, 100, 1)), ("set_gripper_state", (254, 0, 3, 1)),
    ("set_gripper_value", (100, 50)), ("set_gripper_value", (50, 80, 4)),
    ("set_gripper_value", (0, 0, 1, 0)), ("gripper_stop", ()), ("set_gripper_calibration", ()),
    ("is_gripper_moving", ()), ("set_color", (255, 0, 254)), ("set_color", (0, 250, 0)),
    ("set_HTS_gripper_torque", (150,)), ("set_HTS_gripper_torque", (980,)),
    ("get_HTS_gripper_torque", ()), ("get_gripper_protect_current", ()), ("init_gripper", ()),
    ("set_gripper_protect_current", (1,)), ("set_gripper_protect_current", (500,)),
    # coordinate frames
    ("set_tool_reference", ([0, 0, 100.5, 0, 0, -0.02],)), ("get_tool_reference", ()),
    ("set_world_reference", (C_EDGE,)), ("get_world_reference", ()),
    ("set_reference_frame", (0,)), ("set_reference_frame", (1,)), ("get_reference_frame", ()),
    ("set_movement_type", (0,)), ("set_movement_type", (1,)), ("get_movement_type", ()),
    ("set_end_type", (0,)), ("set_end_type", (1,)), ("get_end_type", ()),
    # Basic
    ("set_basic_output", (2, 1)), ("set_basic_output", (5, 0)), ("get_basic_input", (35,)),
    ("get_basic_input", (36,)), ("get_tof_distance", ()), ("get_basic_version", ()),
    ("set_transponder_mode", (0,)), ("set_transponder_mode", (1,)), ("get_transponder_mode", ()),
    ("set_ssid_pwd", ("mynet", "secret")), ("get_ssid_pwd", ()), ("set_server_port", (5001,)),
    # drag teaching
    ("drag_start_record", ()), ("drag_end_record", ()), ("drag_get_record_data", ()),
    ("drag_get_record_len", ()), ("drag_clear_record_data", ()),
]


def call_text(name, args):
    return "{}({})".format(name, ", ".join(repr(a) for a in args))


def main():
    out_path = sys.argv[1] if len(sys.argv) > 1 else DEFAULT_OUT
    serial.Serial = FakeSerial
    real_sleep = time.sleep
    time.sleep = lambda s: None  # MyCobot280 sleeps 1.5 s on open; sync_* poll with sleeps
    try:
        from pymycobot import MyCobot280, __version__

        bot = MyCobot280("/dev/fake")
    finally:
        pass
    port = bot._serial_port
    lines = ["# pymycobot {} MyCobot280 requests, recorded by tools/record_pymycobot.py".format(__version__),
             "# <frame hex> | <call>"]
    failures = []
    for name, args in CALLS:
        port.writes.clear()
        try:
            getattr(bot, name)(*args)
        except Exception as e:  # noqa: BLE001 - record and report every failure
            failures.append("{}: {!r}".format(call_text(name, args), e))
            continue
        seen = set()
        for w in port.writes:
            hx = " ".join("{:02X}".format(b) for b in w)
            if hx in seen:
                continue  # sync_* poll the same query repeatedly
            seen.add(hx)
            is_frame = len(w) >= 5 and w[0] == 0xFE and w[1] == 0xFE and w[2] == len(w) - 3 and w[-1] == 0xFA
            prefix = "" if is_frame else "# raw "
            lines.append("{}{} | {}".format(prefix, hx, call_text(name, args)))
    time.sleep = real_sleep
    with open(out_path, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("wrote {} lines to {}".format(len(lines) - 2, out_path))
    if failures:
        print("calls pymycobot refused:\n  " + "\n  ".join(failures))
        sys.exit(1)


if __name__ == "__main__":
    main()
