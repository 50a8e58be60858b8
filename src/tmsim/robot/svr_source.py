"""The data table of one simulated robot: Ethernet Slave item values from the robot model and its project,
and the writes (stick buttons, outputs, project speed) acted out on them.

Stick buttons (TMflow 2.24 software manual, Appendix D: "W: Triggered as 1 received") act as on the robot
stick: Play starts a stopped project or resumes a paused one, Stop stops the project (a stopped project:
acknowledges the robot error), Pause pauses, PlayPause toggles, +/- change the project speed by 5 %.
Play is refused while the emergency stop is pressed (event ``stick_refused``). Starting and stopping the
project go through the server's ``Robot`` (so the Listen node's port opens and closes as with the control
channel).
"""
from __future__ import annotations

import datetime
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any, Protocol

from tmsim.protocol.svr_table import ITEMS
from tmsim.robot import kinematics as kin

if TYPE_CHECKING:
    from tmsim.protocol.listen_session import ListenSession
    from tmsim.robot.model import RobotModel


class Controller(Protocol):
    """What the data table needs of the robot it describes (the server's ``Robot``): its Listen-node session
    (project state, robot model, clock) and the project's start and stop, as the stick buttons act them out."""
    session: ListenSession

    def start_project(self) -> None: ...

    def stop_project(self) -> None: ...

_SPEED_STEP_S = 0.01          # Joint_Speed / TCP_Speed: difference quotient over this much motion time

_IO = {"Ctrl_": "ControlBox", "End_": "EndModule"}

# Robot_Light (Appendix D) shown by the simulator: our choice of the documented colours
LIGHT_ESTOP, LIGHT_ERROR = 1, 2                                        # solid red, flashing red
LIGHT = {(True, True): 4, (True, False): 3, (False, True): 6, (False, False): 5}   # (auto, running)


# items whose value the simulator does not model (no force sensor, no teach pendant, no safeguard inputs)
_CONSTANT = {
    "Robot_Link": 1, "Get_UI_Control": 0, "Warning_Code": 0, "Warning_Time": "", "Project_Edit": 0,
    "Stick_MA": 0, "Stick_Play": 0, "Stick_Stop": 0, "Stick_Plus": 0, "Stick_Minus": 0, "Stick_Pause": 0,
    "Stick_PlayPause": 0, "Ext_Safeguard": 0, "Safeguard_A": 0, "Robot_Model": "TM5-700",
    "ControlBox_SN": "SIM00000001", "TMflow_Version": "2.24.0000", "TCP_Force": [0.0] * 3, "TCP_Force3D": 0.0,
    "Joint_Torque": [0.0] * 6,
}


def io_key(name: str) -> str | None:
    """``Ctrl_DO3`` -> ``ControlBox.DO[3]`` (the key TMscript's IO['ControlBox'].DO[3] uses)."""
    for prefix, module in _IO.items():
        if name.startswith(prefix):
            rest = name[len(prefix):]
            return f"{module}.{rest[:2]}[{rest[2:]}]"
    return None


class RobotDataSource:
    """``robot`` is a ``tmsim.net.robot_ports.Robot`` (its ``session`` is the ListenSession with the RobotModel)."""

    def __init__(self, robot: Controller, log: Callable[..., None], origin: datetime.datetime | None = None):
        self.robot = robot
        self.log = log
        self.origin = origin or datetime.datetime.now().replace(microsecond=0)   # virtual time 0 on the clock
        self.project_name = "CBT_Demo"
        self.run_since: float | None = None
        self._getters = self._build_getters()

    @property
    def model(self) -> RobotModel:
        return self.robot.session.robot

    @property
    def auto_mode(self) -> bool:
        return self.model.auto_mode

    # ---- reading ------------------------------------------------------------------------------
    def values(self, names: Iterable[str]) -> dict:
        """{name: value} of one consistent moment (joints and poses computed once)."""
        session, model = self.robot.session, self.model
        running = session.project_running()
        if running and self.run_since is None:
            self.run_since = session.now
        elif not running:
            self.run_since = None
        now = _Moment(model, session, running)
        getters = self._getters
        return {name: getters[name](now) for name in names}

    def _build_getters(self):
        """One function per item (the per-frame cost is one call per item)."""
        getters: dict[str, Callable[..., Any]] = {name: (lambda m, v=value: v) for name, value in _CONSTANT.items()}
        for name in ITEMS:
            key = io_key(name)
            if key is not None:
                getters[name] = lambda m, key=key: m.model.io.get(key, 0)
            elif name.startswith("Coord_"):
                getters[name] = lambda m, kind=name: m.pose(kind)
        getters.update({
            "Joint_Angle": lambda m: m.joints,
            "Joint_Speed": lambda m: m.speeds()["Joint_Speed"],
            "TCP_Speed": lambda m: m.speeds()["TCP_Speed"],
            "TCP_Speed3D": lambda m: m.speeds()["TCP_Speed3D"],
            "Robot_Error": lambda m: m.model.error_active,
            "Error_Code": lambda m: m.model.error_code,
            "Error_Content": lambda m: m.model.error_text,
            "Error_Time": lambda m: self._clock(m.model.error_time) if m.model.error_time is not None else "",
            "Camera_Light": lambda m: int(m.model.io.get("CameraLight", 0)),
            "Project_Speed": lambda m: m.model.project_speed,
            "Project_Name": lambda m: self.project_name,
            "Project_Run_Time": lambda m: _duration(m.session.now - self.run_since
                                                    if self.run_since is not None else 0.0),
            "Project_Run": lambda m: m.running,
            "Project_Pause": lambda m: m.running and m.model.paused,
            "ESTOP": lambda m: m.model.estop,
            "Stick_ESTOP": lambda m: m.model.estop,
            "Robot_State": lambda m: 4 if m.model.estop else 3 if m.model.error_active else 0,   # 4 STO, 3 error
            "Robot_Light": lambda m: LIGHT_ESTOP if m.model.estop else LIGHT_ERROR if m.model.error_active
            else LIGHT[(m.model.auto_mode, m.running)],
            "Operation_Mode": lambda m: 1 if m.model.auto_mode else 0,       # Appendix D: 0 manual, 1 auto
            "MA_Mode": lambda m: 2 if m.model.auto_mode else 1,              # older tables: 1 manual, 2 auto
            "TCP_Name": lambda m: m.model.tool_name,
            "TCP_Value": lambda m: list(m.model.tool_pose),
            "TCP_Mass": lambda m: m.model.tool_mass,
            "Base_Name": lambda m: m.model.base_name,
            "Base_Value": lambda m: list(m.model.base_pose),
        })
        return getters

    def _clock(self, seconds) -> str:
        """[YYYY]-[MM]-[DD]T[hh]:[mm]:[ss.sss] (Appendix D) of a virtual time."""
        stamp = self.origin + datetime.timedelta(seconds=seconds)
        return stamp.strftime("%Y-%m-%dT%H:%M:%S.") + f"{stamp.microsecond // 1000:03d}"

    # ---- writing ------------------------------------------------------------------------------
    def write(self, values: dict) -> None:
        model = self.model
        for name, value in values.items():
            if name.startswith("Stick_"):
                if value:
                    self._stick(name[len("Stick_"):])
            elif name == "Project_Speed":
                model.project_speed = int(value)
            elif name == "Project_Name":
                self.project_name = value
            elif name == "Camera_Light":
                model.io["CameraLight"] = int(value)
            else:
                key = io_key(name)
                model.io[key] = value    # type: ignore[index]  # the other writable items are IO points: a key
                self.log("io", point=key, value=value, source="ethernet_slave")

    def _stick(self, button):
        session, model = self.robot.session, self.model
        running = session.project_running()
        if button == "PlayPause":
            button = "Play" if not running or model.paused else "Pause"
        self.log("stick", button=button)
        if button == "Play":
            if model.estop:
                self.log("stick_refused", button=button, reason="emergency stop pressed")
            elif not running:
                model.error_active = False
                self.robot.start_project()
            elif model.paused:
                model.resume()
        elif button == "Stop":
            if running:
                self.robot.stop_project()
            else:
                model.error_active = False
        elif button == "Pause":
            if running:
                model.pause()
        elif button == "Plus":
            model.project_speed = min(100, model.project_speed + 5)
        elif button == "Minus":
            model.project_speed = max(5, model.project_speed - 5)

    # ---- operator actions (control channel, tests) --------------------------------------------
    def set_estop(self, pressed: bool) -> None:
        """Press (the project stops with a robot error) or release the emergency stop."""
        model = self.model
        model.estop = bool(pressed)
        self.log("estop", pressed=model.estop)
        if model.estop:
            self.robot.session.robot_error("emergency stop pressed", source="estop")

    def set_input(self, name: str, value: Any) -> None:
        """An input of the robot changes, as a sensor wired to it would change it: ``Ctrl_DI0``..``Ctrl_DI15`` and
        ``End_DI0``..``End_DI3`` take 0 or 1, ``Ctrl_AI0``/``Ctrl_AI1``/``End_AI0``/``End_AI1`` volts in -10..10
        (Appendix D item names). The data table shows it from its next frame. ValueError naming the item when it is
        not an input or the value does not fit it."""
        item, key = ITEMS.get(name), io_key(name)
        if item is None or key is None or key.partition(".")[2][:2] not in ("DI", "AI"):
            raise ValueError(f"{name!r} is not an input item (Ctrl_DI0..15, Ctrl_AI0..1, End_DI0..3, End_AI0..1)")
        if item.type == "float":
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not -10 <= value <= 10:
                raise ValueError(f"{name} takes volts in -10..10, got {value!r}")
            value = float(value)
        elif isinstance(value, float) or value not in (0, 1):
            raise ValueError(f"{name} takes 0 or 1, got {value!r}")
        else:
            value = int(value)
        self.model.io[key] = value
        self.log("io", point=key, value=value, source="input")

    def set_auto_mode(self, auto: bool) -> None:
        self.model.auto_mode = bool(auto)
        self.log("operation_mode", mode="auto" if auto else "manual")


class _Moment:
    """What one read of the data table sees: joints, poses and speeds computed once, on first use."""

    def __init__(self, model, session, running):
        self.model, self.session, self.running = model, session, running
        self.joints = model.current_joints()
        self._poses, self._speeds, self._flange = {}, None, None

    def pose(self, kind):
        """Coord_{Base|Robot}_{Flange|Tool}: the flange matrix once, then tool and base applied."""
        pose = self._poses.get(kind)
        if pose is None:
            model = self.model
            if self._flange is None:
                self._flange = kin.forward(self.joints)
            m = kin.matmul(self._flange, model._matrix(model.tool_pose)) if kind.endswith("Tool") else self._flange
            if kind.startswith("Coord_Base"):
                m = kin.matmul(kin.inverse(model._matrix(model.base_pose)), m)
            pose = self._poses[kind] = kin.matrix_to_pose(m)
        return pose

    def speeds(self):
        """Joint and TCP speed of the motion under way (difference quotient), zero while it stands."""
        if self._speeds is None:
            model, plan = self.model, self.model.active
            if plan is None or model.paused:
                self._speeds = {"Joint_Speed": [0.0] * 6, "TCP_Speed": [0.0] * 6, "TCP_Speed3D": 0.0}
            else:
                later = plan.joints_at(min(plan.total, model.active_t + _SPEED_STEP_S), self.joints)
                scale = model.motion_rate(plan.request) / _SPEED_STEP_S
                then = kin.matrix_to_pose(kin.forward(later, model._matrix(model.tool_pose)))
                tcp = [(b - a) * scale for a, b in zip(self.pose("Coord_Robot_Tool"), then, strict=False)]
                self._speeds = {"Joint_Speed": [(b - a) * scale for a, b in zip(self.joints, later, strict=False)],
                                "TCP_Speed": tcp, "TCP_Speed3D": sum(v * v for v in tcp[:3]) ** 0.5}
        return self._speeds


def _duration(seconds: float) -> str:
    """[days].[hh]:[mm]:[ss.sss] (Appendix D, Project_Run_Time)."""
    seconds = max(0.0, seconds)
    days, rest = divmod(seconds, 86400)
    hours, rest = divmod(rest, 3600)
    minutes, secs = divmod(rest, 60)
    return f"{int(days)}.{int(hours):02d}:{int(minutes):02d}:{secs:06.3f}"
