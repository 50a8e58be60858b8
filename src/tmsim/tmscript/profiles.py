"""TMflow version profiles: which TMflow release the simulated robot runs, and our choices where the manual
is silent. ``--tmflow 1.8`` / ``--tmflow 2.24`` on the command line; docs/simulator.md has the table."""
from __future__ import annotations

from dataclasses import dataclass

VERSIONS = ("1.8", "2.24")
STOP_TAGS = ("forget", "reached")


@dataclass(frozen=True)
class Profile:
    tmflow: str = "2.24"            # TMscript function set and formats of this TMflow release
    stop_tags: str = "forget"       # what a stop does to the queue tags it drops, see tmsim.robot.model.STOP_TAGS
    tag_history: int = 4            # queue tags whose status the robot keeps (TMscript 2.24 §13.2: four)

    def __post_init__(self):
        if self.tmflow not in VERSIONS:
            raise ValueError(f"TMflow version {self.tmflow!r} is not one of {', '.join(VERSIONS)}")
        if self.stop_tags not in STOP_TAGS:
            raise ValueError(f"stop tags {self.stop_tags!r} is not one of {', '.join(STOP_TAGS)}")
        if self.tag_history < 1:
            raise ValueError(f"tag history must be at least 1, got {self.tag_history}")
