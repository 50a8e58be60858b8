"""Execution of checked TM script lines (a generator, so blocking statements suspend it).

``run_script`` yields wait requests and is resumed with their result:

    ("tag", tag, timeout_s)   QueueTag(n,1) (timeout None) and WaitQueueTag(n, ms); resumed with
                              1 (reached), 0 (timeout or dropped by a stop) or -1 (unknown tag)

It returns "exit" when ScriptExit() ran (the rest of the packet is ignored), else None.
Immediate statements run when reached; motions, queue tags, base/TCP/load changes and DO/AO writes
are appended to the robot FIFO.
"""
from __future__ import annotations

import struct

from . import script as ast
from .checker import IO_WRITABLE
from .codec import encode as encode_frame
from .motion import MotionRequest

MOTIONS = ("PTP", "Line", "Circle", "PLine", "Move_PTP", "Move_Line", "Move_PLine")
_DEFAULTS = {"int": 0, "float": 0.0, "string": "", "bool": False, "byte": 0}


class ScriptRuntimeError(Exception):
    """A statement that cannot be executed with the values it got."""


class Context:
    """What a running script may touch; the session fills it in."""

    def __init__(self, robot, variables, types, listen_send, stop_and_clear, log_line, log_event=None):
        self.robot = robot
        self.vars = variables
        self.types = types
        self.listen_send = listen_send          # (ip_filter or None, sub, payload bytes) -> None
        self.stop_and_clear = stop_and_clear    # () -> None
        self.log_line = log_line                # (line) -> None
        self.log_event = log_event or (lambda kind, **fields: None)     # (kind, **fields) -> None


def run_script(lines, ctx: Context):
    for line in lines:
        if isinstance(line.stmt, ast.Empty):
            continue
        ctx.log_line(line)
        try:
            stmt = line.stmt
            if isinstance(stmt, ast.Decl):
                type_name = stmt.type + ("[]" if stmt.is_array else "")
                ctx.types[stmt.name] = type_name
                if stmt.init is None:
                    ctx.vars[stmt.name] = [] if stmt.is_array else _DEFAULTS[stmt.type]
                else:
                    ctx.vars[stmt.name] = _coerce(type_name, (yield from _eval(stmt.init, ctx, line)))
            elif isinstance(stmt, ast.Assign):
                value = yield from _eval(stmt.value, ctx, line)
                if stmt.op != "=":
                    current = yield from _eval(stmt.target, ctx, line)
                    value = _arith(stmt.op[0], current, value)
                yield from _store(stmt.target, value, ctx, line)
            elif isinstance(stmt, ast.IncDec):
                current = yield from _eval(stmt.target, ctx, line)
                yield from _store(stmt.target, current + (1 if stmt.op == "++" else -1), ctx, line)
            elif isinstance(stmt.expr, ast.Call) and stmt.expr.name == "ScriptExit":
                return "exit"
            else:
                yield from _eval(stmt.expr, ctx, line)
        except ScriptRuntimeError as exc:
            raise ScriptRuntimeError(f"line {line.number}: {exc}") from None
        except (ZeroDivisionError, IndexError, TypeError, ValueError, OverflowError) as exc:
            raise ScriptRuntimeError(f"line {line.number}: {exc}") from None
    return None


def _coerce(type_name, value):
    if type_name in ("int", "byte"):
        return int(value)
    if type_name == "float":
        return float(value)
    if type_name.endswith("[]"):
        return [_coerce(type_name[:-2], v) for v in value]
    return value


def _arith(op, a, b):
    if op == "+":
        return (str(a) + str(b)) if isinstance(a, str) or isinstance(b, str) else a + b
    if op == "-":
        return a - b
    if op == "*":
        return a * b
    if op == "/":
        if b == 0:
            raise ScriptRuntimeError("division by zero")
        return a / b if isinstance(a, float) or isinstance(b, float) else int(a / b)
    if op == "%":
        if b == 0:
            raise ScriptRuntimeError("division by zero")
        return a % b
    raise ScriptRuntimeError(f"unsupported operator {op}")


_COMPARE = {"==": lambda a, b: a == b, "!=": lambda a, b: a != b, "<": lambda a, b: a < b,
            ">": lambda a, b: a > b, "<=": lambda a, b: a <= b, ">=": lambda a, b: a >= b}


def _io_key(node, ctx, line):
    member = node.obj
    module = member.obj.index
    name = module.id if isinstance(module, ast.Name) else module.value
    index = yield from _eval(node.index, ctx, line)
    return f"{name}.{member.name}[{index}]", member.name


def _is_io(node):
    return (isinstance(node, ast.Index) and isinstance(node.obj, ast.Member)
            and isinstance(node.obj.obj, ast.Index) and isinstance(node.obj.obj.obj, ast.Name)
            and node.obj.obj.obj.id == "IO")


def _store(target, value, ctx, line):
    if isinstance(target, ast.Name):
        ctx.vars[target.id] = _coerce(ctx.types.get(target.id, "any"), value)
        return
    if _is_io(target):
        key, member = yield from _io_key(target, ctx, line)
        level = int(value) if IO_WRITABLE[member] == "int" else float(value)
        if member.startswith("Instant"):
            point = key.replace("Instant", "")
            ctx.robot.io[point] = level
            ctx.log_event("io", point=point, value=level, instant=True)
        else:
            if not ctx.robot.has_room:
                yield ("room", None, None)        # the FIFO is full: wait until an item has run
            ctx.robot.enqueue_setting("io", (key, level))
        return
    if isinstance(target, ast.Member):          # Robot[0].CameraLight
        ctx.robot.io["CameraLight"] = int(value)
        return
    array = ctx.vars[target.obj.id]
    index = yield from _eval(target.index, ctx, line)
    if index < 0:
        raise ScriptRuntimeError(f"index {index} is negative")
    while len(array) <= index:
        array.append(_DEFAULTS.get(ctx.types[target.obj.id][:-2], 0))
    array[index] = _coerce(ctx.types[target.obj.id][:-2], value)


_LITERALS = frozenset({ast.Num, ast.Str, ast.Bool})
_QUEUED = frozenset(MOTIONS + ("ChangeBase", "ChangeTCP", "ChangeLoad", "QueueTag", "PVTEnter", "PVTPoint",
                                "PVTExit"))


def _eval(node, ctx, line):
    if isinstance(node, (ast.Num, ast.Str, ast.Bool)):
        return node.value
    if isinstance(node, ast.Name):
        return ctx.vars[node.id] if node.id in ctx.vars else node.id     # else: unquoted string constant
    if isinstance(node, ast.Array):
        values = []
        for item in node.items:
            values.append((yield from _eval(item, ctx, line)))
        return values
    if isinstance(node, ast.Unary):
        value = yield from _eval(node.operand, ctx, line)
        return (not value) if node.op == "!" else -value
    if isinstance(node, ast.Binary):
        left = yield from _eval(node.left, ctx, line)
        if node.op in ("&&", "||"):
            if (node.op == "&&") != bool(left):
                return bool(left)
            return bool((yield from _eval(node.right, ctx, line)))
        right = yield from _eval(node.right, ctx, line)
        if node.op in _COMPARE:
            return _COMPARE[node.op](left, right)
        return _arith(node.op, left, right)
    if isinstance(node, ast.Call):
        args = []
        for arg in node.args:
            if type(arg) in _LITERALS:             # no generator for a literal (motion lines are all literals)
                args.append(arg.value)
            else:
                args.append((yield from _eval(arg, ctx, line)))
        return (yield from _call(node, args, ctx, line))
    if _is_io(node):
        key, _member = yield from _io_key(node, ctx, line)
        return ctx.robot.io.get(key, 0)
    if isinstance(node, ast.Member):                    # Robot[0].X
        return _robot_member(node.name, ctx.robot)
    if isinstance(node, ast.Index):
        base = yield from _eval(node.obj, ctx, line)
        index = yield from _eval(node.index, ctx, line)
        if not 0 <= index < len(base):
            raise ScriptRuntimeError(f"index {index} is outside 0..{len(base) - 1}")
        return base[index]
    raise ScriptRuntimeError("unsupported expression")


def _robot_member(name, robot):
    if name == "CoordRobot":
        return robot.tcp_pose_robot()
    if name == "CoordBase":
        return robot.tcp_pose()
    if name == "Joint":
        return robot.current_joints()
    if name == "BaseName":
        return robot.base_name
    if name == "TCPName":
        return robot.tool_name
    if name == "CameraLight":
        return robot.io.get("CameraLight", 0)
    return 0.0


def _motion(name, args, line):
    fmt, rest = args[0], list(args[1:])
    if name == "Circle":
        if isinstance(rest[0], list):
            via, end, rest = rest[0], rest[1], rest[2:]
        else:
            via, end, rest = rest[:6], rest[6:12], rest[12:]
        if len(via) != 6 or len(end) != 6:
            raise ScriptRuntimeError("Circle points need 6 values each")
        speed, accel, blend, arc, disable = rest
        return MotionRequest(name, fmt, tuple(float(v) for v in via + end), speed, accel, blend, not disable,
                             arc_angle=float(arc), line=line.text)
    if isinstance(rest[0], list):
        target, rest = rest[0], rest[1:]
    else:
        target, rest = rest[:6], rest[6:]
    if len(target) != 6:
        raise ScriptRuntimeError(f"{name} target needs 6 values, got {len(target)}")
    config = None
    if name in ("PLine", "Move_PLine"):
        speed, accel, blend = rest
        disable = True
    else:
        speed, accel, blend, disable = rest[:4]
        if len(rest) > 4:
            config = tuple(int(v) for v in (rest[4] if isinstance(rest[4], list) else rest[4:7]))
            if len(config) != 3 or config[0] not in (0, 1) or config[1] not in (2, 3) or config[2] not in (4, 5):
                raise ScriptRuntimeError(f"arm configuration {list(config)} is not {{0|1, 2|3, 4|5}}")
    return MotionRequest(name, fmt, tuple(float(v) for v in target), speed, accel, blend, not disable,
                         config=config, line=line.text)


def _call(node, args, ctx, line):
    name = node.name
    robot = ctx.robot
    if name in _QUEUED and not robot.has_room:
        yield ("room", None, None)                # the FIFO is full: wait until an item has run
    if name in MOTIONS:
        if not isinstance(args[0], str):
            raise ScriptRuntimeError("data format must be a string")
        robot.enqueue_motion(_motion(name, args, line))
        return True
    if name == "ChangeBase":
        robot.enqueue_setting("base", args[0] if len(args) == 1 else list(args))
        return True
    if name == "ChangeTCP":
        if len(args) == 1 or (args and isinstance(args[0], list)):
            value, mass = args[0], (args[1] if len(args) > 1 else None)
        else:
            value, mass = list(args[:6]), (args[6] if len(args) > 6 else None)
        robot.enqueue_setting("tcp", (value, mass))
        return True
    if name == "ChangeLoad":
        if args[0] < 0:
            raise ScriptRuntimeError("load must not be negative")
        robot.enqueue_setting("load", float(args[0]))
        return True
    if name == "PVTEnter":
        mode = int(args[0]) if args else 0
        if mode not in (0, 1):
            raise ScriptRuntimeError(f"PVT mode {mode} is not 0 (joint) or 1 (Cartesian)")
        robot.enqueue_setting("pvt", mode)
        return True
    if name == "PVTExit":
        robot.enqueue_setting("pvt", None)
        return True
    if name == "PVTPoint":
        if len(args) == 3:
            pos, vel, duration = args
        else:
            pos, vel, duration = list(args[:6]), list(args[6:12]), args[12]
        if len(pos) != 6 or len(vel) != 6:
            raise ScriptRuntimeError("PVTPoint needs 6 positions and 6 velocities")
        robot.enqueue_motion(MotionRequest("PVTPoint", "", tuple(float(v) for v in pos + vel), 0.0, 0.0, 0.0,
                                           False, line=line.text, duration=float(duration)))
        return True
    if name in ("PVTPause", "PVTResume"):
        (robot.pause if name == "PVTPause" else robot.resume)()
        return True
    if name == "QueueTag":
        tag = int(args[0])
        if not 1 <= tag <= 15:
            raise ScriptRuntimeError(f"queue tag {tag} is outside 1..15")
        robot.enqueue_tag(tag)
        if len(args) > 1 and int(args[1]) == 1:
            yield ("tag", tag, None)
        return True
    if name == "WaitQueueTag":
        timeout = args[1] if len(args) > 1 else -1
        return (yield ("tag", int(args[0]), None if timeout < 0 else timeout / 1000.0))
    if name == "Pause":
        robot.pause()
        return True
    if name == "Resume":
        robot.resume()
        return True
    if name == "StopAndClearBuffer":
        ctx.stop_and_clear()
        return True
    if name == "ListenSend":
        ip_filter, sub, value = (None, *args) if len(args) == 2 else args
        if not 90 <= sub <= 99:
            return -2
        value_type = ctx.types.get(node.args[-1].id) if isinstance(node.args[-1], ast.Name) else None
        ctx.listen_send(ip_filter, sub, encode_value(value, value_type))
        return 0
    if name == "ListenPacket":             # the frame text, as in the manual: no CR LF at the end
        header, data = ("TMSCT", args[0]) if len(args) == 1 else args
        if header not in ("TMSCT", "TMSTA", "CPERR"):
            raise ScriptRuntimeError(f"ListenPacket header {header!r} is not TMSCT, TMSTA or CPERR")
        return encode_frame(header, data).decode("utf-8")[:-2]
    if name == "GetString":
        return to_text(args[0])
    raise ScriptRuntimeError(f"function {name} cannot run here")


def to_text(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value) if value != int(value) or abs(value) >= 1e15 else str(int(value))
    if isinstance(value, list):
        return "{" + ",".join(to_text(v) for v in value) + "}"
    return str(value)


def encode_value(value, type_name=None) -> bytes:
    """ListenSend payload: strings as UTF-8 text, other values as little-endian binary."""
    if isinstance(value, str):
        return value.encode("utf-8")
    if isinstance(value, bool):
        return b"\x01" if value else b"\x00"
    element = (type_name or "")[:-2] if type_name and type_name.endswith("[]") else type_name
    if isinstance(value, list):
        return b"".join(encode_value(v, element) for v in value)
    if element == "byte":
        return struct.pack("<B", int(value) & 0xFF)
    if isinstance(value, int) and element != "float":
        return struct.pack("<i", value)
    return struct.pack("<f", float(value))
