"""Ethernet Slave benchmarks: cost of one data-table frame, stream load, read round trip over loopback.

* Frame cost: building the default data table (48 items) from the robot model and encoding it, per
  format, in-process (what the simulator spends per client-independent stream frame; the frame is
  built once per period and sent to every client).
* Stream load: 32 robots with one client each, data table every 10 ms, served by the CLI process for
  3 s of wall time; the simulator's CPU share and the frames the clients received.
* Read round trip: one client sends a mode-12 read (Joint_Angle, Error_Code, Project_Run) and waits for
  the reply, 2,000 times, against the CLI; median and 99th percentile over loopback.
"""
from __future__ import annotations

import os
import pathlib
import selectors
import socket
import subprocess
import sys
import time

from tmsim.net.server import SimServer
from tmsim.protocol import codec
from tmsim.protocol.svr_session import DEFAULT_STREAM

ROOT = pathlib.Path(__file__).resolve().parents[1]


def frame_cost():
    srv = SimServer(port=0, svr_port=0).start()
    try:
        session = srv.robots[0].svr
        for mode, name in ((1, "binary"), (2, "string"), (3, "JSON")):
            count, start = 0, time.perf_counter()
            while time.perf_counter() - start < 0.5:
                session._content(mode, session.stream_items)
                count += 1
            size = len(session._content(mode, session.stream_items))
            print(f"data table frame ({len(DEFAULT_STREAM)} items, {name}): "
                  f"{(time.perf_counter() - start) / count * 1e6:7.1f} us to build, {size} bytes")
    finally:
        srv.close()


def start_cli(robots, period):
    proc = subprocess.Popen([sys.executable, "-m", "tmsim", "--port", "0",
                             "--robots", str(robots), "--no-control", "--svr-period", str(period)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    ports = []
    for _ in range(robots):
        line = proc.stdout.readline()
        ports.append(int(line.rsplit("127.0.0.1:", 1)[1].split()[0]))
    return proc, ports


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def stream_load(robots=32, period=0.01, seconds=3.0):
    proc, ports = start_cli(robots, period)
    try:
        socks = [socket.create_connection(("127.0.0.1", p)) for p in ports]
        sel = selectors.DefaultSelector()
        for s in socks:
            s.setblocking(False)
            sel.register(s, selectors.EVENT_READ, bytearray())
        time.sleep(0.2)
        cpu0, frames, end = cpu_seconds(proc.pid), 0, time.monotonic() + seconds
        while time.monotonic() < end:
            for key, _ in sel.select(0.05):
                key.data.extend(key.fileobj.recv(1 << 20))
                frames += sum(isinstance(i, codec.Frame) for i in codec.decode_all(key.data, {"TMSVR"}))
        cpu = cpu_seconds(proc.pid) - cpu0
        print(f"stream: {robots} robots x 1 client, every {period * 1000:g} ms: {frames / seconds:7.0f} frames/s "
              f"received (expected {robots / period:.0f}), simulator CPU {cpu / seconds * 100:.0f} % of one core")
        for s in socks:
            s.close()
    finally:
        proc.terminate()
        proc.communicate(timeout=10)


def read_round_trip(count=2000):
    proc, ports = start_cli(1, 0)
    try:
        sock = socket.create_connection(("127.0.0.1", ports[0]))
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        request = codec.encode("TMSVR", "R1,12,Joint_Angle\r\nError_Code\r\nProject_Run")
        times, buf = [], bytearray()
        for _ in range(count):
            start = time.perf_counter()
            sock.sendall(request)
            while True:
                buf += sock.recv(65536)
                items = codec.decode_all(buf, {"TMSVR"})
                if items:
                    break
            times.append(time.perf_counter() - start)
        times.sort()
        print(f"read round trip (mode 12, 3 items, loopback): median {times[len(times) // 2] * 1e3:.2f} ms, "
              f"99th percentile {times[int(len(times) * 0.99)] * 1e3:.2f} ms over {count} requests")
        sock.close()
    finally:
        proc.terminate()
        proc.communicate(timeout=10)


if __name__ == "__main__":
    frame_cost()
    stream_load()
    read_round_trip()
