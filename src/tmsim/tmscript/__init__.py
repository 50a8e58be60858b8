"""The TM script language as the simulated robot runs it: parser, static check, interpreter, the one table of
functions and data formats, the TMflow version profiles and the work meter that bounds a turn."""
