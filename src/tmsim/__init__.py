"""TMflow Listen Node simulator: codec (pure), session (sans-I/O), script language, robot model, server."""
