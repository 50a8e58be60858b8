"""Run every benchmark script in bench/ (bench_*.py) one after another and print their figures.

Each benchmark is a standalone script that prints human-readable figures; this runner only sequences
them, so a failing benchmark is reported by name and the others still run.
"""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys


def main() -> int:
    here = pathlib.Path(__file__).resolve().parent
    scripts = sorted(here.glob("bench_*.py"))
    if not scripts:
        print("No benchmarks found in bench/.")
        return 1
    failed = []
    # the benchmarks drive the tests' rigs (tests/lib: the library on the virtual PLC against the simulator;
    # tests/hmi: the stand-in PLC; tests/examples: the example cells); the packages come from the install
    rigs = [str(here.parent / "tests" / folder) for folder in ("lib", "hmi", "examples")]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(rigs + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    for script in scripts:
        print(f"\n=== {script.name} " + "=" * max(0, 60 - len(script.name)), flush=True)
        result = subprocess.run([sys.executable, str(script)], cwd=here.parent, env=env)
        if result.returncode != 0:
            failed.append(script.name)
            print(f"!!! {script.name} ended with exit code {result.returncode}", flush=True)
    print()
    if failed:
        print("Benchmarks that failed: " + ", ".join(failed))
        return 1
    print(f"All {len(scripts)} benchmarks completed.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
