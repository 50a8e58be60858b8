"""ST1009 in the sysmac dialect is an error, as Sysmac Studio refuses a POU that uses a global it does not declare
as an external variable (W501, external variables); the IEC dialect lets a POU read a global directly."""
import pytest

from vplc.api import LoadError, load_plc
from vplc.project import load_project

GLOBALS = "VAR_GLOBAL Count, Limit : INT; END_VAR\n"
USES = "PROGRAM Main\nCount := Count + Limit;\nEND_PROGRAM\n"
DECLARES = "PROGRAM Main\nVAR_EXTERNAL Count, Limit : INT; END_VAR\nCount := Count + Limit;\nEND_PROGRAM\n"


def _write(tmp_path, text):
    path = tmp_path / "main.st"
    path.write_text(GLOBALS + text, encoding="utf-8")
    return path


def test_a_global_used_without_var_external_is_an_error_naming_it(tmp_path):
    proj = load_project([str(_write(tmp_path, USES))])
    found = [d for d in proj.diagnostics if d.code == "ST1009"]
    assert [d.severity for d in found] == ["error"]
    assert "`Count`, `Limit` without VAR_EXTERNAL" in found[0].message


def test_the_program_does_not_load_in_the_sysmac_dialect_and_runs_in_the_iec_dialect(tmp_path):
    path = _write(tmp_path, USES)
    with pytest.raises(LoadError, match="ST1009"):
        load_plc([str(path)])
    plc = load_plc([str(path)], dialect="iec")
    plc.write("Limit", 2)
    plc.scan(0)
    assert plc.read("Count") == 2


def test_the_declared_program_checks_clean(tmp_path):
    assert load_project([str(_write(tmp_path, DECLARES))]).diagnostics == []
