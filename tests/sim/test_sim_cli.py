"""Numeric flags of the simulator's command line are range-checked before anything starts (issue 12, Low:
"--duration/--timeout accept absurd values" - the simulator's side): one line on stderr, exit code 2."""
import pytest

from tmsim import cli


@pytest.mark.parametrize("args, message", [
    (["--speedup", "nan"], "--speedup must be positive and at most 1000"),
    (["--speedup", "inf"], "--speedup must be positive and at most 1000"),
    (["--speedup", "1e9"], "--speedup must be positive and at most 1000"),
    (["--data-timeout", "-1"], "--data-timeout must be 0 (none) to 86400 seconds"),
    (["--data-timeout", "nan"], "--data-timeout must be 0 (none) to 86400 seconds"),
    (["--connection-timeout", "1e300"], "--connection-timeout must be 0 (none) to 86400 seconds"),
    (["--connection-timeout", "inf"], "--connection-timeout must be 0 (none) to 86400 seconds"),
    (["--tag-history", "0"], "--tag-history must be between 1 and 1000"),
    (["--tag-history", "10000000"], "--tag-history must be between 1 and 1000"),
    (["--control-port", "70000"], "--control-port must be 0..65535"),
    (["--port", "-1"], "leaves the port range"),
])
def test_out_of_range_number_is_one_line_error_before_anything_starts(capsys, args, message):
    assert cli.main(args + ["--port", "0"] if "--port" not in args else args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("tmflow_listener: error: ") and message in err, err
