"""Command line: ``python3 -m vplc`` (main: registry and ``check``; run; test)."""
