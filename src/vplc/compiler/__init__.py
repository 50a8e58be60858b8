"""Compiler: checked AST -> Python source of one scan per program (codegen) and its expressions (codegen_expr)."""
