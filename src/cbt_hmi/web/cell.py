"""Serve the web HMI for the user's own program: ``python3 -m cbt_hmi.web.cell --pages DIR SOURCE ...`` compiles the
ST sources on the virtual PLC, builds the variable table from the program's global variables and one page per
page description file in DIR (cbt_hmi.web.pagedesc), runs the PLC in real time and prints the pages' addresses.
A bad page description is printed with its file and line and left out; the other pages are served."""
from __future__ import annotations

import argparse
import sys
import threading

from vplc.api import LoadError, load_plc

from .mapping import Mapping, MappingError
from .pagedesc import load_pages, program_table
from .server import HmiServer, host_argument


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python3 -m cbt_hmi.web.cell",
                                     description=" ".join(__doc__.split("\n\n")[0].split()))   # the whole paragraph
    parser.add_argument("sources", nargs="+", metavar="SOURCE", help="ST files or folders of the program")
    parser.add_argument("--pages", required=True, metavar="DIR", help="folder of page description files (*.json)")
    parser.add_argument("--task", default="Main@10ms", help="task and period (default Main@10ms)")
    parser.add_argument("--program", action="append", default=None, metavar="NAME",
                        help="PROGRAM to run in the task (repeat for several; default: those of the configuration)")
    parser.add_argument("--host", type=host_argument, default="127.0.0.1",
                        help="address to bind (default 127.0.0.1; 0.0.0.0: every interface)")
    parser.add_argument("--port", type=int, default=8080, help="web HMI port (default 8080, 0: any free port)")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        plc = load_plc(args.sources, task=args.task, programs=args.program)
    except LoadError as exc:
        print(exc, file=sys.stderr)
        return 2
    pages, errors = load_pages(args.pages, plc)
    for error in errors:
        print(f"error: {error}", file=sys.stderr)
    try:
        mapping = Mapping(program_table(plc, pages), f"variable table of {' '.join(args.sources)}")
        mapping.check_against_plc(plc)
        hmi = HmiServer(plc, mapping, host=args.host, port=args.port)
        hmi.start()
    except MappingError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"error: web HMI on {args.host}:{args.port}: {exc.strerror}", file=sys.stderr)
        return 2
    print(f"{len(pages)} page(s) from {args.pages}; operator: {hmi.page_url('index', 'operator')}", flush=True)
    print(f"engineer: {hmi.page_url('index', 'engineer')}   monitor: {hmi.url}   (Ctrl-C ends)", flush=True)
    stop = threading.Event()
    try:
        plc.run_realtime(stop, spin_ns=0)      # a desk tool: sleeps to each due time, no spinning (as the demo)
    except KeyboardInterrupt:
        pass
    finally:
        hmi.stop()
        plc.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
