"""Write small PLCopen XML (TC6 v2.01) ladder programs for tests, as an IDE would save them.

    body = [rail(1), contact(2, "A", 1), coil(3, "Q", 2), right(4, 3)]
    path = program(tmp_path, {"A": "BOOL", "Q": "BOOL"}, body)
"""
from __future__ import annotations

from xml.sax.saxutils import escape

HEAD = ('<?xml version="1.0" encoding="utf-8"?>\n'
        '<project xmlns="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml">\n'
        '<fileHeader companyName="t" productName="t" productVersion="1" creationDateTime="2024-01-01T00:00:00"/>\n'
        '<contentHeader name="t"><coordinateInfo><fbd><scaling x="1" y="1"/></fbd><ld><scaling x="1" y="1"/></ld>'
        '<sfc><scaling x="1" y="1"/></sfc></coordinateInfo></contentHeader>\n')
ELEMENTARY = {"BOOL", "INT", "DINT", "UINT", "WORD", "REAL", "TIME", "STRING"}
_y = [0]


def _pos(y):
    return f'<position x="0" y="{y}"/>'


def _conns(*refs):
    inner = "".join(f'<connection refLocalId="{r[0]}" formalParameter="{r[1]}"/>' if isinstance(r, tuple)
                    else f'<connection refLocalId="{r}"/>' for r in refs)
    return f"<connectionPointIn>{inner}</connectionPointIn>"


def rail(lid, y=0):
    return f'<leftPowerRail localId="{lid}">{_pos(y)}<connectionPointOut formalParameter=""/></leftPowerRail>'


def right(lid, *refs, y=0):
    return f'<rightPowerRail localId="{lid}">{_pos(y)}{_conns(*refs)}</rightPowerRail>'


def contact(lid, var, *refs, y=0, **attrs):
    a = "".join(f' {k}="{v}"' for k, v in attrs.items())
    return (f'<contact localId="{lid}"{a}>{_pos(y)}{_conns(*refs)}<connectionPointOut/>'
            f'<variable>{escape(var)}</variable></contact>')


def coil(lid, var, *refs, y=0, **attrs):
    return contact(lid, var, *refs, y=y, **attrs).replace("<contact", "<coil").replace("</contact>", "</coil>")


def invar(lid, expr, y=0):
    return (f'<inVariable localId="{lid}">{_pos(y)}<connectionPointOut/><expression>{escape(expr)}</expression>'
            '</inVariable>')


def outvar(lid, expr, *refs, y=0):
    return f'<outVariable localId="{lid}">{_pos(y)}{_conns(*refs)}<expression>{escape(expr)}</expression></outVariable>'


def block(lid, type_name, inputs: dict, outputs=(), instance="", inouts: dict | None = None, y=0):
    ins = "".join(f'<variable formalParameter="{k}">{_conns(*(v if isinstance(v, list) else [v]))}</variable>'
                  for k, v in inputs.items())
    ios = "".join(f'<variable formalParameter="{k}">{_conns(v)}<connectionPointOut/></variable>'
                  for k, v in (inouts or {}).items())
    outs = "".join(f'<variable formalParameter="{k}"><connectionPointOut/></variable>' for k in outputs)
    inst = f' instanceName="{instance}"' if instance else ""
    return (f'<block localId="{lid}" typeName="{type_name}"{inst}>{_pos(y)}<inputVariables>{ins}</inputVariables>'
            f'<inOutVariables>{ios}</inOutVariables><outputVariables>{outs}</outputVariables></block>')


def jump(lid, label, *refs, y=0):
    return f'<jump localId="{lid}" label="{label}">{_pos(y)}{_conns(*refs)}</jump>'


def label(lid, name, y=0):
    return f'<label localId="{lid}" label="{name}">{_pos(y)}</label>'


def ret(lid, *refs, y=0):
    return f'<return localId="{lid}">{_pos(y)}{_conns(*refs)}</return>'


def comment(lid, text, y=0):
    return (f'<comment localId="{lid}" height="20" width="200">{_pos(y)}<content><xhtml:p>{escape(text)}</xhtml:p>'
            '</content></comment>')


def _type(t):
    if t.upper() in ELEMENTARY:
        return f"<{t.upper()}/>" if t.upper() != "STRING" else "<string/>"
    return f'<derived name="{t}"/>'


def document(variables: dict, body: list[str], name="Main", pou_type="program", externals: dict | None = None) -> str:
    """``externals``: the globals the program uses, declared as external variables (Sysmac requires them)."""
    vars_xml = "".join(f'<variable name="{n}"><type>{_type(t)}</type></variable>' for n, t in variables.items())
    ext_xml = "".join(f'<variable name="{n}"><type>{_type(t)}</type></variable>' for n, t in (externals or {}).items())
    ext = f"<externalVars>{ext_xml}</externalVars>" if externals else ""
    return (HEAD + f'<types><dataTypes/><pous><pou name="{name}" pouType="{pou_type}"><interface>'
            f'{ext}<localVars>{vars_xml}</localVars></interface><body><LD>\n' + "\n".join(body) +
            '\n</LD></body></pou></pous></types><instances><configurations/></instances></project>\n')


def program(tmp_path, variables: dict, body: list[str], name="Main", file="main.xml", externals: dict | None = None):
    path = tmp_path / file
    path.write_text(document(variables, body, name, externals=externals), encoding="utf-8")
    return path


def inoutvar(lid, expr, *refs, y=0):
    return (f'<inOutVariable localId="{lid}">{_pos(y)}{_conns(*refs)}<connectionPointOut/>'
            f'<expression>{escape(expr)}</expression></inOutVariable>')


IEC10_HEAD = ('<?xml version="1.0" encoding="utf-8"?>\n<Project xmlns="www.iec.ch/public/TC65SC65BWG7TF10" '
              'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xmlns:smcext="https://www.ia.omron.com/Smc" '
              'schemaVersion="1"><FileHeader companyName="t" productName="t" productVersion="1"/>'
              '<ContentHeader name="t" creationDateTime="2024-01-01T00:00:00"/><Types><GlobalNamespace>')


def iec10_program(variables: dict, rungs: list[str], name="Main") -> str:
    """An IEC 61131-10 program in Sysmac's ladder shape; ``rungs`` are the inner XML of each Rung."""
    vars_xml = "".join(f'<Variable name="{n}"><Type><TypeName>{t}</TypeName></Type></Variable>'
                       for n, t in variables.items())
    body = "".join(f'<Rung evaluationOrder="{i}">{r}</Rung>' for i, r in enumerate(rungs, start=1))
    return (IEC10_HEAD + f'<Program name="{name}"><Vars accessSpecifier="private">{vars_xml}</Vars><MainBody>'
            f'<BodyContent xsi:type="smcext:LdSection" name="S" evaluationOrder="1">{body}</BodyContent>'
            '</MainBody></Program></GlobalNamespace></Types><Instances/></Project>\n')


# One program holding every ladder element kind (the round-trip and schema tests of the LD readers and writers)
ALL_KINDS = {"A": "BOOL", "B": "BOOL", "C": "BOOL", "Q1": "BOOL", "Q2": "BOOL", "Latch": "BOOL", "Pulse": "BOOL",
             "Up": "BOOL", "Down": "BOOL", "Run": "BOOL", "T": "TON", "Et": "TIME", "N": "INT", "Sum": "INT",
             "Skip": "BOOL", "Mid": "BOOL", "Stop": "BOOL", "Last": "BOOL", "Eno": "BOOL"}
ALL_BODY = [comment(90, "series, parallel, NC", y=-20), rail(1), contact(2, "A", 1), contact(3, "B", 1, y=20),
            contact(4, "C", 2, 3, negated="true"), coil(5, "Q1", 4), coil(6, "Q2", 4, y=20, negated="true"),
            right(7, 5, 6),
            contact(10, "A", 1, y=100, edge="rising"), coil(11, "Latch", 10, y=100, storage="set"),
            contact(12, "B", 1, y=120, edge="falling"), coil(13, "Latch", 12, y=120, storage="reset"),
            contact(14, "C", 1, y=140), coil(15, "Pulse", 14, y=140, edge="rising"),
            contact(20, "Run", 1, y=200), contact(21, "C", 1, y=220),
            block(22, "TON", {"EN": 20, "IN": 21, "PT": 23}, ["ENO", "Q", "ET"], instance="T", y=200),
            invar(23, "T#2ms", y=240), coil(24, "Eno", (22, "ENO"), y=200), coil(25, "Up", (22, "Q"), y=220),
            outvar(26, "Et", (22, "ET"), y=240),
            invar(30, "N", y=300), invar(31, "7", y=310), block(32, "ADD", {"IN1": 30, "IN2": 31}, ["OUT"], y=300),
            outvar(33, "Sum", (32, "OUT"), y=300),
            contact(40, "Skip", 1, y=400), jump(41, "After", 40, y=400),
            contact(42, "A", 1, y=420), coil(43, "Mid", 42, y=420),
            label(44, "After", y=440), contact(45, "Stop", 1, y=460), ret(46, 45, y=460),
            contact(47, "B", 1, y=480), coil(48, "Last", 47, y=480), coil(49, "Down", 47, y=490, negated="true")]
