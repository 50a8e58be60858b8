"""`vplc draw`: a ladder POU as SVG, drawn from the same layout as the HMI's Program page; clean usage errors."""
from __future__ import annotations

import xml.etree.ElementTree as ET

from ld_trace import ROOT
from ld_xml import block, coil, comment, contact, invar, outvar, program, rail, right

from vplc.cli.main import main

LIB = ROOT / "lib" / "CBT_Commands_Lib"
SVG = "{http://www.w3.org/2000/svg}"


def draw(capsys, *args):
    code = main(["draw", *map(str, args)])
    out = capsys.readouterr()
    return code, out.out, out.err


def groups(svg_path, cls):
    root = ET.parse(svg_path).getroot()
    return [g for g in root.iter(f"{SVG}g") if cls in (g.get("class") or "").split()]


def texts(g):
    return [t.text for t in g.iter(f"{SVG}text") if t.text]


def test_the_example_is_drawn_one_rung_per_command(tmp_path, capsys):
    out = tmp_path / "commands.svg"
    code, stdout, _ = draw(capsys, LIB, ROOT / "examples", "--pou", "Commands_Example", "-o", out)
    assert code == 0 and stdout.strip() == f"{out}: Commands_Example, 11 rung(s)"
    rungs = groups(out, "rung")
    assert len(rungs) == 11
    first = rungs[0]
    assert "Change Base" in texts(first)
    blocks = [g for g in first.iter(f"{SVG}g") if "block" in (g.get("class") or "")]
    assert len(blocks) == 1
    words = texts(blocks[0])
    for word in ("fbChangeBase", "CBT_ChangeBase", "CBT", "Execute", "Parameters", "Done", "Busy", "CommandAborted",
                 "Error", "ErrorID", "Cobot", "ChangeBase_Param", "ChangeBase_ErrorID"):
        assert word in words, word
    coils = [texts(g)[0] for g in first.iter(f"{SVG}g") if "coil" in (g.get("class") or "").split()]
    assert coils == ["ChangeBase_Done", "ChangeBase_Busy", "ChangeBase_CommandAborted", "ChangeBase_Error"]


def test_contact_and_coil_variants_are_marked(tmp_path, capsys):
    src = program(tmp_path, {"A": "BOOL", "B": "BOOL", "Q": "BOOL", "R": "BOOL"},
                  [comment(9, "variants", y=-10), rail(1), contact(2, "A", 1, edge="rising"),
                   contact(3, "B", 2, negated="true"), coil(4, "Q", 3, storage="set"),
                   coil(5, "R", 3, y=40, negated="true"),
                   right(6, 4, 5)])
    out = tmp_path / "v.svg"
    assert draw(capsys, src, "--pou", "Main", "-o", out)[0] == 0
    text = out.read_text(encoding="utf-8")
    assert ">P</text>" in text and ">S</text>" in text and ">variants</text>" in text
    assert text.count('class="el contact"') == 2 and text.count('class="el coil"') == 2


def test_usage_errors_are_one_line_with_exit_2(tmp_path, capsys):
    cases = [(["nope.xml", "--pou", "Main", "-o", tmp_path / "x.svg"], "does not exist"),
             ([LIB, ROOT / "examples", "--pou", "Nope", "-o", tmp_path / "x.svg"], "no POU named `Nope`"),
             ([LIB, ROOT / "examples", "--pou", "PnP_Example", "-o", tmp_path / "x.svg"], "written in Structured Text"),
             ([LIB, ROOT / "examples", "--pou", "Commands_Example", "-o", tmp_path / "no" / "x.svg"], "cannot write"),
             ([LIB, ROOT / "examples", "--pou", "Commands_Example", "-o", tmp_path / "x.png"], "ending in .svg")]
    for args, expected in cases:
        code, _, err = draw(capsys, *args)
        assert code == 2 and expected in err and err.count("\n") == 1, err


def test_a_ladder_with_errors_is_not_drawn(tmp_path, capsys):
    src = program(tmp_path, {"Q": "BOOL"}, [rail(1), contact(2, "Strat", 1), coil(3, "Q", 2)])
    out = tmp_path / "x.svg"
    code, _, err = draw(capsys, src, "--pou", "Main", "-o", out)
    assert code == 1 and "Main:rung 1:contact Strat: error[ST1001]" in err and not out.exists()


def test_function_block_pins_carry_their_variables(tmp_path, capsys):
    src = program(tmp_path, {"A": "INT", "S": "INT"},
                  [rail(1), invar(2, "A"), invar(3, "5", y=20), block(4, "ADD", {"IN1": 2, "IN2": 3}, ["OUT"]),
                   outvar(5, "S", (4, "OUT"))])
    out = tmp_path / "f.svg"
    assert draw(capsys, src, "--pou", "Main", "-o", out)[0] == 0
    (add,) = groups(out, "block")
    assert texts(add) == ["ADD", "IN1", "A", "IN2", "5", "OUT", "S"]


def _text_extents(svg_path):
    """(x0, x1, rail_left, rail_right, text) for every name drawn between the rails of a rung, its width estimated
    as the drawer estimates it (layout.text_width: characters x CHAR_W, scaled for the 11 px and bold classes)."""
    import re

    from vplc.ladder.layout import BOLD, SMALL, text_width
    root = ET.parse(svg_path).getroot()
    out = []
    for rung in groups(svg_path, "rung"):
        rails = [p for p in rung.iter(f"{SVG}path") if p.get("class") == "rail"]
        xs = sorted(float(re.match(r"M([\d.]+) ([\d.]+)", r.get("d")).group(1)) for r in rails)
        top = float(re.match(r"M[\d.]+ ([\d.]+)", rails[0].get("d")).group(1))
        for t in rung.iter(f"{SVG}text"):
            if not t.text or float(t.get("y")) <= top:
                continue                                   # the rung number and comment stand above the rails
            cls = (t.get("class") or "").split()
            scale = SMALL if {"pin", "val", "num"} & set(cls) else BOLD if "type" in cls else 1.0
            w = text_width(t.text, scale)
            x = float(t.get("x"))
            x0 = {"start": x, "middle": x - w / 2, "end": x - w}[t.get("text-anchor") or "start"]
            out.append((x0, x0 + w, xs[0], xs[-1], t.text))
    assert root is not None and out
    return out


def test_no_name_of_the_example_crosses_a_power_rail(tmp_path, capsys):
    """Coil names such as ChangeBase_CommandAborted used to run past the right rail."""
    out = tmp_path / "commands.svg"
    assert draw(capsys, LIB, ROOT / "examples", "--pou", "Commands_Example", "-o", out)[0] == 0
    crossing = [(text, round(x0), round(x1), left, right) for x0, x1, left, right, text in _text_extents(out)
                if x0 < left + 2 or x1 > right - 2]
    assert crossing == []


def test_long_names_widen_the_rung_instead_of_crossing_the_rails(tmp_path, capsys):
    long_in, long_out = "Conveyor_Infeed_Photoeye_Blocked_Long", "Palletizer_Layer_Complete_Acknowledged"
    src = program(tmp_path, {long_in: "BOOL", "B": "BOOL", long_out: "BOOL", "Q": "BOOL", "N": "INT",
                             "Sum_Of_Everything_Counted_So_Far": "INT"},
                  [rail(1), contact(2, long_in, 1), contact(3, "B", 2), coil(4, long_out, 3), coil(5, "Q", 3, y=40),
                   invar(6, "N", y=80), invar(7, "1", y=100), block(8, "ADD", {"IN1": 6, "IN2": 7}, ["OUT"], y=80),
                   outvar(9, "Sum_Of_Everything_Counted_So_Far", (8, "OUT"), y=80)])
    out = tmp_path / "long.svg"
    assert draw(capsys, src, "--pou", "Main", "-o", out)[0] == 0
    extents = _text_extents(out)
    assert {long_in, long_out, "Sum_Of_Everything_Counted_So_Far"} <= {t for *_, t in extents}
    assert [t for x0, x1, left, right, t in extents if x0 < left + 2 or x1 > right - 2] == []
    named = sorted((x0, x1) for x0, x1, _, _, t in extents if t in (long_in, "B", long_out))
    assert all(a[1] <= b[0] for a, b in zip(named, named[1:], strict=False)), "names above one row overlap"
