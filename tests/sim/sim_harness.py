"""Test helpers (imported by tests/sim/*): a SimServer on loopback driven by poll() on a virtual clock."""
import select
import socket

from tmsim.net.server import SimServer
from tmsim.protocol import codec


class Peer:
    """A raw TCP client of one simulated robot; collects decoded frames."""

    def __init__(self, port, headers=codec.HEADERS):
        self.headers = headers          # the Ethernet Slave's peers decode {"TMSVR", "CPERR"}
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        self.sock.setblocking(False)
        self.rbuf = bytearray()
        self.frames = []
        self.closed = False
        self.raw_reads = []

    def send(self, data):
        self.sock.setblocking(True)
        self.sock.sendall(data)
        self.sock.setblocking(False)

    def pump(self):
        while not self.closed:
            ready, _, _ = select.select([self.sock], [], [], 0)
            if not ready:
                return
            try:
                data = self.sock.recv(65536)
            except BlockingIOError:
                return
            except ConnectionError:
                data = b""
            if not data:
                self.closed = True
                return
            self.raw_reads.append(data)
            self.rbuf += data
            self.frames.extend(item for item in codec.decode_all(self.rbuf, self.headers)
                               if isinstance(item, codec.Frame))

    def texts(self):
        return [(f.header, f.data.decode("utf-8", "replace")) for f in self.frames]

    def close(self):
        self.sock.close()


class Harness:
    def __init__(self, **kwargs):
        self.srv = SimServer(port=0, **kwargs)
        self.srv.start()
        self.t = 0.0
        self.peers = []

    @property
    def robot(self):
        return self.srv.robots[0]

    def connect(self, robot=0):
        peer = Peer(self.srv.ports[robot])
        self.peers.append(peer)
        self.step()
        return peer

    def connect_svr(self, robot=0):
        """A client of the robot's Ethernet Slave (the Harness needs svr_port=0)."""
        peer = Peer(self.srv.robots[robot].svr_port, headers={"TMSVR", "CPERR"})
        self.peers.append(peer)
        self.step()
        return peer

    def step(self, dt=0.001):
        self.t += dt
        self.srv.poll(self.t)
        for peer in self.peers:
            peer.pump()

    def run(self, seconds, dt=0.01):
        end = self.t + seconds
        while self.t < end - 1e-9:
            self.step(min(dt, end - self.t))

    def until(self, predicate, timeout=30.0, dt=0.005, max_steps=200_000):
        """Step virtual time until predicate() holds; False after ``timeout`` virtual seconds."""
        end = self.t + timeout
        steps = 0
        while not predicate():
            if self.t >= end or steps >= max_steps:
                return False
            # wait (bounded) for loopback delivery instead of sleeping
            select.select([p.sock for p in self.peers if not p.closed] or [], [], [], 0.0005)
            self.step(dt)
            steps += 1
        return True

    def request(self, peer, frame, count=1, timeout=30.0, dt=0.005):
        """Send a frame and step until ``count`` more frames arrived; returns them as (header, text)."""
        start = len(peer.frames)
        peer.send(frame)
        assert self.until(lambda: len(peer.frames) >= start + count, timeout, dt), \
            f"no reply within {timeout} s virtual; got {peer.texts()[start:]}"
        return peer.texts()[start:]

    def close(self):
        for peer in self.peers:
            peer.close()
        self.srv.close()


def sct(ident, script):
    return codec.encode("TMSCT", f"{ident},{script}")


def sta(data):
    return codec.encode("TMSTA", data)
