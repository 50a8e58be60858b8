"""Signal traces of a running PLC: record variables every scan, write VCD (GTKWave) or an SVG timing diagram."""
from .recorder import Recorder, write_trace

__all__ = ["Recorder", "write_trace"]
