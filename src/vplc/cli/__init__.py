"""Command line: ``python -m vplc`` (main: registry and ``check``; run; test)."""
