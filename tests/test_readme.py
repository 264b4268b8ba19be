"""The README is for a person with five minutes: short, plain tables, and no figure in it that a
script does not write (its headline figures are ``make figures``'s, from the same
``build/bench.json`` as ``docs/figures.md``)."""

import importlib
import re
from pathlib import Path

import pytest

from flow import figures as figures_doc

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def test_readme_is_short_and_its_table_cells_plain():
    assert len(README.splitlines()) <= 150
    long_cells = [cell for line in README.splitlines() if line.startswith("|")
                  for cell in re.split(r"(?<!\\)\|", line.strip())[1:-1] if len(cell.split()) > 40]
    assert not long_cells, long_cells


def test_readme_headlines_are_the_figures_page():
    """The README's headline figures are the ones ``docs/figures.md`` holds: none copied by
    hand, none stale (``make figures`` writes both from one ``build/bench.json``)."""
    block = README.split(figures_doc.README_BEGIN, 1)[1].split(figures_doc.README_END, 1)[0].strip()
    page_path = ROOT / "docs" / "figures.md"
    if not page_path.exists():
        # no make bench has been written out yet: then the README must quote no figure either
        assert block == "(run `make bench`, then `make figures`)", block
        pytest.skip("docs/figures.md not written yet (make bench, then make figures)")
    page = figures_doc.parse(page_path.read_text())
    assert all(name in page for _what, name in figures_doc.HEADLINES)
    assert block == figures_doc.headlines(page)


def test_quick_start_names_what_exists():
    """Every ``python -m`` module and host command the README's quick start runs exists."""
    from host import cli
    for module in set(re.findall(r"python -m ([\w.]+)", README)):
        assert importlib.util.find_spec(module) is not None, module
    commands = set(re.findall(r"-m host --address \S+ --timeout \d+ (\w+)", README))
    parser = cli._parser()
    known = next(a for a in parser._actions if a.dest == "command").choices
    assert commands and commands <= set(known), commands - set(known)
