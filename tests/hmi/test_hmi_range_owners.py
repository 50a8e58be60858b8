"""hmi/ranges.json names structures and FB inputs (docs/library/ranges.tsv). An FB whose inputs the HMI variable
table does not feed at all (CBT_SetOverride, issue 26, while the HMI has no override setting) is left out; an FB
it feeds, and every structure, must have each ranged member, so a misspelt name stays an error."""
import pytest

from cbt_hmi.web.ranges import RangeTableError, apply_ranges

ROW = [{"when": {}, "unit": "%", "error": "16#1040", "min": 5, "max": 100}]


def document():
    return {"types": {"stCBT_OutputParam": {"fields": {"Channel": {"type": "USINT"}}}},
            "variables": {"Connect_Time_Out": {"type": "UINT", "input": "CBT_Connect.Time_Out"}}}


def test_an_fb_the_hmi_does_not_drive_is_left_out():
    doc = apply_ranges(document(), {"CBT_SetOverride": {"Override": ROW}})
    assert doc == document()


def test_an_fb_the_hmi_drives_gets_its_range():
    doc = apply_ranges(document(), {"CBT_Connect": {"Time_Out": ROW}})
    assert (doc["variables"]["Connect_Time_Out"]["min"], doc["variables"]["Connect_Time_Out"]["max"]) == (5, 100)


@pytest.mark.parametrize("table,name", [({"CBT_Connect": {"TimeOut": ROW}}, "CBT_Connect.TimeOut"),
                                        ({"stCBT_OutputParam": {"Chanel": ROW}}, "stCBT_OutputParam.Chanel"),
                                        ({"stCBT_Unknown": {"X": ROW}}, "stCBT_Unknown.X")])
def test_a_member_missing_from_a_driven_fb_or_a_structure_is_an_error(table, name):
    with pytest.raises(RangeTableError, match=name.replace(".", r"\.")):
        apply_ranges(document(), table)
