"""This engine against the engine of an earlier commit, on the same ST programs, in one run (issue 15, target 3).

The earlier engine is taken from git (``git archive <rev> src``) into a temporary folder. Each engine runs in a
worker process of its own; the parent asks them for rounds of scans in turn, so both see the same machine load,
and keeps each engine's best round of CPU time (process time: a busy machine's preemption does not count).
Before timing, each worker scans the program on virtual time and reports a digest of every variable it can read
after every scan: the results must be identical.
"""
from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import tarfile
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# the engine before the issue-15 speed work: the commit that split the compiled program from the PLC instance
BASELINE = "d79ff86"

WORKER = r'''
import hashlib, json, sys, time
from vplc.api import load_plc

def leaves(plc, prefix, value, out):
    info = getattr(type(value), "i__vars", None)
    if isinstance(value, list):
        for k, v in enumerate(value):
            leaves(plc, f"{prefix}[{k}]", v, out)
    elif info is not None:
        for name, (attr, _t) in sorted(info.items()):
            if hasattr(value, attr):
                leaves(plc, f"{prefix}.{name}", getattr(value, attr), out)
    else:
        out.append(f"{prefix}={value!r}")

def digest(plc, scans):
    h = hashlib.sha256()
    for k in range(scans):
        plc.scan(k * 1_000_000)
        out = []
        leaves(plc, "Main", plc.instances["MAIN"], out)
        h.update("|".join(out).encode())
    return h.hexdigest()

path, scans = sys.argv[2], int(sys.argv[3])
print(json.dumps({"digest": digest(load_plc([path]), 2000)}), flush=True)
plc = load_plc([path])
t = 0
for line in sys.stdin:
    t0 = time.process_time()
    for _ in range(scans):
        plc.scan(t)
        t += 1_000_000
    print(json.dumps({"us": (time.process_time() - t0) / scans * 1e6}), flush=True)
'''


def baseline_src(rev: str, into: str) -> str:
    """The ``src`` tree of commit ``rev``, extracted below ``into``."""
    data = subprocess.run(["git", "-C", ROOT, "archive", rev, "src"], capture_output=True, check=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(into, filter="data")
    return os.path.join(into, "src")


def compare(programs: dict[str, str], rev: str = BASELINE, rounds: int = 9, scans: int = 1000) -> list[dict]:
    """For each ST program text: best µs per scan of both engines, the speed-up and whether traces agree."""
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        old_src = baseline_src(rev, os.path.join(tmp, "baseline"))
        new_src = os.path.join(ROOT, "src")
        for label, text in programs.items():
            path = os.path.join(tmp, "program.st")
            with open(path, "w") as f:
                f.write(text)
            workers = [subprocess.Popen([sys.executable, "-c", WORKER, src, path, str(scans)], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True, cwd=tmp,
                                        env={**os.environ, "PYTHONPATH": src})
                       for src in (old_src, new_src)]
            try:
                digests = [json.loads(w.stdout.readline())["digest"] for w in workers]
                best = [float("inf"), float("inf")]
                for _ in range(rounds):
                    for k, w in enumerate(workers):
                        w.stdin.write("go\n")
                        w.stdin.flush()
                        best[k] = min(best[k], json.loads(w.stdout.readline())["us"])
            finally:
                for w in workers:
                    w.stdin.close()
                    w.wait(timeout=30)
            results.append(dict(label=label, old=best[0], new=best[1], speedup=best[0] / best[1],
                                identical=digests[0] == digests[1]))
    return results
