"""The library's ST unit tests (tests/lib/st_unit, TcUnit style) through `vplc test`, as a PLC engineer runs them."""
import subprocess
import sys
import xml.etree.ElementTree as ET

from rig import LIB, ROOT

UNIT = ROOT / "tests" / "lib" / "st_unit"


def test_codec_suite_passes_and_writes_junit(tmp_path):
    junit = tmp_path / "codec.xml"
    r = subprocess.run([sys.executable, "-m", "vplc", "test", str(LIB), str(UNIT), "--junit", str(junit)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.strip().splitlines()[-1] == "10 passed, 0 failed"
    cases = ET.parse(junit).getroot().iter("testcase")
    assert sorted(c.get("name") for c in cases)[:2] == ["CheckMotion_applies_the_ranges_of_the_data_format",
                                                         "Checksum_is_the_XOR_of_the_range"]
