"""Commands shown to users run on a stock Debian, which has `python3` and no `python`: every doc page, docstring
and example names the interpreter `python3`."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BARE = re.compile(r"(^|[^A-Za-z0-9_./-])python (-m |sim/|examples/|bench/|docs/)", re.M)


def test_no_user_facing_command_uses_bare_python():
    places = [ROOT / "README.md", *ROOT.glob("docs/**/*.md")]
    for folder in ("src", "sim", "examples", "bench", "docs"):
        places += [p for p in (ROOT / folder).rglob("*") if p.suffix in (".py", ".st", ".md", ".scn", ".js", ".html")]
    offenders = [f"{p.relative_to(ROOT)}:{text[:m.start()].count(chr(10)) + 1}"
                 for p in set(places) for text in [p.read_text(encoding="utf-8", errors="replace")]
                 for m in BARE.finditer(text)]
    assert offenders == [], "write python3: " + ", ".join(sorted(offenders))
