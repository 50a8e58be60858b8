"""How the robot prints a TM ``float`` (GetString, ListenSend texts, the camera's result rows): one function the
interpreter and the robot model's camera share."""
from __future__ import annotations

import math
import struct
from decimal import Decimal


def float_text(value: float) -> str:
    """A TM ``float`` is 32 bits: printed with the fewest digits that read back as the same 32-bit value
    (0.1 -> "0.1", 417.5 -> "417.5", 1/3 -> "0.33333334"), fixed point for exponents -5..14, else
    "1E+15" / "1.5E-07" (our reading of the robot's .NET-style output; docs/simulator.md)."""
    if not math.isfinite(value):
        return "NaN" if math.isnan(value) else ("Infinity" if value > 0 else "-Infinity")
    try:
        single = struct.unpack("<f", struct.pack("<f", value))[0]
    except OverflowError:
        return "Infinity" if value > 0 else "-Infinity"
    if single == 0:
        return "0"
    for digits in range(1, 10):
        text = f"{single:.{digits}g}"
        if struct.unpack("<f", struct.pack("<f", float(text)))[0] == single:
            break
    number = Decimal(text)
    exponent = number.adjusted()
    if -5 <= exponent < 15:
        fixed = format(number, "f")
        return fixed.rstrip("0").rstrip(".") if "." in fixed else fixed
    mantissa, _, power = f"{number:E}".partition("E")
    return f"{mantissa}E{power[0]}{int(power[1:]):02d}"
