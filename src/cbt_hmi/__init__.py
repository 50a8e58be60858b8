"""The HMI/demo application of CBT_Commands_Lib: the `make demo` launcher (robot simulator + virtual PLC running
the examples + web HMI). It uses the toolchain's public API (vplc.api) and the simulator (tmsim); neither uses it.

    web/     the HMI's HTTP server (cbt_hmi.web.server.HmiServer)
    pages/   the pages it serves, the PLC-HMI variable table and the generated error and range tables
             (package data: found through the package, installed or not)
"""
import pathlib

PAGES = pathlib.Path(__file__).resolve().parent / "pages"
