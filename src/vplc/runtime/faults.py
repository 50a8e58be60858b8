"""Runtime faults: the Python side raises RuntimeFaultError; the scan loop turns it into a PlcFault that
names the ST location, the POU instance path and the offending values."""
from __future__ import annotations

GEN_FILE = "<vplc generated>"      # file name of generated code in tracebacks: frames with it run ST


class RuntimeFaultError(Exception):
    """Raised by runtime helpers (division by zero, index out of range, ...) inside generated code."""


class WatchdogError(RuntimeFaultError):
    """A scan ran longer than the watchdog limit (for example an endless WHILE loop)."""


class PlcFault(Exception):
    """Major fault of the virtual controller: the controller stops. ``str()`` is the operator message."""

    def __init__(self, message: str, *, file: str | None = None, line: int | None = None,
                 instance: str | None = None, kind: str = "fault") -> None:
        super().__init__(message)
        self.file, self.line, self.instance, self.kind = file, line, instance, kind
