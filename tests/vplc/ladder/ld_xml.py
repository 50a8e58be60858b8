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
    return f'<inVariable localId="{lid}">{_pos(y)}<connectionPointOut/><expression>{escape(expr)}</expression></inVariable>'


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


def document(variables: dict, body: list[str], name="Main", pou_type="program") -> str:
    vars_xml = "".join(f'<variable name="{n}"><type>{_type(t)}</type></variable>' for n, t in variables.items())
    return (HEAD + f'<types><dataTypes/><pous><pou name="{name}" pouType="{pou_type}"><interface>'
            f'<localVars>{vars_xml}</localVars></interface><body><LD>\n' + "\n".join(body) +
            '\n</LD></body></pou></pous></types><instances><configurations/></instances></project>\n')


def program(tmp_path, variables: dict, body: list[str], name="Main", file="main.xml"):
    path = tmp_path / file
    path.write_text(document(variables, body, name), encoding="utf-8")
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
