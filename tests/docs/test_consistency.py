"""README.md and the user manual tell the same story: the same programs, as
many as the manual says it is made of."""

import os
import re

from conftest import markdown

NUMBERS = {"five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10, "eleven": 11, "twelve": 12}


def program_table(doc, heading):
    text = markdown(doc)
    section = text[text.index(heading):]
    rows = re.findall(r"^\| `([^`]+)`", section[:section.index("\n#", 1)], re.M)
    return {os.path.basename(r) for r in rows}


def test_the_readme_and_the_manual_list_the_same_programs_and_the_manual_counts_them():
    readme = program_table("README.md", "## Programs")
    manual = program_table("docs/user-manual.md", "## What it is")
    assert readme == manual
    said = re.search(r"It is made of (\w+) programs", markdown("docs/user-manual.md"))
    assert said and NUMBERS.get(said.group(1)) == len(manual), f"the manual says {said and said.group(1)}"
