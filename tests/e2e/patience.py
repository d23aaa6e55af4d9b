"""How long the end-to-end suites wait for the arm, shared by the pymycobot 4.0.7 suite
(robot.py) and the 2.9.8 one (seed_298_suite.py), which cannot import robot.py (it imports
4.0.7's MyCobot280)."""

import time

# Every wait for something the arm does gives up only after PATIENCE times its timeout, the
# time it takes on an idle machine with room. On a busy machine the robot runs late (it stalls
# while other programs have the cores; docs/quickstart.md), and a wait that gives up then
# fails a test of behaviour on the machine's load. A passing wait ends as soon as the arm is
# there: the patience only costs time when a test fails anyway.
PATIENCE = 5


def wait_until(predicate, timeout, interval=0.02):
    """Polls predicate() until it returns a truthy value, for up to `timeout` s on an idle
    machine (PATIENCE times that on a busy one); returns it, or the last value."""
    deadline = time.monotonic() + timeout * PATIENCE
    value = predicate()
    while not value and time.monotonic() < deadline:
        time.sleep(interval)
        value = predicate()
    return value
