"""The HMI/demo application of CBT_Commands_Lib: the `make demo` launcher (robot simulator + virtual PLC running
the examples + web HMI). It uses the toolchain (vplc) and the simulator (tmsim); neither uses it."""
