"""TM5-700 robot model: a motion FIFO that takes time, plus base, tool, load, IO and queue tags.

State changes only in ``tick(dt)`` (and in the immediate commands ``pause``, ``resume``,
``stop_and_clear``). FIFO items run strictly in order; a queue tag is reached when every item
queued before it has finished. Durations come from ``tmsim.robot.motion`` (documented formulas there).
"""
from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from typing import Any

from tmsim.limits import FIFO_ITEMS_MAX, WORK_PLAN, WORK_PVT_CARTESIAN
from tmsim.robot import kinematics as kin
from tmsim.robot.camera import Camera
from tmsim.robot.errors import classify
from tmsim.robot.motion import MotionError, MotionRequest, Plan, Planner, PvtPlan
from tmsim.tmscript.work import WorkMeter

HOME_JOINTS = (0.0, 0.0, 90.0, 0.0, 90.0, 0.0)
_MATRICES: dict[tuple, list] = {}          # pose -> matrix of bases and tools in use (never modified)
IDENTITY_POSE = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


class RobotModel:
    """One arm. ``tick(dt)`` returns the list of events (dicts) that happened during dt."""

    def __init__(self, tag_history: int = 4, bases: dict | None = None, tools: dict | None = None,
                 stop_tags: str = "forget"):
        self.joints = list(HOME_JOINTS)
        self.bases = {"RobotBase": IDENTITY_POSE, **(bases or {})}
        # The bare flange is a tool record of the controller under both names: "NOTOOL" (TMflow 1.x) and
        # "RobotEndFlange", which TMscript 2.24 §15.3 (item 3) and §15.7 use in their own example packets.
        self.tools = {"NOTOOL": IDENTITY_POSE, "RobotEndFlange": IDENTITY_POSE, **(tools or {})}
        self.base_name, self.base_pose = "RobotBase", list(IDENTITY_POSE)
        self.tool_name, self.tool_pose = "NOTOOL", list(IDENTITY_POSE)
        self.tool_mass = 0.0
        self.load = 0.0
        self.io: dict[str, Any] = {}
        self.fifo: deque[tuple[str, Any]] = deque()
        self.active: Plan | None = None
        self.camera = Camera()     # the project's vision jobs (tmsim/robot/camera.py)
        self.meter = WorkMeter()   # the robot's turn budget, shared with its session (tmsim/tmscript/work.py)
        self.owed = 0.0            # seconds of robot clock not run yet: the turn's budget ended the tick
        self.active_t = 0.0
        self.paused = False
        self.tag_history = tag_history
        self.stop_tags = stop_tags     # tmsim.tmscript.profiles.STOP_TAGS: what a stop does to the tags it drops
        # tag -> "true" | "false", the last tag_history tags in the order they were queued
        self.tags: dict[int, str] = {}
        # tag -> generation of its latest QueueTag (a reused tag's older item stays mute)
        self.tag_gen: dict[int, int] = {}
        self._gen = 0
        self.fault: str | None = None
        self.pvt_mode = None       # None outside PVTEnter .. PVTExit, else 0 (joint) / 1 (Cartesian)
        self.pvt_velocity = (0.0,) * 6   # end velocity of the last PVTPoint (start velocity of the next)
        # status read over the Ethernet Slave (TMflow 2.24 software manual, Appendix D)
        self.error_active = False        # Robot_Error: set by a robot error, cleared by Play or Stop
        self.error_code, self.error_text = 0, ""                         # the last error, kept ...
        self.error_time: float | None = None                             # ... and its robot clock
        self.estop = False               # ESTOP: pressed stops the project; Play is refused while pressed
        self.auto_mode = True            # Operation_Mode: True auto, False manual
        self.project_speed = 100         # Project_Speed in %: motions advance at this share of time (motion_rate)

    # ---- queue --------------------------------------------------------------------------------
    def enqueue_motion(self, request: MotionRequest) -> None:
        self.fifo.append(("motion", request))

    def enqueue_tag(self, tag: int) -> None:
        """QueueTag(tag): the robot keeps the status of the last four tags only (TMscript 2.24 §13.2, §13.3:
        "retain the status of the final four tags ... if the tag number did not occur or exceeds them, it
        returns not existed"); a tag queued earlier than the last ``tag_history`` ones is forgotten, even
        when its motion has not finished yet. Its FIFO item still pushes 01,NN,true when reached."""
        self._gen += 1
        self.tags.pop(tag, None)
        self.tags[tag] = "false"
        self.tag_gen[tag] = self._gen
        while len(self.tags) > max(1, self.tag_history):
            del self.tags[next(iter(self.tags))]
        self.fifo.append(("tag", (tag, self._gen)))

    def enqueue_setting(self, kind: str, value: Any) -> None:
        self.fifo.append((kind, value))

    @property
    def queue_length(self) -> int:
        return len(self.fifo) + (1 if self.active else 0)

    @property
    def has_room(self) -> bool:
        """False while the FIFO holds FIFO_ITEMS_MAX items (bounded memory; the script queueing more waits)."""
        return len(self.fifo) < FIFO_ITEMS_MAX

    @property
    def idle(self) -> bool:
        return not self.fifo and self.active is None

    def tag_status(self, tag: int) -> str:
        return self.tags.get(tag, "none")

    def tag_result(self, tag: int) -> int:
        """WaitQueueTag / CheckQueueTag result (TMscript 2.24 §13.2, §13.3): 1 completed, 0 incomplete,
        -1 not existed (never queued, older than the last four, dropped by a stop, or outside 1..15)."""
        status = self.tags.get(tag, "none") if 1 <= tag <= 15 else "none"
        return {"true": 1, "false": 0}.get(status, -1)

    # ---- immediate commands -------------------------------------------------------------------
    def pause(self) -> None:
        self.paused = True

    def resume(self) -> None:
        self.paused = False

    def stop_and_clear(self) -> list:
        """Stop where the arm is now and drop the FIFO; returns the queue tags that were dropped.
        The manual (TMscript 2.24 §13.1-13.4) does not say what becomes of them; our choice (profile
        option, docs/simulator.md): 'forget' - they answer "not existed" (TMSTA 01 none, WaitQueueTag -1);
        'reached' - they answer true / 1, without a push, for clients that poll until true."""
        if self.active is not None:
            self.joints = self.active.joints_at(self.active_t, self.joints)
            self.active = None
        dropped = [value[0] for kind, value in self.fifo if kind == "tag"]
        for tag in dropped:
            if self.tags.get(tag) == "false":
                if self.stop_tags == "reached":
                    self.tags[tag] = "true"
                else:
                    del self.tags[tag]
        self.fifo.clear()
        self.owed = 0.0
        self.pvt_mode, self.pvt_velocity = None, (0.0,) * 6       # a stop also ends PVT mode
        return dropped

    def latch_error(self, text: str, now: float) -> None:
        """A robot error (its project stops): shown in Robot_Error, Error_Code, Error_Content."""
        self.error_active = True
        self.error_code, self.error_text, self.error_time = classify(text)[0], text, now

    def motion_rate(self, request: MotionRequest) -> float:
        """Share of time a motion advances at: Project_Speed, except the D formats (absolute mm/s, not scaled
        by the project speed, TMscript 2.24 §13.10-13.12) and PVT points (their durations; the
        syncToProjectSpeed flag of §13.19 is not modelled)."""
        if self.project_speed == 100 or request.function == "PVTPoint" or request.fmt[1:2] == "D":
            return 1.0
        return self.project_speed / 100.0

    # ---- time ---------------------------------------------------------------------------------
    def pvt_mode_queued(self) -> int | None:
        """The PVT mode once every queued item has run (None = not in PVT mode)."""
        for kind, value in reversed(self.fifo):
            if kind == "pvt":
                return value
        return self.pvt_mode

    def tick(self, dt: float) -> list[dict]:
        """Run ``dt`` seconds of the arm (plus what an earlier tick owes). Planning a motion is the costly
        part (WORK_PLAN, a Cartesian PVTPoint WORK_PVT_CARTESIAN): once the turn's budget is spent, the
        next motion is not started in this tick; the time left is owed and runs first in the next tick,
        so the timeline of the motions stays exactly the same, only later on the wall clock."""
        events = []
        dt, self.owed = dt + self.owed, 0.0
        while not self.paused:
            if self.active is not None:
                rate = self.motion_rate(self.active.request)
                remaining = (self.active.total - self.active_t) / rate
                if dt < remaining:
                    self.active_t += dt * rate
                    break
                dt -= remaining
                finished, self.active = self.active, None
                self.joints = list(finished.end_joints)
                events.append({"kind": "motion_end", "function": finished.request.function,
                               "line": finished.request.line, "joints": _frozen(self.joints),
                               "pose": _frozen(finished.end_pose)})
                continue
            if not self.fifo:
                break
            if self.meter.spent and self.fifo[0][0] == "motion":
                self.owed = dt
                break
            kind, value = self.fifo.popleft()
            handler = getattr(self, "_run_" + kind)
            event = handler(value)
            if event:
                events.append(event)
            if self.fault:
                break
        return events

    def _run_motion(self, request):
        self.meter.add(WORK_PVT_CARTESIAN if request.function == "PVTPoint" and self.pvt_mode == 1 else WORK_PLAN)
        planner = Planner(self._matrix(self.base_pose), self._matrix(self.tool_pose))    # cached matrices
        plan: Plan | PvtPlan
        try:
            if request.function == "PVTPoint":
                if self.pvt_mode is None:
                    raise MotionError("PVTPoint outside PVTEnter() ... PVTExit()")
                plan = planner.plan_pvt(request, self.joints, self.pvt_mode, self.pvt_velocity)
                self.pvt_velocity = tuple(request.target[6:12])
            elif self.pvt_mode is not None:
                raise MotionError(f"{request.function} inside PVT mode; call PVTExit() first")
            else:
                plan = planner.plan(request, self.joints)
        except (MotionError, kin.KinematicsError, ValueError, ArithmeticError) as exc:   # never the server's end
            self.fault = str(exc)
            self.stop_and_clear()
            return {"kind": "motion_failed", "function": request.function, "line": request.line,
                    "reason": str(exc)}
        self.active, self.active_t = plan, 0.0
        return {"kind": "motion_start", "function": request.function, "line": request.line,
                "from": _frozen(plan.start_pose), "to": _frozen(plan.end_pose),
                "joints_to": _frozen(plan.end_joints), "duration_s": round(plan.total, 4)}

    def _run_tag(self, value):
        tag, gen = value
        if self.tag_gen.get(tag) == gen and tag in self.tags:
            self.tags[tag] = "true"
        return {"kind": "tag_reached", "tag": tag}

    def _run_base(self, value):
        name, pose = self._resolve(value, self.bases, "base")
        if name is None:
            return self._fault_event("ChangeBase", pose)
        self.base_name, self.base_pose = name, pose
        return {"kind": "setting", "what": "base", "name": name, "pose": _frozen(pose)}

    def _run_tcp(self, value):
        mass = None
        if isinstance(value, tuple):
            value, mass = value
        name, pose = self._resolve(value, self.tools, "tool")
        if name is None:
            return self._fault_event("ChangeTCP", pose)
        self.tool_name, self.tool_pose = name, pose
        if mass is not None:
            self.tool_mass = mass
        return {"kind": "setting", "what": "tcp", "name": name, "pose": _frozen(pose)}

    def _run_load(self, value):
        if not 0 <= value < 1e6:
            return self._fault_event("ChangeLoad", f"load {value:g} kg is not a valid mass")
        self.load = value
        return {"kind": "setting", "what": "load", "value": value}

    def _run_pvt(self, mode):
        """PVTEnter(mode) (0 joint, 1 Cartesian) or PVTExit() (mode None), in queue order."""
        if mode is not None and self.pvt_mode is not None:
            return self._fault_event("PVTEnter", "PVTEnter while already in PVT mode")
        self.pvt_mode, self.pvt_velocity = mode, (0.0,) * 6
        return {"kind": "setting", "what": "pvt", "value": {None: "exit", 0: "joint", 1: "cartesian"}[mode]}

    def _run_io(self, value):
        key, level = value
        self.io[key] = level
        return {"kind": "io", "point": key, "value": level}

    def _fault_event(self, function, reason):
        self.fault = reason
        self.stop_and_clear()
        return {"kind": "motion_failed", "function": function, "line": "", "reason": reason}

    @staticmethod
    def _resolve(value, table, what):
        if isinstance(value, str):
            if value not in table:
                return None, f"{what} '{value}' is not defined on the robot"
            return value, list(table[value])
        pose = [float(v) for v in value[:6]]
        if len(pose) != 6 or not all(math.isfinite(v) for v in pose):
            return None, f"{what} frame needs 6 finite numbers"
        return "(custom)", pose

    @staticmethod
    def _matrix(pose):
        key = tuple(pose)
        matrix = _MATRICES.get(key)
        if matrix is None:
            if len(_MATRICES) > 256:
                _MATRICES.clear()
            matrix = _MATRICES[key] = kin.pose_to_matrix(pose)
        return matrix

    # ---- reading ------------------------------------------------------------------------------
    def current_joints(self) -> list[float]:
        if self.active is None:
            return list(self.joints)
        return self.active.joints_at(self.active_t, self.joints)

    def tcp_pose(self, joints: Sequence[float] | None = None) -> list[float]:
        """TCP pose (X, Y, Z, Rx, Ry, Rz) in the current base."""
        joints = self.current_joints() if joints is None else joints
        m = kin.matmul(kin.inverse(self._matrix(self.base_pose)),
                       kin.forward(joints, self._matrix(self.tool_pose)))
        return kin.matrix_to_pose(m)

    def tcp_speed(self, dt: float = 0.01) -> float:
        """TCP speed in mm/s (Robot[0].TCPSpeed3D), from the position now and ``dt`` s before."""
        if self.active is None or self.paused or self.active_t <= 0:
            return 0.0
        before = max(0.0, self.active_t - dt)
        tool = self._matrix(self.tool_pose)
        p0 = kin.forward(self.active.joints_at(before, self.joints), tool)
        p1 = kin.forward(self.active.joints_at(self.active_t, self.joints), tool)
        return math.dist([p0[i][3] for i in range(3)], [p1[i][3] for i in range(3)]) / (self.active_t - before)

    def tcp_pose_robot(self) -> list[float]:
        return kin.matrix_to_pose(kin.forward(self.current_joints(), self._matrix(self.tool_pose)))

    def state(self) -> dict:
        joints = self.current_joints()
        return {"joints": _round(joints), "tcp": _round(self.tcp_pose(joints)),
                "tcp_robot": _round(kin.matrix_to_pose(kin.forward(joints, self._matrix(self.tool_pose)))),
                "configuration": list(kin.configuration(joints)),
                "base": {"name": self.base_name, "pose": _round(self.base_pose)},
                "tool": {"name": self.tool_name, "pose": _round(self.tool_pose), "mass": self.tool_mass},
                "load": self.load, "io": dict(self.io), "queue_length": self.queue_length,
                "moving": self.active is not None, "paused": self.paused,
                "tags": {str(k): v for k, v in self.tags.items()}, "fault": self.fault,
                "pvt": {None: None, 0: "joint", 1: "cartesian"}[self.pvt_mode],
                "robot_error": {"active": self.error_active, "code": self.error_code, "text": self.error_text},
                "estop": self.estop, "operation_mode": "auto" if self.auto_mode else "manual",
                "project_speed": self.project_speed}


def _round(values):
    return [round(v, 4) + 0.0 for v in values]


def _frozen(values):
    """Rounded values as a tuple: events keep tuples so the garbage collector can skip them."""
    return tuple(round(v, 4) + 0.0 for v in values)
