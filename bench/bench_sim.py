"""Simulator benchmarks: TMSTA ping-pong rate, reply latency with 32 streaming robots, memory, poll() cost.

The simulator runs as its own process (the CLI, real-time clock) so client and server do not share
an interpreter; the in-process figure at the end is the cost of one poll() on the virtual clock.
Targets (issue 5): >= 5,000 round trips/s; worst reply latency <= 5 ms; <= 60 MB RSS with 32 robots.
"""
from __future__ import annotations

import os
import pathlib
import selectors
import socket
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sim import codec  # noqa: E402
from sim.server import SimServer  # noqa: E402


def start_cli(robots):
    proc = subprocess.Popen([sys.executable, str(ROOT / "sim" / "tmflow_listener.py"), "--port", "0",
                             "--robots", str(robots), "--no-control"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    ports = []
    for _ in range(robots):
        line = proc.stdout.readline()
        ports.append(int(line.split("127.0.0.1:")[1].split()[0]))
    return proc, ports


def rss_mb(pid):
    with open(f"/proc/{pid}/status", encoding="ascii") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def bench_ping_pong(port, seconds=3.0):
    """One client, one TMSTA 00 in flight; the reply is compared byte for byte (a lean client, so the
    figure measures the simulator rather than the benchmark's own Python)."""
    sock = socket.create_connection(("127.0.0.1", port))
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    request = codec.encode("TMSTA", "00")
    expected = codec.encode("TMSTA", "00,true,Listen1")
    size, count = len(expected), 0

    def exchange():
        sock.sendall(request)
        reply = sock.recv(4096)
        while len(reply) < size:
            more = sock.recv(4096)
            if not more:
                raise ConnectionError("simulator closed the connection")
            reply += more
        if reply != expected:
            raise AssertionError(f"unexpected reply {reply!r}")

    for _ in range(200):                                   # warm-up
        exchange()
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        exchange()
        count += 1
    elapsed = time.perf_counter() - start
    sock.close()
    return count / elapsed


def bench_streaming(ports, seconds=5.0, look_ahead=3, saturate=False, warm_up=1.0):
    """Every client streams blended Line motions, each followed by QueueTag(n).

    Normal mode keeps ``look_ahead`` motions queued per robot: a new script is sent whenever an
    unsolicited tag push says a motion finished (how a streaming PLC client feeds the robot).
    ``saturate`` sends the next script as soon as the previous reply arrives (server at 100 % CPU).
    Latency = time from writing a script to reading its TMSCT reply; scripts written during the
    first ``warm_up`` seconds (all clients send their first scripts at the same instant) are not counted.
    """
    sel = selectors.DefaultSelector()
    clients = []
    for index, port in enumerate(ports):
        sock = socket.create_connection(("127.0.0.1", port))
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.setblocking(False)
        client = {"sock": sock, "buf": bytearray(), "sent": {}, "n": 0}
        clients.append(client)
        sel.register(sock, selectors.EVENT_READ, client)
    latencies = []

    def send(client):
        n = client["n"]
        client["n"] += 1
        x = 380 + 40 * (n % 2)
        script = f'Line("CAR",{x},-100,350,180,0,90,400,100,50,true)\r\nQueueTag({n % 15 + 1})'
        client["sent"][f"S{n}"] = time.perf_counter()
        client["sock"].sendall(codec.encode("TMSCT", f"S{n},{script}"))

    for client in clients:
        for _ in range(1 if saturate else look_ahead):
            send(client)
    counted_from = time.perf_counter() + warm_up
    end = time.perf_counter() + warm_up + seconds
    while time.perf_counter() < end:
        for key, _ in sel.select(0.05):
            client = key.data
            data = client["sock"].recv(65536)
            if not data:
                raise ConnectionError("simulator closed a streaming connection")
            client["buf"] += data
            for item in codec.decode_all(client["buf"]):
                if not isinstance(item, codec.Frame):
                    continue
                if item.header == "TMSCT":
                    ident = item.data.split(b",", 1)[0].decode()
                    sent = client["sent"].pop(ident)
                    if sent >= counted_from:
                        latencies.append(time.perf_counter() - sent)
                    if saturate:
                        send(client)
                elif item.header == "TMSTA" and item.data.startswith(b"01,") and not saturate:
                    send(client)
    for client in clients:
        client["sock"].close()
    latencies.sort()
    return latencies


def bench_poll_cost(robots=32, iterations=2000):
    srv = SimServer(port=0, robots=robots).start()
    try:
        start = time.perf_counter()
        for i in range(iterations):
            srv.poll(i * 0.001)
        return (time.perf_counter() - start) / iterations
    finally:
        srv.close()


def main():
    proc, ports = start_cli(1)
    try:
        rates = sorted(bench_ping_pong(ports[0], seconds=1.5) for _ in range(3))
    finally:
        proc.terminate()
        proc.communicate(timeout=10)
    print(f"TMSTA 00 round trips, one client: {rates[1]:,.0f} /s median of 3 runs "
          f"(best {rates[2]:,.0f}, worst {rates[0]:,.0f})   (target >= 5,000)")

    proc, ports = start_cli(32)
    try:
        idle_rss = rss_mb(proc.pid)
        latencies = bench_streaming(ports)
        busy_rss = rss_mb(proc.pid)
        saturated = bench_streaming(ports, seconds=3.0, saturate=True)
        peak_rss = rss_mb(proc.pid)
    finally:
        proc.terminate()
        proc.communicate(timeout=10)

    def figures(values):
        return (values[len(values) // 2] * 1000, values[int(len(values) * 0.99)] * 1000, values[-1] * 1000)

    print(f"32 robots streaming blended Line motions (3 queued per robot, next sent on each tag push):")
    print(f"  {len(latencies):,d} scripts in 5 s; reply latency median / p99 / worst: "
          "%.2f / %.2f / %.2f ms   (target worst <= 5 ms)" % figures(latencies))
    print(f"  same clients flooding (next script on each reply, server CPU-bound): {len(saturated) / 3:,.0f} scripts/s,"
          " latency median / p99 / worst %.1f / %.1f / %.1f ms" % figures(saturated))
    print(f"RSS of the simulator with 32 robots: {idle_rss:.1f} MB idle, {busy_rss:.1f} MB after streaming, "
          f"{peak_rss:.1f} MB after flooding   (target <= 60 MB)")
    cost = bench_poll_cost()
    print(f"poll() with 32 idle robots (in-process, virtual clock): {cost * 1e6:.1f} us per call")
    return 0


if __name__ == "__main__":
    sys.exit(main())
