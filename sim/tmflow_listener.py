"""Command line of the TMflow Listen Node simulator.

    python sim/tmflow_listener.py [--host 127.0.0.1] [--port 5890] [--robots N]
                                  [--realtime | --speedup K] [--log FILE.jsonl]
                                  [--no-auto-enter] [--send-message Listen1]
                                  [--control-port 5889 | --no-control] [--tag-history 4]
                                  [--data-timeout S] [--connection-timeout S]
"""
from __future__ import annotations

import argparse
import gc
import os
import signal
import sys
import threading

if __package__ in (None, ""):
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from sim.server import SimServer  # noqa: E402


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="tmflow_listener.py",
        description="TMflow Listen Node simulator (TM5-700 model). Serves the external-script protocol "
                    "(TMSCT/TMSTA/CPERR) on one TCP port per robot.")
    parser.add_argument("--host", default="127.0.0.1", metavar="ADDRESS", help="address to listen on (default 127.0.0.1)")
    parser.add_argument("--port", type=int, default=5890, metavar="PORT",
                        help="port of robot 1; further robots use the next ports (default 5890, 0 = any free port)")
    parser.add_argument("--robots", type=int, default=1, metavar="N", help="number of independent robots (1..512, default 1)")
    timing = parser.add_mutually_exclusive_group()
    timing.add_argument("--realtime", action="store_true", help="motions take their real duration (default)")
    timing.add_argument("--speedup", type=float, default=1.0, metavar="K",
                        help="run the robot clock K times faster than the wall clock")
    parser.add_argument("--log", metavar="FILE.jsonl", help="append every event as one JSON line to FILE")
    parser.add_argument("--no-auto-enter", action="store_true",
                        help="start with the flow outside the Listen node (enter it via the control channel)")
    parser.add_argument("--send-message", default="Listen1", metavar="TEXT", help="the node's Send Message (default Listen1)")
    parser.add_argument("--control-port", type=int, default=5889, metavar="PORT",
                        help="port of the local JSON control channel (default 5889, 0 = any free port)")
    parser.add_argument("--no-control", action="store_true", help="do not open the control channel")
    parser.add_argument("--data-timeout", type=float, default=0.0, metavar="S",
                        help="leave the node via Fail after S seconds without a packet (0 = none, default)")
    parser.add_argument("--connection-timeout", type=float, default=0.0, metavar="S",
                        help="leave the node via Fail when no client connected within S seconds (0 = none)")
    parser.add_argument("--tag-history", type=int, default=4, metavar="N",
                        help="number of reached queue tags the robot remembers (default 4)")
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    problems = []
    if not 1 <= args.robots <= 512:
        problems.append(f"--robots must be between 1 and 512 (got {args.robots})")
    if not 0 <= args.port <= 65535 or (args.port and args.port + args.robots - 1 > 65535):
        problems.append(f"--port {args.port} with {args.robots} robot(s) leaves the port range 1..65535")
    if args.speedup <= 0:
        problems.append(f"--speedup must be positive (got {args.speedup:g})")
    if not 0 <= args.control_port <= 65535:
        problems.append(f"--control-port must be 0..65535 (got {args.control_port})")
    if args.tag_history < 1:
        problems.append(f"--tag-history must be at least 1 (got {args.tag_history})")
    if problems:
        for problem in problems:
            print(f"tmflow_listener: error: {problem}", file=sys.stderr)
        return 2
    try:
        server = SimServer(host=args.host, port=args.port, robots=args.robots, speedup=args.speedup,
                           auto_enter=not args.no_auto_enter, send_message=args.send_message,
                           log_path=args.log, tag_history=args.tag_history,
                           control_port=None if args.no_control else args.control_port,
                           data_timeout=args.data_timeout if args.data_timeout > 0 else None,
                           connection_timeout=args.connection_timeout if args.connection_timeout > 0 else None,
                           manage_gc=True)
        server.start()
    except OSError as exc:
        print(f"tmflow_listener: error: {exc.strerror or exc}", file=sys.stderr)
        return 1
    for robot in server.robots:
        node = "in Listen node" if robot.session.state == "in_node" else "project running, not in Listen node"
        print(f"robot {robot.index + 1}: TM5-700 listening on {args.host}:{robot.port} ({node})", flush=True)
    if server.control is not None:
        print(f"control channel: {args.host}:{server.control.port} (JSON lines)", flush=True)
    if args.speedup != 1.0:
        print(f"robot clock runs {args.speedup:g} x faster than real time", flush=True)
    print("Press Ctrl-C to stop.", flush=True)
    gc.disable()     # the server collects between bursts of requests (SimServer(manage_gc=True))
    gc.freeze()      # what start-up built lives for good: keep it out of every later collection
    done = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: done.set())
    try:
        server.serve_forever(done)          # the main thread serves: fastest replies
    except KeyboardInterrupt:
        pass
    server.close()
    print("simulator stopped", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
