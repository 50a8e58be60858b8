"""Ladder blocks Sysmac names by their symbols (W502 2-87, 2-89): `<`, `=`, `+` ... run as LT, EQ, ADD ..."""
from ld_run import Run
from ld_xml import block, coil, invar, outvar, rail, right


def test_symbol_blocks_compare_and_add_like_their_iec_names(tmp_path):
    body = [rail(1), invar(2, "A"), invar(3, "B", y=10), block(4, "&lt;", {"In1": 2, "In2": 3}, ["Out"]),
            coil(5, "Less", (4, "Out")), right(6, 5),
            invar(7, "A", y=40), invar(8, "B", y=50), block(9, "=", {"In1": 7, "In2": 8}, ["Out"], y=40),
            coil(10, "Same", (9, "Out"), y=40),
            invar(11, "A", y=80), invar(12, "B", y=90), block(13, "+", {"In1": 11, "In2": 12}, ["Out"], y=80),
            outvar(14, "Sum", (13, "Out"), y=80),
            invar(15, "A", y=120), invar(16, "B", y=130), block(17, "-", {"In1": 15, "In2": 16}, ["Out"], y=120),
            outvar(18, "Diff", (17, "Out"), y=120)]
    r = Run.of(tmp_path, {"A": "INT", "B": "INT", "Less": "BOOL", "Same": "BOOL", "Sum": "INT", "Diff": "INT"}, body)
    r.scan(A=3, B=4)
    assert (r["Less"], r["Same"], r["Sum"], r["Diff"]) == (True, False, 7, -1)
    r.scan(A=4, B=4)
    assert (r["Less"], r["Same"], r["Sum"], r["Diff"]) == (False, True, 8, 0)


def test_a_ctd_block_with_the_iec_pin_ld_loads_the_counter(tmp_path):
    """W502 2-134 names the input Load; a ladder drawn with IEC's LD pin means the same input."""
    body = [rail(1), invar(2, "Pulse"), invar(3, "Reload", y=10), invar(4, "3", y=20),
            block(5, "CTD", {"CD": 2, "LD": 3, "PV": 4}, ["Q", "CV"], instance="Down"),
            outvar(6, "Left", (5, "CV"))]
    r = Run.of(tmp_path, {"Pulse": "BOOL", "Reload": "BOOL", "Left": "INT", "Down": "CTD"}, body)
    assert r.scan(Reload=True)["Left"] == 3
    r.scan(Reload=False)
    assert r.scan(Pulse=True)["Left"] == 2
