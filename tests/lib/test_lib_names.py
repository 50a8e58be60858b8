"""The library's interface is visible by name (issue 22 step 7): the public POUs are the files at the top of
lib/CBT_Commands_Lib and carry the public prefix CBT_; every POU of core/ and platform/ carries the internal prefix
CBTi_ (and a type of platform/ stCBTi_/eCBTi_), so a Sysmac Studio user tells the two apart in the toolbox; the
docs offer only public POUs as the library's interface."""
import re

from rig import LIB, ROOT

POU = re.compile(r"^\s*(FUNCTION_BLOCK|FUNCTION|PROGRAM)\s+(\w+)", re.M | re.I)
TYPE = re.compile(r"^\s*(\w+)\s*:\s*(?:STRUCT|\()", re.M)
INTERNAL = re.compile(r"CBTi_[A-Za-z0-9]+")
PUBLIC = re.compile(r"CBT_[A-Za-z0-9]+")
DOCS = ROOT / "docs" / "library"


COMMENT = re.compile(r"\(\*.*?\*\)|//[^\n]*", re.S)


def source(path):
    return COMMENT.sub(" ", path.read_text(encoding="utf-8"))


def pous(path):
    return [m.group(2) for m in POU.finditer(source(path))]


def top_level():
    return sorted(LIB.glob("*.st"))


def inside():
    return sorted(p for folder in ("core", "platform") for p in (LIB / folder).glob("*.st"))


def test_every_top_level_pou_is_public_and_named_after_its_file():
    found = {path.stem: pous(path) for path in top_level()}
    assert len(found) >= 20
    wrong = {stem: names for stem, names in found.items() if names != [stem] or not PUBLIC.fullmatch(stem)}
    assert wrong == {}, "top-level files must declare one public POU CBT_<Name> named after the file"


def test_every_pou_of_core_and_platform_carries_the_internal_prefix():
    wrong = [f"{path.relative_to(ROOT)}: {name}" for path in inside() for name in pous(path)
             if not INTERNAL.fullmatch(name) or name != path.stem]
    assert wrong == []
    assert sum(len(pous(path)) for path in inside()) >= 40


def test_every_type_of_platform_carries_the_internal_prefix():
    types = [(path, m.group(1)) for path in sorted((LIB / "platform").glob("*.st"))
             for m in TYPE.finditer(source(path))]
    assert types, "platform/ declares the link state types"
    assert [name for _, name in types if not re.fullmatch(r"(st|e)CBTi_[A-Za-z0-9]+", name)] == []


def test_no_internal_name_can_be_taken_for_a_public_one():
    # Sysmac Studio compares POU names without regard to case (W501 6-3-12): CBTi_ must not reduce to CBT_
    public = {path.stem.upper() for path in top_level()}
    internal = {name.upper() for path in inside() for name in pous(path)}
    assert not public & internal
    assert all(not name.startswith("CBT_") for name in internal)


def test_the_docs_offer_only_public_pous_as_the_interface():
    public = {path.stem for path in top_level()}
    pages = {path.stem for path in DOCS.glob("CBT*.md")}
    assert pages == public
    index = (DOCS / "getting_started.md").read_text(encoding="utf-8").split("\n## ")[-1]
    linked = set(re.findall(r"\[(CBTi?_\w+)\]\(", index))
    assert linked == public
