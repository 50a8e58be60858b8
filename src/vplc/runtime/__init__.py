"""Back end of the virtual PLC: IEC value semantics, standard library, Sysmac instructions, scan loop."""
