"""vplc — an open IEC 61131-3 Structured Text toolchain: front end (parse, check), compiler and virtual PLC."""

__version__ = "0.1.0"
