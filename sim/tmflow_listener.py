"""Launcher kept for existing users: `python3 sim/tmflow_listener.py ...` from a checkout, nothing installed.

The simulator is the package `tmsim` (src/tmsim/, console script `tmflow-sim`). This file only starts it with the
checkout's src/ on PYTHONPATH, in place of this process (same PID, so signals reach the simulator itself).
"""
import os
import sys

SRC = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src")
ENV = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH", "")) if p))

if __name__ == "__main__":
    os.execve(sys.executable, [sys.executable, "-m", "tmsim", *sys.argv[1:]], ENV)
