"""Virtual camera of one robot: the vision jobs of its project and what each would find.

A job is set through the control channel (``vision_job``) or the start-up option ``--vision-job``; the script
functions of TMscript 2.24 §13.32-13.34 (Vision_DoJob, Vision_DoJob_PTP, Vision_DoJob_Line) and chapter 14
(Vision_IsJobAvailable §14.1, Vision_GetOutputArraySize / Vision_GetOutputArrayValue §14.2) ask it
(tmsim/tmscript/interp.py). What a job holds:

    objects   the located objects, each a pose X, Y, Z (mm), RX, RY, RZ (deg) relative to RobotBase: the vision
              base the job defines for that object (our model of a landmark / object-locating job)
    passed    the job's result (False: the job runs and its result is fail; §13.32 "False ... the result is
              fail")
    seconds   the time the job takes once the robot has come to it (image, processing)
    capture   the vision capture point as six joint angles (deg), or None. Vision_DoJob refuses a job with a
              capture point (§13.32 False case 3); Vision_DoJob_PTP / _Line move there first (§13.33, §13.34)
    variable  the name of its output variable, one row per object and the columns X, Y, Z, RX, RY, RZ as texts
              (the 2D string array of §14.2); default ``<job>_Base_TM`` (our choice: TMflow composes the name
              from the job, module and output, as the manual's Job1_Count_Blob_1_DetectObjectX_TM)

After a run the output variable holds the objects of a passed job and no row after a failed one (our choice:
the manual does not say what a failed job leaves). Every value is checked here; a bad one is a ValueError whose
text names it (the control channel answers it, the command line prints it).
"""
from __future__ import annotations

import math
import re
from typing import Any, Protocol

from tmsim.limits import VISION_JOBS_MAX, VISION_OBJECTS_MAX, VISION_POSE_MAX, VISION_SECONDS_MAX
from tmsim.tmscript.floats import float_text  # the texts GetString prints

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,47}\Z")


class VisionJob:
    __slots__ = ("name", "objects", "passed", "seconds", "capture", "variable")

    def __init__(self, name: str, objects: list[tuple], passed: bool, seconds: float, capture: tuple | None,
                 variable: str):
        self.name, self.objects, self.passed = name, objects, passed
        self.seconds, self.capture, self.variable = seconds, capture, variable

    def describe(self) -> dict:
        return {"job": self.name, "objects": [list(p) for p in self.objects], "pass": self.passed,
                "seconds": self.seconds, "capture": None if self.capture is None else list(self.capture),
                "variable": self.variable}


class Camera:
    """The jobs of one robot's project and the output variables of the jobs that ran."""

    def __init__(self):
        self.jobs: dict[str, VisionJob] = {}
        self.outputs: dict[str, list[list[str]]] = {}
        self.runs = 0

    def define(self, name: Any, objects: Any = (), passed: Any = True, seconds: Any = 0.2, capture: Any = None,
               variable: Any = None) -> dict:
        """Define (or redefine) a job from unchecked values (the control channel's, the command line's);
        ValueError names the first bad one."""
        name = _name(name, "job name")
        if name not in self.jobs and len(self.jobs) >= VISION_JOBS_MAX:
            raise ValueError(f"at most {VISION_JOBS_MAX} vision jobs per robot")
        if not isinstance(objects, (list, tuple)) or len(objects) > VISION_OBJECTS_MAX:
            raise ValueError(f"'objects' must be a list of at most {VISION_OBJECTS_MAX} poses")
        poses = [_pose(p, f"object {i}") for i, p in enumerate(objects)]
        if not isinstance(passed, bool):
            raise ValueError("'pass' must be true or false")
        if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) or not 0 <= seconds <= VISION_SECONDS_MAX:
            raise ValueError(f"'seconds' must be 0 .. {VISION_SECONDS_MAX:g}, got {seconds!r}")
        joints = None if capture is None else _pose(capture, "capture point")
        variable = f"{name}_Base_TM" if variable is None else _name(variable, "output variable")
        self.jobs[name] = VisionJob(name, poses, passed, float(seconds), joints, variable)
        return self.jobs[name].describe()

    def remove(self, name: str) -> bool:
        job = self.jobs.pop(name, None)
        if job is not None:
            self.outputs.pop(job.variable, None)
        return job is not None

    def available(self, name: str) -> bool:
        """§14.1: the job is in the project."""
        return name in self.jobs

    def finish(self, job: VisionJob) -> bool:
        """The job has run: its output variable now holds its objects (none when it failed)."""
        self.runs += 1
        rows = [[float_text(v) for v in pose] for pose in job.objects] if job.passed else []
        self.outputs[job.variable] = rows
        return job.passed

    def _rows(self, variable):
        return self.outputs.get(variable, [])             # a name no job has filled: no rows (our choice)

    def array_size(self, variable: str, row: Any = None) -> int:
        """§14.2.1 syntax 1: the object count; syntax 2: the length of the object's result array."""
        rows = self._rows(variable)
        if row is None:
            return len(rows)
        return len(rows[_index(row, len(rows), "object")])

    def array_value(self, variable: str, row: Any, column: Any = None) -> Any:
        """§14.2.2 syntax 1: the object's result array; syntax 2: one value of it. Outside the rows or
        columns: an error, "exceeding the access range" (the manual's example)."""
        rows = self._rows(variable)
        values = rows[_index(row, len(rows), "object")]
        if column is None:
            return list(values)
        return values[_index(column, len(values), "column")]

    def state(self) -> dict:
        return {"jobs": [job.describe() for job in self.jobs.values()], "runs": self.runs,
                "outputs": {name: len(rows) for name, rows in self.outputs.items()}}


def _index(value, count, what) -> int:
    if not 0 <= value < count:
        raise ValueError(f"{what} index {value} exceeds the access range 0..{count - 1}" if count
                         else f"{what} index {value} exceeds the access range (no {what}s)")
    return value


def _name(value, what) -> str:
    if not isinstance(value, str) or not _NAME.match(value):
        shown = repr(value)[:40]
        raise ValueError(f"{what} must be 1..48 letters, digits or '_' (not starting with a digit), got {shown}")
    return value


def _pose(value, what) -> tuple:
    if not isinstance(value, (list, tuple)) or len(value) != 6:
        raise ValueError(f"{what} must be 6 numbers, got {repr(value)[:40]}")
    for v in value:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or abs(v) > VISION_POSE_MAX:
            raise ValueError(f"{what}: {v!r} is not a finite number within +-{VISION_POSE_MAX:g}")
    return tuple(float(v) for v in value)


def parse_option(text: str) -> dict:
    """One --vision-job option: NAME=POSE;POSE...[@SECONDS][!fail], POSE = X,Y,Z,RX,RY,RZ, e.g.
    ``job1=300,0,5,0,0,0;300,60,5,0,0,90@0.5``; an empty pose list (``job1=``) finds nothing."""
    head, sep, rest = text.partition("=")
    if not sep:
        raise ValueError("expected NAME=POSE;POSE...[@SECONDS][!fail]")
    passed = True
    if rest.endswith("!fail"):
        passed, rest = False, rest[:-5]
    seconds = 0.2
    if "@" in rest:
        rest, _, time_text = rest.rpartition("@")
        try:
            seconds = float(time_text)
        except ValueError:
            raise ValueError(f"job time {time_text[:20]!r} is not a number of seconds") from None
    poses = []
    for part in filter(None, (p.strip() for p in rest.split(";"))):
        try:
            poses.append([float(v) for v in part.split(",")])
        except ValueError:
            raise ValueError(f"pose {part[:40]!r} is not 6 numbers X,Y,Z,RX,RY,RZ") from None
    return dict(name=head.strip(), objects=poses, passed=passed, seconds=seconds)


class _HasCamera(Protocol):
    camera: Camera


def camera_of(model: _HasCamera) -> Camera:
    """The camera of a robot model (tmsim/robot/model.py declares it; it lives as long as the model)."""
    return model.camera
