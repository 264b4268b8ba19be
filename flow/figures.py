"""``make figures``: ``docs/figures.md`` from ``build/bench.json``, a table per figure prefix,
and the README's headline figures.

``build/bench.json`` is what ``make bench`` writes (:mod:`flow.bench`): every figure with its
value, unit and source. The prefix is a figure name's part before its first dot (``eth``,
``seq``, ``sys``, ``store``, ...); each table lists its figures in name order with their value,
unit and source. The README quotes a few of them (:data:`HEADLINES`) between its markers, so that
no figure in it is copied by hand; a test holds the README's block to ``docs/figures.md``.

Any page under ``docs/`` (and the README) may quote a figure in its text between two markers::

    <!-- figure seq.gray8_rate_hz_dlp7000:.1f Hz -->302.1 Hz<!-- /figure -->

The opening marker names the figure, then optionally ``:`` and a Python format spec (``.1f``,
``,.0f``, ``.1%`` for a fraction as a percentage, written ``97.2 %``), then optionally the unit
to write after the value. ``make figures`` rewrites the text between the markers in every page
(:func:`quote`); a figure the last run did not give is written as :data:`PLACEHOLDER`. The value
formatted is the one ``docs/figures.md`` shows (six significant digits), so a page's figure can be
checked against that page alone.
"""

import json
import re
from pathlib import Path

__all__ = ["render", "write", "main", "HEADER", "HEADLINES", "headlines", "parse", "README_BEGIN", "README_END",
           "MARKER", "PLACEHOLDER", "markers", "quote", "quoted", "recorded"]

HEADER = ("Written by `python -m flow figures` from `build/bench.json` (the output of `make bench`); "
          "do not edit by hand.")


#: The figures the README quotes: (what it is, figure name).
HEADLINES = (
    ("8-bit frames back to back on the DLP7000 at DCLK 400 MHz, on the pins", "sys.xga_rate_hz_measured"),
    ("the same, the schedule model's period for the plan", "sys.xga_rate_hz_model"),
    ("trigger pin to the first clocking pulse, worst", "sys.xga_trigger_latency_cycles_worst"),
    ("grey error of every frame under the camera model, largest", "sys.xga_gray_error_lsb_max"),
    ("a new frame at every trigger, streamed as deltas over GigE", "sys.xga_new_frames_per_s_streamed"),
    ("the same, every frame whole (GigE-bound)", "sys.xga_new_frames_per_s_streamed_whole"),
    ("binary patterns from the store while GigE writes, slowest period", "seq.binary_rate_hz_memory"),
    ("8-bit frames back to back on the DLP9500 (one memory bank), on the pins", "sys.dlp9500_rate_hz_measured"),
)
README_BEGIN, README_END = "<!-- headline figures: written by make figures -->", "<!-- end of headline figures -->"

#: A figure quoted in a page: ``<!-- figure NAME[:SPEC][ UNIT] -->text<!-- /figure -->``.
MARKER = re.compile(r"<!-- figure (?P<name>[A-Za-z_][\w.]*)(?::(?P<spec>[^\s>]+))?(?: (?P<unit>[^<>]*?))? -->"
                    r"(?P<text>.*?)<!-- /figure -->")
#: What a marker holds when the last ``make bench`` did not give its figure.
PLACEHOLDER = "(run make bench)"


def headlines(figures):
    """The README's block of :data:`HEADLINES` from ``figures`` (as :func:`render` takes them);
    a figure the run did not give is said to be missing."""
    lines = ["| what | figure | value |", "|---|---|---|"]
    for what, name in HEADLINES:
        entry = figures.get(name)
        value = "missing from the last make bench" if entry is None else \
            f"{_cell(_value(entry.get('value')))} {_cell(entry.get('unit', ''))}".strip()
        lines.append(f"| {what} | `{name}` | {value} |")
    return "\n".join(lines)


def parse(markdown):
    """The figures of a page :func:`render` wrote: ``{name: {"value", "unit", "source",
    "commit"}}``, the values as the page shows them (text)."""
    figures = {}
    for line in markdown.splitlines():
        if line.startswith("| `"):
            cells = [_uncell(cell.strip()) for cell in re.split(r"(?<!\\)\|", line)[1:-1]]
            if len(cells) == 5:
                name, value, unit, source, commit = cells
                figures[name.strip("`")] = {"value": value, "unit": unit, "source": source,
                                            "commit": commit.strip("`")}
    return figures


def recorded(markdown):
    """The figures of a page :func:`render` wrote as ``build/bench.json`` holds them: each value a
    number again (six significant digits, as the page shows it), with its unit, source and commit.
    A ``--merge`` run of ``make bench`` in a clone without ``build/bench.json`` starts from these."""
    out = {}
    for name, entry in parse(markdown).items():
        entry = dict(entry, value=_shown(entry["value"]))
        if entry["commit"] in ("", "not recorded"):
            del entry["commit"]
        out[name] = entry
    return out


def _cell(text):
    """``text`` fit for a Markdown table cell."""
    return str(text).replace("\\", "\\\\").replace("|", "\\|").replace("\n", " ")


def _uncell(text):
    """A Markdown table cell's text as :func:`_cell` was given it."""
    return re.sub(r"\\(.)", r"\1", text)


def _value(value):
    if isinstance(value, bool) or not isinstance(value, float):
        return str(value)
    return f"{value:.6g}"


def _shown(value):
    """``value`` as ``docs/figures.md`` shows it (:func:`_value`), read back as a number."""
    text = _value(value)
    if text in ("True", "False"):
        return text == "True"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def quoted(entry, spec=None, unit=None):
    """The text a marker holds for the figure ``entry`` (``{"value", ...}`` as :func:`render` or
    :func:`parse` give it, or None: :data:`PLACEHOLDER`), formatted by ``spec``, then ``unit``."""
    if entry is None:
        return PLACEHOLDER
    value = _shown(entry.get("value"))
    if not spec:
        text = _value(value)
    elif spec.endswith("%"):
        text = f"{value * 100:{spec[:-1]}f} %"
    else:
        text = format(value, spec)
    return f"{text} {unit}" if unit else text


def markers(text):
    """Every figure ``text`` quotes: ``[(name, spec, unit, text between the markers)]``."""
    return [(m["name"], m["spec"], m["unit"], m["text"]) for m in MARKER.finditer(text)]


def quote(text, figures):
    """``text`` with every marker's figure written from ``figures`` (as :func:`render` takes
    them); ValueError naming the marker if its spec does not fit its figure."""
    def one(match):
        try:
            value = quoted(figures.get(match["name"]), match["spec"], match["unit"])
        except (TypeError, ValueError) as error:
            raise ValueError(f"{match[0]}: {error}") from error
        return match[0][:match.start("text") - match.start()] + value + "<!-- /figure -->"
    return MARKER.sub(one, text)


def _commits(figures):
    """The commits the figures were measured on (``make bench`` records each figure's; a
    ``--merge`` run leaves the figures it did not measure with theirs), and how many each."""
    counts = {}
    for entry in figures.values():
        counts[entry.get("commit") or "not recorded"] = counts.get(entry.get("commit") or "not recorded", 0) + 1
    return "Measured on commit " + ", ".join(f"`{commit}` ({n} figures)" for commit, n in
                                             sorted(counts.items(), key=lambda item: -item[1])) + "."


def render(figures):
    """The Markdown of ``figures`` (``{name: {"value", "unit", "source"}}``)."""
    groups = {}
    for name in sorted(figures):
        groups.setdefault(name.split(".", 1)[0], []).append(name)
    lines = ["# Figures", "", HEADER, "", _commits(figures), ""]
    for prefix in sorted(groups):
        lines += [f"## {prefix}", "", "| figure | value | unit | source | commit |", "|---|---|---|---|---|"]
        for name in groups[prefix]:
            entry = figures[name]
            commit = entry.get("commit") or "not recorded"
            lines.append(f"| `{_cell(name)}` | {_cell(_value(entry.get('value')))} | {_cell(entry.get('unit', ''))} "
                         f"| {_cell(entry.get('source') or '(no source)')} | `{commit}` |")
        lines.append("")
    return "\n".join(lines)


def write(bench="build/bench.json", out="docs/figures.md", readme=None, pages=None):
    """Read ``bench`` and write ``out``, the headline block of ``readme`` if given (between its
    markers), and the figures quoted in ``readme`` and in every ``*.md`` page of the folder
    ``pages`` if given (:func:`quote`; ``out`` itself left as written); returns the path of
    ``out``. FileNotFoundError if ``bench`` is missing (``make bench`` writes it): then no page is
    touched."""
    bench, out = Path(bench), Path(out)
    if not bench.is_file():
        raise FileNotFoundError(f"{bench} not found: run `make bench` (python -m flow bench) first, it writes "
                                f"the figures {out} is made from")
    figures = json.loads(bench.read_text())
    if not isinstance(figures, dict) or not all(isinstance(v, dict) and "value" in v for v in figures.values()):
        raise ValueError(f"{bench} is not a bench.json of make bench: {{figure: {{value, unit, source}}}}")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(render(figures))
    if readme is not None and Path(readme).is_file():
        readme = Path(readme)
        text = readme.read_text()
        if README_BEGIN in text and README_END in text:
            head, rest = text.split(README_BEGIN, 1)
            _, tail = rest.split(README_END, 1)
            readme.write_text(f"{head}{README_BEGIN}\n{headlines(figures)}\n{README_END}{tail}")
    quoting = [Path(readme)] if readme is not None and Path(readme).is_file() else []
    if pages is not None:
        quoting += [page for page in sorted(Path(pages).glob("*.md")) if page.resolve() != out.resolve()]
    for page in quoting:
        text = page.read_text()
        new = quote(text, figures)
        if new != text:
            page.write_text(new)
    return out


def main(bench="build/bench.json", out="docs/figures.md", readme="README.md", pages="docs"):
    path = write(bench, out, readme, pages)
    print(f"wrote {path}, the headline figures of {readme} and the figures quoted in {readme} and {pages}/*.md")
    return 0
