"""A Listen-node session of the simulator without sockets (sans-I/O), for the session-level tests of tests/sim:
``S`` connects clients, feeds them frames and returns what each received; time advances on a virtual clock."""
from sim_harness import sct, sta  # noqa: F401  (the frames the session tests send)

from tmsim.protocol import codec
from tmsim.protocol.listen_session import ListenSession

PTP_LONG = 'PTP("JPP",90,0,90,0,90,0,10,200,0,false)'   # 90 deg at 18 deg/s: 5.35 s


class S:
    """A session with connected clients; ``send`` returns the frames each client received."""

    def __init__(self, **kwargs):
        self.events = []
        self.s = ListenSession(log=lambda kind, **f: self.events.append((kind, f)), **kwargs)
        self.t = 0.0

    def connect(self, conn=1, peer="127.0.0.1"):
        self.s.connect(conn, peer)

    def send(self, conn, raw):
        buf = bytearray(raw)
        for item in codec.decode_all(buf):
            self.s.handle(conn, item)
        return self.out(conn)

    def out(self, conn=1):
        queued = self.s.clients[conn].outbox[:]          # (frame, header, data) each; no frame_out event here
        self.s.clients[conn].outbox.clear()
        return [frame.decode("utf-8", "backslashreplace") for frame, _header, _data in queued]

    def advance(self, seconds, dt=0.01):
        end = self.t + seconds
        while self.t < end - 1e-9:
            self.t = min(end, self.t + dt)
            self.s.advance(self.t)
