"""``python3 -m vplc``: see vplc.cli.main."""
import sys

from .cli.main import main

sys.exit(main())
