"""Ladder Diagram: load LD POUs from PLCopen XML (TC6 v2.01) and IEC 61131-10 XML into the same front end as
Structured Text, draw them, monitor them live and write them back (docs/toolchain/ladder.md).

    model         the rung graph every stage shares
    xmlsafe       standard-library XML parsing with bomb / external-entity / size protection
    plcopen_read  iec10_read     the two readers (XML -> declarations + ladder model)
    translate     declarations + ladder -> ST text with element regions for diagnostics
    load          the front end's entry (read_xml) and the ladder-only type rule
    layout  svg   the computed rung layout and its SVG drawing (vplc draw, the HMI's Program page)
    iec10_write  plcopen_write   ladder bodies for the two export formats
"""
