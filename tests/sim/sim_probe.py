"""A raw JSON-lines client of the simulator's control channel, for the probes that send it hostile lines."""
import json
import select
import socket


class ControlClient:
    """One control-channel connection kept open across requests (the probes send raw lines)."""

    def __init__(self, port, timeout=5.0):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        self.buf = b""

    def send_line(self, line: bytes):
        self.sock.sendall(line + b"\n")

    def answer(self) -> dict:
        while b"\n" not in self.buf:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise ConnectionError("the simulator closed the control connection")
            self.buf += chunk
        line, _, self.buf = self.buf.partition(b"\n")
        return json.loads(line)

    def answer_ready(self) -> bool:
        """Whether a whole answer has arrived: reads what is there, never waits (for a test that polls the
        simulator in its own thread, where a blocking read would wait for a poll that never comes)."""
        while b"\n" not in self.buf:
            if not select.select([self.sock], [], [], 0)[0]:
                return False
            chunk = self.sock.recv(65536)
            if not chunk:
                raise ConnectionError("the simulator closed the control connection")
            self.buf += chunk
        return True

    def ask(self, payload) -> dict:
        self.send_line(payload if isinstance(payload, bytes) else json.dumps(payload).encode())
        return self.answer()

    def close(self):
        self.sock.close()
