"""Command line of the TMflow Listen Node simulator.

    tmflow-sim [--host 127.0.0.1] [--port 5890] [--robots N]
                      [--realtime | --speedup K] [--log FILE.jsonl]
                      [--no-auto-enter] [--send-message Listen1]
                      [--control-port 5889 | --no-control] [--control-host 127.0.0.1]
                      [--tmflow 1.8|2.24] [--tag-history 4] [--stop-tags forget|reached]
                      [--data-timeout S] [--connection-timeout S]
                      [--svr-port PORT | --no-svr] [--svr-period S]
                      [--svr-format binary|string|json] [--svr-items A,B,...]
                      [--svr-var NAME:TYPE[:ACCESS][=VALUE] ...]
                      [--vision-job NAME=POSE;POSE...[@S][!fail] ...]

Also `python3 -m tmsim` and, from a checkout, `python3 sim/tmflow_listener.py` (the launcher kept for existing
users). Every number is range-checked before anything starts; a bad one is one line on stderr, exit code 2.
"""
from __future__ import annotations

import argparse
import gc
import math
import signal
import sys
import threading

from tmsim.limits import NODE_TIMEOUT_MAX_S, SPEEDUP_MAX
from tmsim.net.control import default_port, robot_numbering
from tmsim.net.server import SimServer
from tmsim.protocol.listen_session import IN_NODE
from tmsim.protocol.svr_session import DEFAULT_STREAM
from tmsim.protocol.svr_table import ITEMS, SvrValueError, parse_variable
from tmsim.robot.camera import Camera, parse_option
from tmsim.tmscript.profiles import STOP_TAGS, VERSIONS, Profile

SVR_FORMATS = {"binary": 1, "string": 2, "json": 3}


def bind_address(text: str) -> str:
    """An address to listen on (``--host``, ``--control-host``). An empty one (a script's unset variable) is a usage
    error: the socket would take every network interface while the start-up lines said otherwise."""
    address = text.strip()
    if not address:
        raise argparse.ArgumentTypeError("an address is needed: 127.0.0.1 for this computer only, 0.0.0.0 for "
                                         "every interface")
    return address


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="tmflow-sim",
        description="TMflow Listen Node simulator (TM5-700 model). Serves the external-script protocol "
                    "(TMSCT/TMSTA/CPERR) on one TCP port per robot.")
    parser.add_argument("--host", type=bind_address, default="127.0.0.1", metavar="ADDRESS",
                        help="address to listen on (default 127.0.0.1; 0.0.0.0: every interface)")
    parser.add_argument("--port", type=int, default=5890, metavar="PORT",
                        help="port of robot 1; further robots use the next ports (default 5890, 0 = any free port)")
    parser.add_argument("--robots", type=int, default=1, metavar="N",
                        help="number of independent robots (1..512, default 1)")
    timing = parser.add_mutually_exclusive_group()
    timing.add_argument("--realtime", action="store_true", help="motions take their real duration (default)")
    timing.add_argument("--speedup", type=float, default=1.0, metavar="K",
                        help="run the robot clock K times faster than the wall clock")
    parser.add_argument("--log", metavar="FILE.jsonl",
                        help="append every event as one JSON line to FILE (renamed to FILE.1 at 64 MiB)")
    parser.add_argument("--no-auto-enter", action="store_true",
                        help="start with the flow outside the Listen node (enter it via the control channel)")
    parser.add_argument("--send-message", default="Listen1", metavar="TEXT",
                        help="the node's Send Message (default Listen1)")
    parser.add_argument("--control-port", type=int, default=None, metavar="PORT",
                        help="port of the local JSON control channel (default: the port before robot 1's, 5889 "
                             "for 5890, or any free port when that one is taken; 0 = any free port)")
    parser.add_argument("--no-control", action="store_true", help="do not open the control channel")
    parser.add_argument("--control-host", type=bind_address, default="127.0.0.1", metavar="ADDRESS",
                        help="address of the control channel (default 127.0.0.1, whatever --host says)")
    parser.add_argument("--data-timeout", type=float, default=0.0, metavar="S",
                        help="leave the node via Fail after S seconds without a packet (0 = none, default)")
    parser.add_argument("--connection-timeout", type=float, default=0.0, metavar="S",
                        help="leave the node via Fail when no client connected within S seconds (0 = none)")
    parser.add_argument("--tag-history", type=int, default=4, metavar="N",
                        help="number of queue tags the robot remembers (1..1000, default 4, TMscript 2.24 13.2)")
    parser.add_argument("--tmflow", choices=VERSIONS, default="2.24",
                        help="TMflow version whose TM script functions and formats the robot knows (default 2.24)")
    parser.add_argument("--stop-tags", choices=STOP_TAGS, default="forget",
                        help="what the queue tags dropped by a stop answer: forget = 'none' (default), "
                             "reached = 'true'")
    svr = parser.add_argument_group("Ethernet Slave ($TMSVR, TMscript manual chapter 17)")
    svr.add_argument("--svr-port", type=int, default=None, metavar="PORT",
                     help="Ethernet Slave port of robot 1, further robots the next ports "
                          "(default: the port after the last Listen node port, 5891 for one robot; 0 = any free port)")
    svr.add_argument("--no-svr", action="store_true", help="do not open the Ethernet Slave")
    svr.add_argument("--svr-period", type=float, default=0.1, metavar="S",
                     help="period of the data table sent to every client (default 0.1 s, 0 = not sent)")
    svr.add_argument("--svr-format", choices=sorted(SVR_FORMATS), default="binary",
                     help="format of the periodic data table (default binary, as the Techman ROS driver reads it)")
    svr.add_argument("--svr-items", metavar="A,B,...", default=",".join(DEFAULT_STREAM),
                     help="items of the periodic data table, comma separated (default: the ROS driver's items "
                          "plus the status items; see docs/simulator.md)")
    svr.add_argument("--svr-var", action="append", default=[], metavar="NAME:TYPE[:ACCESS][=VALUE]",
                     help="a global variable of the robot's project, readable and writable through the Ethernet "
                          "Slave (repeat for more): TYPE bool, byte, int, float or string, an array as int[4] "
                          "(fixed size) or string[] (any number of elements, as TMscript's arrays); "
                          "ACCESS rw (default), auto (written in auto mode only) or ro; VALUE as written in string "
                          "mode, e.g. g_count:int=5, g_pos:float[3]={1,2,3}, g_name:string=\"abc\"")
    vision = parser.add_argument_group("virtual camera (TMscript manual §13.32-13.34, chapter 14)")
    vision.add_argument("--vision-job", action="append", default=[], metavar="NAME=POSE;POSE...[@S][!fail]",
                        help="a vision job of every robot's project and the objects it finds, each pose X,Y,Z,RX,RY,RZ "
                             "relative to RobotBase; @S the time it takes (default 0.2 s), !fail a failing job, e.g. "
                             "job1=300,0,5,0,0,0;300,60,5,0,0,90@0.5 (more: control command vision_job)")
    return parser


def check_vision_jobs(args: argparse.Namespace) -> tuple[list[str], list[dict]]:
    """(one line per --vision-job that cannot be defined, the jobs as camera.define arguments)."""
    problems, jobs = [], []
    for spec in getattr(args, "vision_job", []):
        try:
            job = parse_option(spec)
            Camera().define(**job)
        except ValueError as exc:
            problems.append(f"--vision-job {spec[:60]}: {exc}")
            continue
        jobs.append(job)
    return problems, jobs


def check_variables(args: argparse.Namespace) -> tuple[list[str], list]:
    """(one line per --svr-var that cannot be declared, the declared (Item, value) pairs)."""
    problems, variables, seen = [], [], set()
    for spec in args.svr_var:
        try:
            item, value = parse_variable(spec)
        except SvrValueError as exc:
            problems.append(f"--svr-var {spec[:60]}: {exc}")
            continue
        if item.name in seen:
            problems.append(f"--svr-var {spec[:60]}: variable {item.name} is declared twice")
        seen.add(item.name)
        variables.append((item, value))
    return problems, variables




def check_args(args: argparse.Namespace) -> tuple[list[str], int | None, list[str]]:
    """(one line per argument outside its range, Ethernet Slave port or None, its data-table items)."""
    problems = []
    if not 1 <= args.robots <= 512:
        problems.append(f"--robots must be between 1 and 512 (got {args.robots})")
    if not 0 <= args.port <= 65535 or (args.port and args.port + args.robots - 1 > 65535):
        problems.append(f"--port {args.port} with {args.robots} robot(s) leaves the port range 1..65535")
    if not (math.isfinite(args.speedup) and 0 < args.speedup <= SPEEDUP_MAX):
        problems.append(f"--speedup must be positive and at most {SPEEDUP_MAX:g} (got {args.speedup:g})")
    if args.control_port is not None and not 0 <= args.control_port <= 65535:
        problems.append(f"--control-port must be 0..65535 (got {args.control_port})")
    if not 1 <= args.tag_history <= 1000:
        problems.append(f"--tag-history must be between 1 and 1000 (got {args.tag_history})")
    for flag, value in (("--data-timeout", args.data_timeout), ("--connection-timeout", args.connection_timeout)):
        if not (math.isfinite(value) and 0 <= value <= NODE_TIMEOUT_MAX_S):
            problems.append(f"{flag} must be 0 (none) to {NODE_TIMEOUT_MAX_S:g} seconds (got {value:g})")
    svr_port = None if args.no_svr else args.port + args.robots if args.svr_port is None and args.port else \
        (args.svr_port or 0)
    if svr_port is not None and not (svr_port >= 0 and (not svr_port or svr_port + args.robots - 1 <= 65535)):
        if args.svr_port is not None:
            problems.append(f"--svr-port {svr_port} with {args.robots} robot(s) leaves the port range 1..65535")
        else:
            problems.append(f"the Ethernet Slave ports would follow the Listen node ports at {svr_port}, outside "
                            f"1..65535: choose --svr-port PORT or --no-svr")
    elif svr_port and args.port and svr_port < args.port + args.robots and args.port < svr_port + args.robots:
        problems.append(f"--svr-port {svr_port} overlaps the Listen node ports {args.port}.."
                        f"{args.port + args.robots - 1}: choose another --svr-port")
    if not (math.isfinite(args.svr_period) and 0 <= args.svr_period <= 3600):
        problems.append(f"--svr-period must be 0 (off) .. 3600 s (got {args.svr_period:g})")
    svr_items = [name.strip() for name in args.svr_items.split(",") if name.strip()]
    if not svr_items:
        problems.append("--svr-items names no item: give the data table items to stream, A,B,... "
                        "(see docs/simulator.md)")
    declared = {spec.partition(":")[0].strip() for spec in getattr(args, "svr_var", [])}
    unknown = [name for name in svr_items if name not in ITEMS and name not in declared]
    if unknown:
        problems.append(f"--svr-items: unknown data table item(s): {', '.join(unknown)} (see docs/simulator.md)")
    return problems, svr_port, svr_items


def control_port(args: argparse.Namespace) -> int:
    """--control-port as given; by default the port before robot 1's, or any free one when that is in use
    (``tmsim.net.control.default_port``)."""
    return args.control_port if args.control_port is not None else default_port(args.port, args.control_host)


def main(argv: list[str] | None = None) -> int:
    """The command line; Ctrl-C before the simulator is up ends it with exit 130 and one line, no traceback."""
    try:
        return _run(argv)
    except KeyboardInterrupt:
        print("tmflow_listener: interrupted", file=sys.stderr)
        return 130


def _run(argv: list[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    problems, svr_port, svr_items = check_args(args)
    variable_problems, variables = check_variables(args)
    problems += variable_problems
    vision_problems, vision_jobs = check_vision_jobs(args)
    problems += vision_problems
    if problems:
        for problem in problems:
            print(f"tmflow_listener: error: {problem}", file=sys.stderr)
        return 2
    try:
        server = SimServer(host=args.host, port=args.port, robots=args.robots, speedup=args.speedup,
                           auto_enter=not args.no_auto_enter, send_message=args.send_message,
                           log_path=args.log,
                           profile=Profile(tmflow=args.tmflow, tag_history=args.tag_history,
                                           stop_tags=args.stop_tags),
                           control_port=None if args.no_control else control_port(args),
                           data_timeout=args.data_timeout if args.data_timeout > 0 else None,
                           connection_timeout=args.connection_timeout if args.connection_timeout > 0 else None,
                           manage_gc=True, control_host=args.control_host, svr_port=svr_port,
                           svr_options=dict(period=args.svr_period, mode=SVR_FORMATS[args.svr_format],
                                            items=svr_items, variables=variables))
        for robot in server.robots:
            for job in vision_jobs:
                robot.camera().define(**job)
        server.start()
    except OSError as exc:
        print(f"tmflow_listener: error: {exc.strerror or exc}", file=sys.stderr)
        return 1
    # SIGTERM and Ctrl-C stop the simulator cleanly from here on, before the start-up lines: a supervisor (or a user)
    # that waits for them and then stops it gets the clean stop (exit 0), not the default action of the signal or a
    # KeyboardInterrupt in the middle of a line; a second Ctrl-C does not interrupt the shutdown
    done = threading.Event()
    previous = {sig: signal.signal(sig, lambda *_: done.set()) for sig in (signal.SIGTERM, signal.SIGINT)}
    try:
        for robot in server.robots:
            node = "in Listen node" if robot.session.node_state() == IN_NODE else "project running, not in Listen node"
            slave = f", Ethernet Slave on {args.host}:{robot.svr_port}" if server.svr is not None else ""
            print(f"robot {robot.index + 1}: TM5-700 listening on {args.host}:{robot.port} ({node}){slave}", flush=True)
        if server.control is not None:
            print(f"control channel: {args.control_host}:{server.control.port} "
                  f"(JSON lines; {robot_numbering(len(server.robots))})", flush=True)
        first_slave = server.robots[0].slave
        if first_slave is not None:
            print(f"Ethernet Slave data table: every {args.svr_period:g} s, {args.svr_format}, "
                  f"{len(first_slave.session.config()['items'])} items", flush=True)
        if args.speedup != 1.0:
            print(f"robot clock runs {args.speedup:g} x faster than real time", flush=True)
        print("Press Ctrl-C to stop.", flush=True)
        gc.disable()     # the server collects between bursts of requests (SimServer(manage_gc=True))
        gc.freeze()      # what start-up built lives for good: keep it out of every later collection
        server.serve_forever(done)              # the main thread serves: fastest replies
        server.close()
    finally:                                # (for a caller in the same process)
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    print("simulator stopped", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
