"""`python3 -m cbt_hmi`: the demo (the same as the console script `cbt-demo` and `make demo`)."""
from .demo import main

raise SystemExit(main())
