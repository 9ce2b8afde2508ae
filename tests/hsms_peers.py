"""What the host link's tests share (tests/host, tests/gui/test_gui_host.py): a free TCP port
on 127.0.0.1, waiting for a condition, and a message of any number and body as a misbehaving
host sends it."""

import socket
import time

__all__ = ["free_port", "wait_for", "Raw"]


def free_port():
    """A TCP port of 127.0.0.1 that nothing listens on now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def wait_for(predicate, timeout_s=5.0):
    """Whether ``predicate()`` came true within ``timeout_s`` seconds (asked every 10 ms)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.01)
    return predicate()


class Raw:
    """A stream function of any number and body, as a misbehaving host would send it."""

    def __init__(self, stream, function, body=b""):
        self.stream, self.function, self.body = stream, function, body
        self.is_reply_required = True

    def encode(self):
        return self.body

    def __repr__(self):
        return f"S{self.stream}F{self.function} W <raw {self.body.hex()}> ."
