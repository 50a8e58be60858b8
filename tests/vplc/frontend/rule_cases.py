"""The snippets of every check rule: (code, a source that reports the code, the fixed source that does not).
test_fe_rules.py checks each pair; test_fe_printer.py round-trips every snippet through the printer."""
from __future__ import annotations

from fe_helpers import program

FB = """
FUNCTION_BLOCK Mover
VAR_IN_OUT CBT : INT; END_VAR
VAR_INPUT Execute : BOOL; Speed : INT; END_VAR
VAR_OUTPUT Done : BOOL; END_VAR
Done := Execute AND CBT > Speed;
END_FUNCTION_BLOCK
"""

TON_X = "FUNCTION_BLOCK TON_X VAR_INPUT IN : BOOL; END_VAR END_FUNCTION_BLOCK\n"

# (code, failing source, fixed source)
CASES = [
    ("ST1001", program("Cuont := 1;", "Count : INT;"), program("Count := 1;", "Count : INT;")),
    ("ST1002", program("Speed := 1;", "Speed : INT; Speed : REAL;"), program("Speed := 1;", "Speed : INT;")),
    ("ST1004", program("", "p : stUnknown;"), program("p := 1;", "p : INT;")),
    ("ST1005", "TYPE stP : STRUCT X : REAL; END_STRUCT; END_TYPE\n" + program("p.Z := 1.0;", "p : stP;"),
     "TYPE stP : STRUCT X : REAL; END_STRUCT; END_TYPE\n" + program("p.X := 1.0;", "p : stP;")),
    ("ST1101", program("i := r;", "i : INT; r : REAL;"), program("i := REAL_TO_INT(r);", "i : INT; r : REAL;")),
    ("ST1101", program("s := d;", "s : INT; d : DINT;"), program("d := s;", "s : INT; d : DINT;")),
    ("ST1102", program("b := s + 1;", "b : INT; s : STRING;"), program("b := LEN(s) + 1;", "b : DINT; s : STRING;")),
    ("ST1103", program("r := SQRT('x');", "r : LREAL;"), program("r := SQRT(2.0);", "r : LREAL;")),
    ("ST1105", program("IF i THEN i := 0; END_IF;", "i : INT;"), program("IF i > 0 THEN i := 0; END_IF;", "i : INT;")),
    ("ST1106", program("i := i[0];", "i : INT;"), program("i := a[0];", "i : INT; a : ARRAY[0..1] OF INT;")),
    ("ST1107", program("s := 300;", "s : SINT;"), program("s := 100;", "s : SINT;")),
    ("ST1107", program("r := 1.0E39;", "r : REAL;"), program("r := 3.4028235E38;", "r : REAL;")),
    ("ST1107", program("l := 1.0E309;", "l : LREAL;"), program("l := 1.0E308;", "l : LREAL;")),
    ("ST1107", program("r := REAL#-4.0E38;", "r : REAL;"), program("r := REAL#-3.0E38;", "r : REAL;")),
    ("ST1004", "TYPE A : STRUCT b : ARRAY[1..2] OF B; END_STRUCT; B : STRUCT a : A; END_STRUCT; END_TYPE\n"
     + program("x.b[1] := x.b[2];", "x : A;"),
     "TYPE A : STRUCT b : ARRAY[1..2] OF B; END_STRUCT; B : STRUCT n : INT; END_STRUCT; END_TYPE\n"
     + program("x.b[1].n := 1;", "x : A;")),
    ("ST1201", FB + program("m(CBT := c, Exec := TRUE);", "m : Mover; c : INT;"),
     FB + program("m(CBT := c, Execute := TRUE);", "m : Mover; c : INT;")),
    ("ST1202", FB + program("m(Execute := TRUE);", "m : Mover;"),
     FB + program("m(CBT := c, Execute := TRUE);", "m : Mover; c : INT;")),
    ("ST1203", FB + program("m(CBT := c, Done := d);", "m : Mover; c : INT; d : BOOL;"),
     FB + program("m(CBT := c, Done => d);", "m : Mover; c : INT; d : BOOL;")),
    ("ST1203", FB + program("m(CBT := c, Execute => d);", "m : Mover; c : INT; d : BOOL;"),
     FB + program("m(CBT := c, Execute := d);", "m : Mover; c : INT; d : BOOL;")),
    ("ST1204", program("i := ABS(1, 2);", "i : DINT;"), program("i := ABS(-2);", "i : DINT;")),
    ("ST1205", FB + program("m(CBT := 5);", "m : Mover;"), FB + program("m(CBT := c);", "m : Mover; c : INT;")),
    ("ST1206", program("i := LIMIT(MN := 0, i, 5);", "i : INT;"), program("i := LIMIT(0, i, 5);", "i : INT;")),
    ("ST1207", FB + program("m(CBT := c, Speed := 1, Speed := 2);", "m : Mover; c : INT;"),
     FB + program("m(CBT := c, Speed := 1);", "m : Mover; c : INT;")),
    ("ST1208", program("EXIT;", ""), program("WHILE TRUE DO EXIT; END_WHILE;", "")),
    ("ST1006", program("TON_X(IN := TRUE);", "") + TON_X, program("t(IN := TRUE);", "t : TON_X;") + TON_X),
    ("ST1301", program("Max := 5;", "END_VAR VAR CONSTANT Max : INT := 10;"),
     program("i := Max;", "i : INT; END_VAR VAR CONSTANT Max : INT := 10;")),
    ("ST1302", FB + program("m.Done := FALSE;", "m : Mover;"), FB + program("d := m.Done;", "m : Mover; d : BOOL;")),
    ("ST1303", FB + program("m(CBT := c); m.Execute := TRUE;", "m : Mover; c : INT;"),
     FB + program("m.Execute := TRUE; m(CBT := c);", "m : Mover; c : INT;")),
    ("ST1304", program("FOR i := 0 TO 9 DO i := i + 1; END_FOR;", "i : INT;"),
     program("FOR i := 0 TO 9 DO j := i + 1; END_FOR;", "i, j : INT;")),
    ("ST1401", program("CASE i OF 'a': i := 1; END_CASE;", "i : INT;"),
     program("CASE i OF 1: i := 1; END_CASE;", "i : INT;")),
    ("ST1402", program("CASE i OF 1..5: i := 1; 3: i := 2; END_CASE;", "i : INT;"),
     program("CASE i OF 1..5: i := 1; 6: i := 2; END_CASE;", "i : INT;")),
    ("ST1501", program("a[10] := 1;", "a : ARRAY[0..9] OF INT;"), program("a[9] := 1;", "a : ARRAY[0..9] OF INT;")),
    ("ST1601", program("s := 'Hello!';", "s : STRING[6];"), program("s := 'Hello';", "s : STRING[6];")),
    ("ST1701", "FUNCTION Fact : DINT VAR_INPUT n : DINT; END_VAR Fact := n * Fact(n - 1); END_FUNCTION\n",
     "FUNCTION Fact : DINT VAR_INPUT n : DINT; END_VAR VAR i : DINT; END_VAR Fact := 1; "
     "FOR i := 2 TO n DO Fact := Fact * i; END_FOR; END_FUNCTION\n"),
    ("ST1801", "FUNCTION Clamp : INT VAR_INPUT x : INT; END_VAR IF x > 100 THEN Clamp := 100; END_IF; END_FUNCTION\n",
     "FUNCTION Clamp : INT VAR_INPUT x : INT; END_VAR IF x > 100 THEN Clamp := 100; ELSE Clamp := x; END_IF; "
     "END_FUNCTION\n"),
    ("ST1901", program("Count := 1;", "Count, Spare : INT;"), program("Count := 1;", "Count : INT;")),
]
