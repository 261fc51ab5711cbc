"""The flag tables of README.md and the user manual say what the programs'
--help says: every flag of fishtank-server, fishtank-viewer and fishtank-client
has a row in the manual, no row names a flag the program lacks, and each
table's default is the one --help states. A flag added to a program therefore
needs only a row in the manual's table (and in the README's, if a newcomer
needs it)."""

import re
import subprocess

import pytest

from conftest import DOCS, markdown, program

# Each flag table, the heading it sits under and the program it describes.
# complete: every flag of --help has a row (the README keeps a newcomer's selection).
TABLES = [
    ("README.md", "### Server flags", "fishtank-server", False),
    ("docs/user-manual.md", "## Server options", "fishtank-server", True),
    ("docs/user-manual.md", "### Viewer options", "fishtank-viewer", True),
    ("docs/user-manual.md", "## The test client", "fishtank-client", True),
]
IMPLICIT = {"help"}  # every program has it; a table need not repeat it

# boost::program_options' layout: "  -h [ --help ]  text", "  --port arg (=7878)  text",
# continuation lines indented further.
FLAG_LINE = re.compile(r"^  (?:-\w \[ )?--([\w-]+)(?: \])?(?: arg)?(?: \(=(.*?)\))?(?:\s+(.*))?$")
# A default given in the text instead: "(default 60; ...)", "(default: the scene's, ...)", "(default 0: stay open)".
TEXT_DEFAULT = re.compile(r"\(default:?\s+(.+?)(?:[,;)]|: |$)")


def help_flags(name):
    """{flag: default or None} from the program's --help."""
    out = subprocess.run([str(program(name)), "--help"], capture_output=True, text=True, timeout=30)
    assert out.returncode == 0, out.stderr
    flags, text, current = {}, {}, None
    for line in out.stdout.splitlines():
        m = FLAG_LINE.match(line)
        if m:
            current = m.group(1)
            flags[current] = m.group(2)
            text[current] = m.group(3) or ""
        elif current and line.startswith("    ") and line.strip():
            text[current] += " " + line.strip()
        else:
            current = None
    for flag, description in text.items():
        found = TEXT_DEFAULT.search(" ".join(description.split()))  # a wrap can leave two spaces
        if flags[flag] is None and found:
            flags[flag] = found.group(1).strip()
    assert flags, f"no flags found in {name} --help:\n{out.stdout}"
    return flags


def table_under(doc, heading):
    """The first Markdown table after the heading, before the next heading: a list of {column: cell}."""
    lines = markdown(doc).splitlines()
    start = lines.index(heading)
    rows, header = [], None
    for line in lines[start + 1:]:
        if line.startswith("#"):
            break
        if not line.startswith("|"):
            if header:
                break
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if header is None:
            header = [c.lower() for c in cells]
        elif not set("".join(cells)) <= set("-: "):
            rows.append(dict(zip(header, cells)))
    assert rows, f"no table under '{heading}' in {doc}"
    return rows


def row_flags(row):
    return re.findall(r"--([\w-]+)", row["flag"])


def table_id(table):
    return f"{table[0]} {table[1]}"


@pytest.mark.parametrize("table", TABLES, ids=table_id)
def test_every_row_names_a_flag_that_the_program_has(table):
    doc, heading, name, _ = table
    flags = help_flags(name)
    for row in table_under(doc, heading):
        for flag in row_flags(row):
            assert flag in flags, f"{doc} '{heading}' lists --{flag}, which {name} --help does not"


@pytest.mark.parametrize("table", [t for t in TABLES if t[3]], ids=table_id)
def test_every_flag_of_help_has_a_row(table):
    doc, heading, name, _ = table
    listed = {f for row in table_under(doc, heading) for f in row_flags(row)}
    missing = sorted(set(help_flags(name)) - listed - IMPLICIT)
    assert not missing, f"{name} --help has " + ", ".join("--" + f for f in missing) + f", missing from {doc} '{heading}'"


@pytest.mark.parametrize("table", TABLES, ids=table_id)
def test_each_default_is_the_one_help_states(table):
    """A table's default starts with --help's, and may explain it after: '0 (automatic)'."""
    doc, heading, name, _ = table
    flags = help_flags(name)
    for row in table_under(doc, heading):
        assert "default" in row, f"{doc} '{heading}' has no default column"
        cell = row["default"].replace("`", "")
        for i, flag in enumerate(row_flags(row)):
            stated = flags.get(flag)
            if i > 0:  # a row naming several flags (--pause / --resume) gives no default for the later ones
                assert stated is None, f"{doc}: --{flag} has a default (={stated}); give it a row of its own"
            elif stated is None:
                assert cell == "", f"{doc} '{heading}': --{flag} has no default in --help, the table says '{cell}'"
            else:
                assert re.match(re.escape(stated) + r"(\W|$)", cell), \
                    f"{doc} '{heading}': --{flag} defaults to '{stated}' in --help, the table says '{cell}'"


def test_every_flag_table_in_the_docs_is_checked_here():
    checked = {(doc, heading) for doc, heading, _, _ in TABLES}
    for doc in DOCS:
        heading = None
        for line in markdown(doc).splitlines():
            if line.startswith("#"):
                heading = line
            elif re.match(r"\|\s*flag\s*\|", line):
                assert (doc, heading) in checked, f"{doc} '{heading}' has a flag table this test does not check"


def test_the_readme_points_to_the_manual_for_every_flag():
    readme = markdown("README.md")
    section = readme[readme.index("### Server flags"):]
    section = section[:section.index("\n#", 1)]
    assert "docs/user-manual.md" in section and "every" in section
