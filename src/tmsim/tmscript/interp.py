"""Execution of checked TM script lines (a generator, so blocking statements suspend it).

``run_script`` yields wait requests and is resumed with their result:

    ("tag", tag, timeout_s)   QueueTag(n,1) (timeout None) and WaitQueueTag(n, ms); resumed with
                              1 (completed), 0 (timeout) or -1 (not existed: unknown, forgotten, dropped)
    ("idle", None, None)      WaitQueueTag(): until every queued motion is done
    ("delay", None, s)        Sleep(ms), WaitQueueTag(0, ms)
    ("room", None, None)      a queued statement while the FIFO is full
    ("turn", None, None)      the turn's work budget is spent (ctx.meter, tmsim/tmscript/work.py): go on in a later turn

It returns "exit" when ScriptExit() ran (the rest of the packet is ignored), else None.
Immediate statements run when reached; motions, queue tags, base/TCP/load changes and DO/AO writes
are appended to the robot FIFO.

Values are bounded as on the robot (tmsim/limits.py; each bound is a run-time ``ERROR;line``):
int arithmetic wraps at 32 bits and byte arithmetic at 8 bits [MAN 2.24 §2.2]; a value outside int
converted to int (a variable, an IO point, any int parameter of any function) is an error [§2.2], so no
Sleep or WaitQueueTag timeout exceeds INT_MAX ms; a float variable refuses
a value beyond ±3.4028235E+38, infinity or NaN [MAN 2.24 §2.5]; arrays hold at most 2048 elements
[MAN 2.24 §2.3]; strings at most STRING_MAX characters; a project at most VARIABLES_MAX variables using
VARIABLE_BYTES_MAX bytes; one script at most STEPS_MAX steps of work. A script's intermediate values
are freed when it ends; its variables live until the flow leaves the Listen node.
"""
from __future__ import annotations

import math
import struct
from collections.abc import Callable, Generator, Iterable
from typing import TYPE_CHECKING, Any

from tmsim.limits import (
    ARRAY_MAX,
    BYTE_MAX,
    FLOAT_MAX,
    INT_MAX,
    INT_MIN,
    IO_INDEX_MAX,
    STEPS_MAX,
    STRING_MAX,
    VARIABLE_BYTES_MAX,
    VARIABLES_MAX,
    WORK_STEP,
)
from tmsim.protocol.codec import encode as encode_frame
from tmsim.robot.camera import camera_of
from tmsim.robot.motion import MotionRequest
from tmsim.tmscript import functions as table
from tmsim.tmscript import parser as ast
from tmsim.tmscript.floats import float_text
from tmsim.tmscript.work import WorkMeter

if TYPE_CHECKING:
    from tmsim.robot.model import RobotModel

MOTIONS = ("PTP", "Line", "Circle", "PLine", "Move_PTP", "Move_Line", "Move_PLine")
_DEFAULTS = {"int": 0, "float": 0.0, "string": "", "bool": False, "byte": 0}


class ScriptRuntimeError(Exception):
    """A statement that cannot be executed with the values it got."""


class Context:
    """What a running script may touch; the session fills it in."""

    def __init__(self, robot: RobotModel, variables: dict[str, Any], types: dict[str, Any],
                 listen_send: Callable[[str | None, str, bytes], None], stop_and_clear: Callable[[], None],
                 log_line: Callable[..., None], log_event: Callable[..., None] | None = None,
                 meter: WorkMeter | None = None):
        self.robot = robot
        self.vars = variables
        self.types = types
        self.steps = 0                          # work done by this script (STEPS_MAX)
        self.var_bytes = sum(map(_size, variables.values()))
        self.listen_send = listen_send          # (ip_filter or None, sub, payload bytes) -> None
        self.stop_and_clear = stop_and_clear    # () -> None
        self.log_line = log_line                # (line) -> None
        self.log_event = log_event or (lambda kind, **fields: None)     # (kind, **fields) -> None
        self.meter = meter or WorkMeter()       # the turn's work (tmscript/work.py): a spent turn suspends the script


def run_script(lines: Iterable[Any], ctx: Context) -> Generator[tuple, Any, str | None]:
    """Run checked lines (ast.Line) on ``ctx``: a generator that yields each wait (see the session's _resume_waits)
    and returns "exit" when ScriptExit() ran."""
    for line in lines:
        if isinstance(line.stmt, ast.Empty):
            continue
        if ctx.meter.spent:                     # between two statements: the rest in a later turn
            yield ("turn", None, None)
        ctx.log_line(line)
        try:
            stmt = line.stmt
            _work(ctx, 1)
            if isinstance(stmt, ast.Decl):
                type_name = stmt.type + ("[]" if stmt.is_array else "")
                if stmt.name not in ctx.vars and len(ctx.vars) >= VARIABLES_MAX:
                    raise ScriptRuntimeError(f"the project holds at most {VARIABLES_MAX} variables")
                if stmt.init is None:
                    value = _Array() if stmt.is_array else _DEFAULTS[stmt.type]
                else:
                    _check_constant(type_name, stmt.init)
                    value = _coerce(type_name, (yield from _eval(stmt.init, ctx, line)), ctx)
                _set_variable(ctx, stmt.name, type_name, value)
            elif isinstance(stmt, ast.Assign):
                value = yield from _eval(stmt.value, ctx, line)
                if stmt.op != "=":
                    current = yield from _eval(stmt.target, ctx, line)
                    value = _arith(stmt.op[0], current, value, ctx)
                elif isinstance(stmt.target, ast.Name):
                    _check_constant(ctx.types.get(stmt.target.id, "any"), stmt.value)
                yield from _store(stmt.target, value, ctx, line)
            elif isinstance(stmt, ast.IncDec):
                current = yield from _eval(stmt.target, ctx, line)
                yield from _store(stmt.target, _arith("+" if stmt.op == "++" else "-", current, 1, ctx), ctx, line)
            elif isinstance(stmt.expr, ast.Call) and stmt.expr.name == "ScriptExit":
                yield from _arguments(stmt.expr, ctx, line)      # checked like any call's, then the exit
                return "exit"
            else:
                yield from _eval(stmt.expr, ctx, line)
        except ScriptRuntimeError as exc:
            raise ScriptRuntimeError(f"line {line.number}: {exc}") from None
        except (ZeroDivisionError, IndexError, TypeError, ValueError, OverflowError) as exc:
            raise ScriptRuntimeError(f"line {line.number}: {exc}") from None
    return None


class _Array(list):
    """An array value of a variable; ``nbytes`` is its share of VARIABLE_BYTES_MAX (kept up to date)."""
    __slots__ = ("nbytes",)

    def __init__(self, items=(), nbytes=None):
        super().__init__(items)
        self.nbytes = sum(map(_size, self)) if nbytes is None else nbytes


def _size(value) -> int:
    """Bytes a variable value counts against VARIABLE_BYTES_MAX: 8 a number, 1 a character."""
    if type(value) is str:
        return 8 + len(value)
    if type(value) is _Array:
        return 8 + value.nbytes
    if isinstance(value, list):
        return 8 + sum(map(_size, value))
    return 8


def variable_memory(variables: dict) -> int:
    """Bytes the variables count against VARIABLE_BYTES_MAX."""
    return sum(map(_size, variables.values()))


def _work(ctx, steps):
    ctx.steps += steps
    ctx.meter.work += steps * WORK_STEP
    if ctx.steps > STEPS_MAX:
        raise ScriptRuntimeError(f"the script needs more than {STEPS_MAX} steps of work; "
                                 f"send it in smaller packets")


def _set_variable(ctx, name, type_name, value):
    """Store a whole variable, keeping the project within VARIABLE_BYTES_MAX."""
    new = _size(value)
    old = _size(ctx.vars[name]) if name in ctx.vars else 0
    if ctx.var_bytes - old + new > VARIABLE_BYTES_MAX:
        raise ScriptRuntimeError(f"variable memory full: the project's variables may use {VARIABLE_BYTES_MAX} bytes")
    ctx.var_bytes += new - old
    ctx.types[name] = type_name
    ctx.vars[name] = value


def _wrap_int(value: int) -> int:
    """[MAN 2.24 §2.2] int keeps the low 32 bits of a result, as a signed value (2147483647 + 1 = -2147483648)."""
    if INT_MIN <= value <= INT_MAX:
        return value
    return ((value - INT_MIN) & 0xFFFFFFFF) + INT_MIN


def _check_constant(type_name, node):
    """[MAN 2.24 §2.2] a constant outside the byte range assigned to a byte is an Error (byte b = -100)."""
    if type_name == "byte" and isinstance(node, ast.Num) and not 0 <= node.value <= BYTE_MAX:
        raise ScriptRuntimeError(f"constant {node.value} is outside the byte range 0..{BYTE_MAX}")


def _to_int(value) -> int:
    """A value converted to int, as an int variable or an int parameter takes it: a float is truncated; a
    value outside the int range is an error [MAN 2.24 §2.2]: results of int arithmetic wrap before they
    get here, so an int outside the range is the constant 2147483648, a float constant by §2.2."""
    if isinstance(value, float):
        if not math.isfinite(value) or not INT_MIN <= value < INT_MAX + 1:
            raise ScriptRuntimeError(f"value {value:g} does not fit int ({INT_MIN}..{INT_MAX})")
        return int(value)
    value = int(value)
    if not INT_MIN <= value <= INT_MAX:
        raise ScriptRuntimeError(f"value {value} does not fit int ({INT_MIN}..{INT_MAX})")
    return value


def _int_arguments(name, args, positions):
    """The arguments of a call with its int (and int[]) parameters converted by the rule of _to_int, for
    every function in one place: Sleep(1e30) or WaitQueueTag(1, 2147483648) is an error of its line, not a
    wait of 10^27 s. ``positions``: tmsim.tmscript.functions.INT_ARGUMENTS."""
    args = list(args)
    for position, is_array in positions:
        try:
            value = args[position]
            args[position] = [_to_int(v) for v in value] if is_array else _to_int(value)
        except ScriptRuntimeError as exc:
            raise ScriptRuntimeError(f"{name} argument {position + 1}: {exc}") from None
    return args


def _to_float(value) -> float:
    value = float(value)
    if not math.isfinite(value) or abs(value) > FLOAT_MAX:        # [MAN 2.24 §2.5]
        raise ScriptRuntimeError(f"value {value:g} is outside the float range (±3.4028235E+38)")
    return value


def _coerce(type_name, value, ctx):
    if type_name == "int":
        return _to_int(value)
    if type_name == "byte":
        return _to_int(value) & BYTE_MAX          # [MAN 2.24 §2.2] byte keeps the low 8 bits (0 - 1 = 255)
    if type_name == "float":
        return _to_float(value)
    if type_name.endswith("[]"):
        if len(value) > ARRAY_MAX:
            raise ScriptRuntimeError(f"an array holds at most {ARRAY_MAX} elements, got {len(value)}")
        _work(ctx, len(value) // 8)
        element = type_name[:-2]
        if element == "int" and all(type(v) is int and INT_MIN <= v <= INT_MAX for v in value):
            items = list(value)                   # fast path: a copy of valid values (array = array)
        elif element == "float" and all(type(v) is float and -FLOAT_MAX <= v <= FLOAT_MAX for v in value):
            items = list(value)
        else:
            items = [_coerce(element, v, ctx) for v in value]
        return _Array(items, 8 * len(items) + sum(len(v) for v in items if type(v) is str))
    if type(value) is str and len(value) > STRING_MAX:
        raise ScriptRuntimeError(f"a string holds at most {STRING_MAX} characters")
    return value


def _arith(op, a, b, ctx):
    if op == "+" and (isinstance(a, str) or isinstance(b, str)):
        a, b = _text_of(a, ctx), _text_of(b, ctx)
        if len(a) + len(b) > STRING_MAX:
            raise ScriptRuntimeError(f"a string holds at most {STRING_MAX} characters")
        _work(ctx, (len(a) + len(b)) // 256)
        return a + b
    if isinstance(a, (str, list)) or isinstance(b, (str, list)):
        raise ScriptRuntimeError(f"operator {op} needs numbers")
    integer = not (isinstance(a, float) or isinstance(b, float))
    if op == "+":
        result = a + b
    elif op == "-":
        result = a - b
    elif op == "*":
        result = a * b
    elif op == "/":
        if b == 0:
            raise ScriptRuntimeError("division by zero")
        result = int(a / b) if integer else a / b
    elif op == "%":
        if b == 0:
            raise ScriptRuntimeError("division by zero")
        result = a % b
    else:
        raise ScriptRuntimeError(f"unsupported operator {op}")
    return _wrap_int(result) if integer else result


_COMPARE = {"==": lambda a, b: a == b, "!=": lambda a, b: a != b, "<": lambda a, b: a < b,
            ">": lambda a, b: a > b, "<=": lambda a, b: a <= b, ">=": lambda a, b: a >= b}


def _io_key(node, ctx, line):
    member = node.obj
    module = member.obj.index
    name = module.id if isinstance(module, ast.Name) else module.value
    index = yield from _eval(node.index, ctx, line)
    if not 0 <= index <= IO_INDEX_MAX:
        raise ScriptRuntimeError(f"IO index {index} is outside 0..{IO_INDEX_MAX}")
    return f"{name}.{member.name}[{index}]", member.name


def _is_io(node):
    return (isinstance(node, ast.Index) and isinstance(node.obj, ast.Member)
            and isinstance(node.obj.obj, ast.Index) and isinstance(node.obj.obj.obj, ast.Name)
            and node.obj.obj.obj.id == "IO")


def _store(target, value, ctx, line):
    if isinstance(target, ast.Name):
        type_name = ctx.types.get(target.id, "any")
        _set_variable(ctx, target.id, type_name, _coerce(type_name, value, ctx))
        return
    if _is_io(target):
        key, member = yield from _io_key(target, ctx, line)
        level = _to_int(value) if table.IO_POINTS[member][0] == "int" else _to_float(value)
        if member.startswith("Instant"):
            point = key.replace("Instant", "")
            ctx.robot.io[point] = level
            ctx.log_event("io", point=point, value=level, instant=True)
        else:
            if not ctx.robot.has_room:
                yield ("room", None, None)        # the FIFO is full: wait until an item has run
            ctx.robot.enqueue_setting("io", (key, level))
        return
    if isinstance(target, ast.Member):          # Robot[0].CameraLight / InstantCameraLight
        ctx.robot.io["CameraLight"] = _to_int(value)
        return
    name = target.obj.id
    array = ctx.vars[name]
    index = yield from _eval(target.index, ctx, line)
    if not 0 <= index < ARRAY_MAX:           # [MAN 2.24 §2.3] at most 2048 elements
        raise ScriptRuntimeError(f"index {index} is outside 0..{ARRAY_MAX - 1} (an array holds at most "
                                 f"{ARRAY_MAX} elements)")
    element_type = ctx.types[name][:-2]
    value = _coerce(element_type, value, ctx)
    default = _DEFAULTS.get(element_type, 0)
    grown = max(0, index + 1 - len(array))
    old = _size(array[index]) if index < len(array) else 0
    added = grown * _size(default) - (_size(default) if grown else 0) + _size(value) - old
    if ctx.var_bytes + added > VARIABLE_BYTES_MAX:
        raise ScriptRuntimeError(f"variable memory full: the project's variables may use {VARIABLE_BYTES_MAX} bytes")
    _work(ctx, grown)
    array.extend([default] * grown)
    array[index] = value
    ctx.var_bytes += added
    if type(array) is _Array:
        array.nbytes += added


_LITERALS = frozenset({ast.Num, ast.Str, ast.Bool})
_QUEUED = frozenset(name for name in table.FUNCTIONS if table.queued(name))
_INT_ARGUMENTS = table.INT_ARGUMENTS


def _eval(node, ctx, line):
    if isinstance(node, (ast.Num, ast.Str, ast.Bool)):
        return node.value
    if isinstance(node, ast.Name):
        return ctx.vars.get(node.id, node.id)     # not a variable: an unquoted string constant
    ctx.steps += 1
    if isinstance(node, ast.Array):
        if len(node.items) > ARRAY_MAX:
            raise ScriptRuntimeError(f"an array holds at most {ARRAY_MAX} elements, got {len(node.items)}")
        values = []
        for item in node.items:
            if type(item) in _LITERALS:             # no generator for a literal element
                values.append(item.value)
            else:
                values.append((yield from _eval(item, ctx, line)))
        return values
    if isinstance(node, ast.Unary):
        value = yield from _eval(node.operand, ctx, line)
        if node.op == "!":
            return not value
        return -value if isinstance(value, float) else _wrap_int(-value)
    if isinstance(node, ast.Binary):
        left = yield from _eval(node.left, ctx, line)
        if node.op in ("&&", "||"):
            if (node.op == "&&") != bool(left):
                return bool(left)
            return bool((yield from _eval(node.right, ctx, line)))
        right = yield from _eval(node.right, ctx, line)
        if node.op in _COMPARE:
            return _COMPARE[node.op](left, right)
        return _arith(node.op, left, right, ctx)
    if isinstance(node, ast.Call):
        args = yield from _arguments(node, ctx, line)
        return (yield from _call(node, args, ctx, line))
    if _is_io(node):
        key, _member = yield from _io_key(node, ctx, line)
        return ctx.robot.io.get(key, 0)
    # the static check admits an index only on a name, so node.obj.obj is an ast.Name here
    if isinstance(node, ast.Member) and isinstance(node.obj, ast.Index) and node.obj.obj.id == "IO":  # type: ignore[attr-defined]
        return _io_array(node, ctx.robot)                # IO["Module"].DI: the whole array (2.x)
    if isinstance(node, ast.Member):                    # Robot[0].X
        return _robot_member(node.name, ctx.robot)
    if isinstance(node, ast.Index):
        base = yield from _eval(node.obj, ctx, line)
        index = yield from _eval(node.index, ctx, line)
        if not 0 <= index < len(base):
            raise ScriptRuntimeError(f"index {index} is outside 0..{len(base) - 1}")
        return base[index]
    raise ScriptRuntimeError("unsupported expression")


def _io_array(node, robot):
    """IO["Module"].ATTR as an array (TMscript 2.24 §11.5); sizes: tmsim.tmscript.functions.IO_SIZES."""
    module = node.obj.index
    name = module.id if isinstance(module, ast.Name) else module.value
    attribute = node.name.replace("Instant", "")
    return [robot.io.get(f"{name}.{attribute}[{i}]", 0) for i in range(table.io_size(name, node.name))]


def _robot_member(name, robot):
    """Robot[0].attribute (TMscript 2.24 §11.6). The model has no force sensing: TCPForce3D is 0."""
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
    if name in ("CameraLight", "InstantCameraLight"):
        return robot.io.get("CameraLight", 0)
    if name == "Payload":
        return robot.load
    if name == "TCPSpeed3D":
        return robot.tcp_speed()
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
            config = tuple(rest[4] if isinstance(rest[4], list) else rest[4:7])
            if len(config) != 3 or config[0] not in (0, 1) or config[1] not in (2, 3) or config[2] not in (4, 5):
                raise ScriptRuntimeError(f"arm configuration {list(config)} is not {{0|1, 2|3, 4|5}}")
    return MotionRequest(name, fmt, tuple(float(v) for v in target), speed, accel, blend, not disable,
                         config=config, line=line.text)


def _arguments(node, ctx, line):
    """The argument values of a call, its int parameters converted (_int_arguments)."""
    args = []
    for arg in node.args:
        if type(arg) in _LITERALS:                 # no generator for a literal (motion lines are all literals)
            args.append(arg.value)
        else:
            args.append((yield from _eval(arg, ctx, line)))
    positions = _INT_ARGUMENTS.get((node.name, len(args)))
    return _int_arguments(node.name, args, positions) if positions else args


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
        # §13.5 syntax 1: the index picks one of the bases a vision job found; for the name of a plain base
        # it has no meaning ("the base index is invalid", the manual's ChangeBase("RobotBase", 10)). The
        # simulator's bases are all plain ones, so the index is not used.
        single = len(args) == 1 or isinstance(args[0], str)
        robot.enqueue_setting("base", args[0] if single else list(args))
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
        mode = args[0] if args else 0
        if mode not in (0, 1):
            raise ScriptRuntimeError(f"PVT mode {mode} is not 0 (joint) or 1 (Cartesian)")
        robot.enqueue_setting("pvt", mode)
        return True
    if name == "PVTExit":                       # §13.18; outside PVT mode: "command rejected" (false), no effect
        if robot.pvt_mode_queued() is None:
            return False
        robot.enqueue_setting("pvt", None)
        return True
    if name == "PVTPoint":
        if isinstance(args[0], list):           # §13.19 syntax 1/2: arrays, duration [, sync to project speed]
            pos, vel, duration = args[:3]
        else:                                   # syntax 3/4: 13 numbers [, sync]; the sim runs at 100 %
            pos, vel, duration = list(args[:6]), list(args[6:12]), args[12]
        if len(pos) != 6 or len(vel) != 6:
            raise ScriptRuntimeError("PVTPoint needs 6 positions and 6 velocities")
        robot.enqueue_motion(MotionRequest("PVTPoint", "", tuple(float(v) for v in pos + vel), 0.0, 0.0, 0.0,
                                           False, line=line.text, duration=float(duration)))
        return True
    if name in ("PVTPause", "PVTResume"):      # §13.20, §13.21; outside PVT mode: rejected (false), no effect
        if robot.pvt_mode is None:
            return False
        (robot.pause if name == "PVTPause" else robot.resume)()
        return True
    if name == "QueueTag":
        tag = args[0]
        if not 1 <= tag <= 15:
            raise ScriptRuntimeError(f"queue tag {tag} is outside 1..15")
        robot.enqueue_tag(tag)
        if len(args) > 1 and args[1] == 1:
            yield ("tag", tag, None)
        return True
    if name == "WaitQueueTag":
        return (yield from _wait_queue_tag(args, robot))
    if name == "CheckQueueTag":                 # TMscript 2.24 §13.3: WaitQueueTag(tag, 0), one check
        return robot.tag_result(args[0])
    if name == "Sleep":
        if args[0] > 0:
            yield ("delay", None, args[0] / 1000.0)
        return None
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
        payload = encode_value(value, value_type)
        _work(ctx, len(payload) // 256)          # sending is string work: counted by its size, as building one
        ctx.listen_send(ip_filter, sub, payload)
        return 0
    if name == "ListenPacket":             # the frame text, as in the manual: no CR LF at the end
        header, data = ("TMSCT", args[0]) if len(args) == 1 else args
        if header not in ("TMSCT", "TMSTA", "CPERR"):
            raise ScriptRuntimeError(f"ListenPacket header {header!r} is not TMSCT, TMSTA or CPERR")
        return encode_frame(header, data).decode("utf-8")[:-2]
    if name == "GetString":
        return _text_of(args[0], ctx)
    if name.startswith("Vision_"):
        return (yield from _vision(name, args, ctx, line))
    raise ScriptRuntimeError(f"function {name} cannot run here")


def _vision(name, args, ctx, line):
    """The vision functions against the robot's virtual camera (tmsim/robot/camera.py). A job runs in order with the
    motions: Vision_DoJob* first wait until the motions queued before them are done (§13.33, §13.34 "queue with
    the motion commands"), _PTP / _Line then move to the job's capture point and wait for that motion, and the
    job takes its time; the script goes on with the job's result. An unknown job returns False, "fail to
    execute" (§13.32-13.34 False case 2)."""
    camera = camera_of(ctx.robot)
    if name == "Vision_IsJobAvailable":                   # §14.1
        return camera.available(args[0])
    try:
        if name == "Vision_GetOutputArraySize":           # §14.2.1
            return camera.array_size(*args)
        if name == "Vision_GetOutputArrayValue":          # §14.2.2
            return camera.array_value(*args)
    except ValueError as exc:                              # the manual's "Return error. Exceeding the access range."
        raise ScriptRuntimeError(str(exc)) from None
    job = camera.jobs.get(args[0])
    if job is None:
        ctx.log_event("vision_job", job=args[0][:48], result="unknown")
        return False
    if name == "Vision_DoJob" and job.capture is not None:
        ctx.log_event("vision_job", job=job.name, result="has a capture point")
        return False                                      # §13.32 False case 3
    robot = ctx.robot
    yield ("idle", None, None)
    if name != "Vision_DoJob" and job.capture is not None:
        if name == "Vision_DoJob_PTP":                    # §13.33: speed %, time to top speed (ms)
            if args[1] < 0:
                raise ScriptRuntimeError("Vision_DoJob_PTP speed must be 0..100 %")
            motion = ("PTP", ["JPP", list(job.capture), args[1], args[2], 0, False])
        else:                                             # §13.34: syntax 1 speed %, syntax 2/3 mm/s and ms
            target = robot.tcp_pose(list(job.capture))
            if args[1] < 0:
                raise ScriptRuntimeError("Vision_DoJob_Line speed must not be negative")
            if len(args) == 2:
                motion = ("Line", ["CPP", target, args[1], 200, 0, False])
            else:
                linked = args[3] if len(args) > 3 else True
                motion = ("Line", ["CAP" if linked else "CDP", target, args[1], args[2], 0, False])
        if not robot.has_room:
            yield ("room", None, None)
        robot.enqueue_motion(_motion(motion[0], motion[1], line))
        yield ("idle", None, None)
    if job.seconds > 0:
        yield ("delay", None, job.seconds)
    result = camera.finish(job)
    ctx.log_event("vision_job", job=job.name, result="pass" if result else "fail",
                  objects=len(job.objects) if result else 0)
    return result


def _wait_queue_tag(args, robot):
    """WaitQueueTag per TMscript 2.24 §13.2. Syntax 3 (no argument): wait until every queued motion is
    done, no return value. Tag 1..15: timeout < 0 (the default of syntax 2) waits until completed or not
    existed, 0 checks once, > 0 waits up to that many ms. Tag 0 is invalid but waits for the timeout
    (returns at once when the timeout is infinite); a tag < 0 or > 15 returns -1 without waiting."""
    if not args:
        yield ("idle", None, None)
        return None
    tag = args[0]
    timeout = args[1] if len(args) > 1 else -1
    if tag < 0 or tag > 15:
        return -1
    if tag == 0:
        if timeout > 0:
            yield ("delay", None, timeout / 1000.0)
        return 0
    if timeout == 0:
        return robot.tag_result(tag)
    return (yield ("tag", tag, None if timeout < 0 else timeout / 1000.0))


def _text_of(value, ctx) -> str:
    """to_text, counting its work: an array's elements are printed one by one (4 steps each)."""
    if isinstance(value, list):
        _work(ctx, 4 * len(value))
    return to_text(value)


def to_text(value: Any) -> str:
    """A value as GetString and string concatenation print it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return float_text(value)
    if isinstance(value, list):
        return "{" + ",".join(to_text(v) for v in value) + "}"
    return str(value)


def encode_value(value: Any, type_name: str | None = None) -> bytes:
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
