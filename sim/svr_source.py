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

from . import kinematics as kin

_IDENTITY = kin.pose_to_matrix((0.0,) * 6)
_SPEED_STEP_S = 0.01          # Joint_Speed / TCP_Speed: difference quotient over this much motion time

_IO = {"Ctrl_": "ControlBox", "End_": "EndModule"}

# Robot_Light (Appendix D) shown by the simulator: our choice of the documented colours
LIGHT_ESTOP, LIGHT_ERROR = 1, 2                                        # solid red, flashing red
LIGHT = {(True, True): 4, (True, False): 3, (False, True): 6, (False, False): 5}   # (auto, running)


def io_key(name: str) -> str | None:
    """``Ctrl_DO3`` -> ``ControlBox.DO[3]`` (the key TMscript's IO['ControlBox'].DO[3] uses)."""
    for prefix, module in _IO.items():
        if name.startswith(prefix):
            rest = name[len(prefix):]
            return f"{module}.{rest[:2]}[{rest[2:]}]"
    return None


class RobotDataSource:
    """``robot`` is a ``sim.server.Robot`` (its ``session`` is the ListenSession with the RobotModel)."""

    def __init__(self, robot, log, origin: datetime.datetime | None = None):
        self.robot = robot
        self.log = log
        self.origin = origin or datetime.datetime.now().replace(microsecond=0)   # virtual time 0 on the clock
        self.project_name = "CBT_Demo"
        self.run_since = None

    @property
    def model(self):
        return self.robot.session.robot

    @property
    def auto_mode(self) -> bool:
        return self.model.auto_mode

    # ---- reading ------------------------------------------------------------------------------
    def values(self, names) -> dict:
        session, model = self.robot.session, self.model
        running = session.state != "project_stopped"
        if running and self.run_since is None:
            self.run_since = session.now
        elif not running:
            self.run_since = None
        joints = model.current_joints()
        cache = {}

        def pose(kind):
            if kind not in cache:
                tool = model._matrix(model.tool_pose) if kind.endswith("Tool") else _IDENTITY
                m = kin.forward(joints, tool)
                if kind.startswith("Coord_Base"):
                    m = kin.matmul(kin.inverse(model._matrix(model.base_pose)), m)
                cache[kind] = kin.matrix_to_pose(m)
            return cache[kind]

        out = {}
        for name in names:
            out[name] = self._value(name, model, session, running, joints, pose)
        return out

    def _value(self, name, model, session, running, joints, pose):
        if name.startswith("Coord_"):
            return pose(name)
        key = io_key(name)
        if key is not None:
            return model.io.get(key, 0)
        simple = {
            "Robot_Link": 1, "Get_UI_Control": 0, "Warning_Code": 0, "Warning_Time": "", "Project_Edit": 0,
            "Stick_MA": 0, "Stick_Play": 0, "Stick_Stop": 0, "Stick_Plus": 0, "Stick_Minus": 0,
            "Stick_Pause": 0, "Stick_PlayPause": 0, "Ext_Safeguard": 0, "Safeguard_A": 0,
            "Robot_Model": "TM5-700", "ControlBox_SN": "SIM00000001", "TMflow_Version": "2.24.0000",
            "TCP_Force": [0.0] * 3, "TCP_Force3D": 0.0, "Joint_Torque": [0.0] * 6,
        }
        if name in simple:
            return simple[name]
        if name == "Joint_Angle":
            return joints
        if name in ("Joint_Speed", "TCP_Speed", "TCP_Speed3D"):
            return self._speeds(model, joints, pose)[name]
        if name == "Robot_Error":
            return model.error_active
        if name == "Error_Code":
            return model.error_code
        if name == "Error_Content":
            return model.error_text
        if name == "Error_Time":
            return self._clock(model.error_time) if model.error_time is not None else ""
        if name == "Camera_Light":
            return int(model.io.get("CameraLight", 0))
        if name == "Project_Speed":
            return model.project_speed
        if name == "Project_Name":
            return self.project_name
        if name == "Project_Run_Time":
            return _duration(session.now - self.run_since if self.run_since is not None else 0.0)
        if name == "Project_Run":
            return running
        if name == "Project_Pause":
            return running and model.paused
        if name in ("ESTOP", "Stick_ESTOP"):
            return model.estop
        if name == "Robot_State":          # 0 normal, 3 error, 4 STO (including ESTOP)
            return 4 if model.estop else 3 if model.error_active else 0
        if name == "Robot_Light":
            return LIGHT_ESTOP if model.estop else LIGHT_ERROR if model.error_active else \
                LIGHT[(model.auto_mode, running)]
        if name == "Operation_Mode":       # Appendix D: 0 manual, 1 auto
            return 1 if model.auto_mode else 0
        if name == "MA_Mode":              # older tables (EtherNet/IP ManualAuto): 1 manual, 2 auto
            return 2 if model.auto_mode else 1
        if name == "TCP_Name":
            return model.tool_name
        if name == "TCP_Value":
            return list(model.tool_pose)
        if name == "TCP_Mass":
            return model.tool_mass
        if name == "Base_Name":
            return model.base_name
        if name == "Base_Value":
            return list(model.base_pose)
        raise KeyError(name)

    def _speeds(self, model, joints, pose):
        """Joint and TCP speed from the motion under way (difference quotient), zero when it stands."""
        plan = model.active
        if plan is None or model.paused:
            return {"Joint_Speed": [0.0] * 6, "TCP_Speed": [0.0] * 6, "TCP_Speed3D": 0.0}
        h = _SPEED_STEP_S
        later = plan.joints_at(min(plan.total, model.active_t + h), joints)
        scale = model.project_speed / 100.0 / h
        joint_speed = [(b - a) * scale for a, b in zip(joints, later)]
        now_pose = pose("Coord_Robot_Tool")
        then = kin.matrix_to_pose(kin.forward(later, model._matrix(model.tool_pose)))
        tcp = [(b - a) * scale for a, b in zip(now_pose, then)]
        return {"Joint_Speed": joint_speed, "TCP_Speed": tcp, "TCP_Speed3D": sum(v * v for v in tcp[:3]) ** 0.5}

    def _clock(self, seconds) -> str:
        """[YYYY]-[MM]-[DD]T[hh]:[mm]:[ss.sss] (Appendix D) of a virtual time."""
        stamp = self.origin + datetime.timedelta(seconds=seconds)
        return stamp.strftime("%Y-%m-%dT%H:%M:%S.") + f"{stamp.microsecond // 1000:03d}"

    # ---- writing ------------------------------------------------------------------------------
    def write(self, values: dict):
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
                model.io[key] = value
                self.log("io", point=key, value=value, source="ethernet_slave")

    def _stick(self, button):
        session, model = self.robot.session, self.model
        running = session.state != "project_stopped"
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
    def set_estop(self, pressed: bool):
        """Press (the project stops with a robot error) or release the emergency stop."""
        model, session = self.model, self.robot.session
        model.estop = bool(pressed)
        self.log("estop", pressed=model.estop)
        if model.estop and session.state != "project_stopped":
            session.fire("robot_fault", reason="emergency stop pressed", source="estop")
        elif model.estop:
            model.latch_error("emergency stop pressed", session.now)

    def set_auto_mode(self, auto: bool):
        self.model.auto_mode = bool(auto)
        self.log("operation_mode", mode="auto" if auto else "manual")


def _duration(seconds: float) -> str:
    """[days].[hh]:[mm]:[ss.sss] (Appendix D, Project_Run_Time)."""
    seconds = max(0.0, seconds)
    days, rest = divmod(seconds, 86400)
    hours, rest = divmod(rest, 3600)
    minutes, secs = divmod(rest, 60)
    return f"{int(days)}.{int(hours):02d}:{int(minutes):02d}:{secs:06.3f}"
