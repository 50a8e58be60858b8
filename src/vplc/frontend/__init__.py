"""Front end: source text, tokens, AST, printer, diagnostics, and the type and standard-function facts."""
