"""SVG timing diagrams of long runs: a time window, REAL as an analog curve, BOOL pulses that stay visible."""
import re
import xml.etree.ElementTree as ET

import pytest

from vplc.cli.run import parse_window
from vplc.trace.svg import LABEL_W, MIN_PULSE, render_svg

MS = 1_000_000
NS = "{http://www.w3.org/2000/svg}"


class Rec:
    """What the Recorder hands to the writer: paths, kinds and the change lists."""

    def __init__(self, rows, end_ns):
        self.paths = [r[0] for r in rows]
        self.kinds = [r[1] for r in rows]
        self.changes = [r[2] for r in rows]
        self.end_ns = end_ns


def polyline_points(svg, index):
    lines = ET.fromstring(svg).findall(f"{NS}polyline")
    return [tuple(float(v) for v in p.split(",")) for p in lines[index].get("points").split()]


def test_a_one_scan_pulse_in_a_one_hour_trace_stays_visible_and_is_marked():
    hour = 3_600_000 * MS
    rec = Rec([("Main.Done", ("bool", 1), [(0, False), (1_800_000 * MS, True), (1_800_001 * MS, False)])], hour)
    svg = render_svg(rec)
    pts = polyline_points(svg, 0)
    highs = [x for x, y in pts if y == min(y for _, y in pts)]
    assert max(highs) - min(highs) == pytest.approx(MIN_PULSE)
    assert svg.count('fill="#c01c28"') == 1            # the marker above the widened pulse


def test_real_is_an_analog_curve_scaled_to_its_range():
    ramp = [(t * MS, float(t)) for t in range(0, 1001)]
    rec = Rec([("Main.Pos.X", ("real", 32), ramp)], 1000 * MS)
    svg = render_svg(rec)
    pts = polyline_points(svg, 0)
    ys = [y for _, y in pts]
    assert ys[0] > ys[-1]                               # rises from the bottom to the top of its row
    assert len(pts) < 4 * 700                           # at most four points per pixel column
    assert ">1000<" in svg and ">0<" in svg             # range written at the left


def test_trace_window_draws_only_that_part_with_the_value_in_effect_at_its_start():
    rec = Rec([("Main.Step", ("int", 16), [(0, 1), (10 * MS, 2), (30 * MS, 3)])], 40 * MS)
    svg = render_svg(rec, parse_window("20ms..35ms"))
    texts = [t.text for t in ET.fromstring(svg).iter(f"{NS}text")]
    assert "2" in texts and "3" in texts and "1" not in texts
    ticks = [t for t in texts if t.endswith(" ms")]
    assert ticks == [f"{t} ms" for t in range(20, 35, 2)]          # 1-2-5 grid: 2 ms steps over 15 ms
    first_shape = ET.fromstring(svg).find(f"{NS}polygon").get("points")
    assert float(re.split("[ ,]", first_shape)[-2]) == pytest.approx(LABEL_W)


@pytest.mark.slow
def test_dense_bus_changes_become_one_hatched_band():
    rec = Rec([("Main.N", ("int", 16), [(t * MS, t) for t in range(5000)])], 5000 * MS)
    svg = render_svg(rec)
    assert svg.count('fill="url(#dense)"') == 1 and "<polygon" not in svg


def test_trace_window_option_is_checked():
    for bad in ("2s", "3s..1s", "a..b"):
        with pytest.raises(ValueError, match="--trace-window"):
            parse_window(bad)
    assert parse_window("..3s") == (0, 3_000_000_000)
