"""``python -m vplc``: see vplc.cli."""
import sys

from .cli import main

sys.exit(main())
