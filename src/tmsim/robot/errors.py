"""Robot error codes of the simulator (Error_Code / Error_Content of the Ethernet Slave).

TMflow reports a robot error with a code shown in hexadecimal (software manual 2.24, Appendix D,
``Error_Code``: "Last Error Code, Format: Hexadecimal"); the manuals at hand do not list the codes
themselves, so these numbers are the simulator's own (docs/simulator.md says so). One row per kind of
error; the first row whose words all occur in the error text gives the code.
"""
from __future__ import annotations

# (code, words that identify the error in its text, title)
ERRORS = (
    (0x00010001, ("out of reach",), "Target out of reach"),
    (0x00010001, ("cannot be reached",), "Target out of reach"),
    (0x00010002, ("joint limits",), "Joint limit exceeded"),
    (0x00010003, ("speed",), "Invalid motion parameter"),
    (0x00010003, ("blending",), "Invalid motion parameter"),
    (0x00010003, ("acceleration",), "Invalid motion parameter"),
    (0x00010003, ("finite",), "Invalid motion parameter"),
    (0x00010003, ("duration",), "Invalid motion parameter"),
    (0x00010003, ("one line",), "Invalid motion parameter"),
    (0x00010004, ("base",), "Frame or payload setting refused"),
    (0x00010004, ("tool",), "Frame or payload setting refused"),
    (0x00010004, ("load",), "Frame or payload setting refused"),
    (0x00010005, ("pvt",), "PVT sequence error"),
    (0x00020001, ("emergency stop",), "Emergency stop"),
    (0x000F0001, ("internal error",), "Internal error of the simulator"),
)
OTHER = 0x000F0002, "Robot error"


def classify(text: str) -> tuple[int, str]:
    """(code, title) of a robot error text."""
    lowered = text.lower()
    for code, words, title in ERRORS:
        if all(word in lowered for word in words):
            return code, title
    return OTHER
