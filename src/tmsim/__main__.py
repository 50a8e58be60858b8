"""`python3 -m tmsim`: the simulator's command line (the same as the console script `tmflow-sim`)."""
from tmsim.cli import main

raise SystemExit(main())
