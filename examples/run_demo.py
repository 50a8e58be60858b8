"""Launcher kept for existing users: `python3 examples/run_demo.py ...` from a checkout, nothing installed.

The demo is the package `cbt_hmi` (src/cbt_hmi/, console script `cbt-demo`, `make demo`). This file only starts it
with the checkout's src/ on PYTHONPATH, in place of this process (same PID, so Ctrl-C and SIGTERM reach the demo).
"""
import os
import sys

SRC = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src")
ENV = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH", "")) if p))

if __name__ == "__main__":
    os.execve(sys.executable, [sys.executable, "-m", "cbt_hmi", *sys.argv[1:]], ENV)
