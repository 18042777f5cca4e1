"""Every number the documentation publishes has an entry in the claims table, docs/claims.toml,
and the entry says what backs it (docs/testing.md, "The claims table", explains the format).

What counts as a number: in the prose of README.md and of every page docs/*.md, every token that
starts with a digit and is not preceded by a letter, digit, underscore, dot or caret, with its
decimals, thousands commas and exponent (`2e-12`, `1,035`, `0.2`, `64` in `dt/64`, `10` in
`10x`). Not prose, so never a number here: fenced code blocks, inline code spans, link targets
and image paths (the `(...)` after `]`), URLs, HTML comments (the engine page's stage table
comes from planarsim/kernels/stages.py through such a marker) and mkdocs snippet markers (a
page that includes README's section or the committed benchmark result shows that file; README is
checked here, and a result file is its own backing). Digits inside a name are not numbers
(`chain4`, `rattle4`, `float64`, `MP4`, `V1`: preceded by a letter), nor an exponent after `^`
(`dt^2`: the formula's base is). The allow-rules, all of them:

- the numbering of an ordered list or a heading (`1. Its rows ...`, `### 8. Positions`), and
  a reference to the engine's numbered stages (`stage 7`, `stages 4 and 5`, `stages 1-9`);
- a year: a four-digit integer from 1900 to 2099 (`Kelly 2014`, `IJRR 1998`);
- the names in NAMES (`2D`, `2-D`, `x86-64`), which carry digits but are not figures.

Every other number, however small, needs an entry: a count of walkers in digits, a dt in an
example, a version, a measured time. An entry names its page, the figure as written (`number`,
with a few words around it where the same figure stands on the page with another meaning) or a
whole table (`table`: its header row; every number in the rows below it), a short `what`, and exactly one
backing: `test` (a test function, path::name, that asserts the figure at the stated bound or
tighter), `result` (a committed file written by a benchmark that holds every number the
entry covers, as written or rounded as the page prints it, and `command`, the command that
writes it), or `kind`: "definition" or "input" (a number that is set, not measured: a
parameter, a default, a dt, a version, a count of things named, a date), "cited" (a figure
from a paper, with `source`) or "measured-once" (a figure from one run by hand, which its page
says was measured, with `command` and `measured`: when and where).

An entry covers every number inside each place its text stands on its page (words matched
across line breaks, inline code ignored); one entry per figure and page.

The test fails naming page, line and number for a number without an entry, for an entry whose
figure is no longer on its page, for a test that does not exist, for a result file that does
not hold the figure, and for a figure "measured-once" whose paragraph does not say it was
measured. It runs no physics."""
import ast
import functools
import re
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TABLE = ROOT / "docs" / "claims.toml"
PAGES = ["README.md"] + sorted(f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md"))
NAMES = ("2D", "2-D", "x86-64")
# every measured figure has a test or a committed result: a run by hand is committed under
# benchmarks/results/ before a page quotes it (there is no kind for a figure measured once)
KINDS = {"definition", "input", "cited"}
# pages whose entries are still being written: their numbers are not enforced yet
PENDING: set[str] = set()

NUMBER = re.compile(r"(?<![\w.^])\d+(?:,\d{3})*(?:\.\d+)?(?:[eE][-+]?\d+)?")


def _blank(text, start, end):
    return text[:start] + re.sub(r"[^\n]", " ", text[start:end]) + text[end:]


@functools.lru_cache(maxsize=None)
def prose(text):
    """The page with everything that is not prose blanked out, offsets and lines kept."""
    for pattern in (r"(?s)^ *```.*?^ *```[^\n]*$",        # fenced code blocks
                    r"(?s)<!--.*?-->",                      # HTML comments (and the stage table's marker)
                    r"^.*--8<--.*$",                        # snippet markers and includes
                    r"``(?:[^\n]|\n(?!\n))+?``|`(?:[^`\n]|\n(?!\n))+`",   # inline code (may wrap a line)
                    r"\]\([^)\s]*\)",                       # link targets and image paths
                    r"https?://\S+"):                       # bare URLs
        for m in reversed(list(re.finditer(pattern, text, re.M))):
            text = _blank(text, m.start(), m.end())
    for name in NAMES:
        text = re.sub(rf"(?<![\w.]){re.escape(name)}(?!\w)", " " * len(name), text)
    return text


def allowed(text, m):
    """The allow-rules: ordered-list and heading numbering, the engine's stage numbers, years."""
    line_start = text.rfind("\n", 0, m.start()) + 1
    before = text[line_start:m.start()]
    if re.fullmatch(r" *(#+ +)?", before) and text[m.end():m.end() + 2] == ". ":
        return True
    if re.search(r"\bstages? (\d+(-| and ))?$", text[max(0, m.start() - 20):m.start()], re.I):
        return True
    return re.fullmatch(r"(19|20)\d\d", m.group()) is not None


@functools.lru_cache(maxsize=None)
def numbers(text):
    """(offset, token) of every number in the prose of a page's text."""
    clean = prose(text)
    return clean, [(m.start(), m.end(), m.group()) for m in NUMBER.finditer(clean) if not allowed(clean, m)]


def line_of(text, offset):
    return text.count("\n", 0, offset) + 1


@functools.lru_cache(maxsize=None)
def _table():
    return tomllib.loads(TABLE.read_text())["claim"]


def load():
    return _table()


def spans(clean, entry):
    """Where an entry's figure (or table) stands in the page's prose: (start, end) pairs."""
    if "table" in entry:                    # the rows under the header and its |---| line
        at = clean.find(entry["table"])
        if at < 0:
            return []
        rows = clean.find("\n", clean.find("\n", at) + 1) + 1
        end = clean.find("\n\n", at)
        return [(rows, len(clean) if end < 0 else end)]
    words = [re.escape(w) for w in re.sub(r"`[^`]+`", " ", entry["number"]).split()]   # code: blank
    pattern = r"(?<![\w.])" + r"\s+".join(words) + r"(?![\w]|[.,]\d)"
    return [(m.start(), m.end()) for m in re.finditer(pattern, clean)]


def test_the_claims_table_reads_and_every_entry_has_one_backing():
    problems = []
    seen = set()
    for i, e in enumerate(load()):
        name = f"entry {i + 1} ({e.get('page')}: {e.get('number', e.get('table'))!r})"
        if e.get("page") not in PAGES:
            problems.append(f"{name}: no such page")
        if ("number" in e) == ("table" in e):
            problems.append(f"{name}: give `number` or `table`, one of them")
        if not e.get("what"):
            problems.append(f"{name}: says not `what` it is")
        backings = [k for k in ("test", "result", "kind") if k in e]
        if len(backings) != 1:
            problems.append(f"{name}: needs exactly one of test / result / kind, has {backings}")
        if e.get("kind") not in KINDS | {None}:
            problems.append(f"{name}: kind {e['kind']!r} is not one of {sorted(KINDS)}")
        if "result" in e and not e.get("command"):
            problems.append(f"{name}: a measured figure needs the `command` that measures it")
        if e.get("kind") == "cited" and not e.get("source"):
            problems.append(f"{name}: a cited figure needs its `source`")
        key = (e.get("page"), e.get("number", e.get("table")))
        if key in seen:
            problems.append(f"{name}: a second entry for the same figure on the same page")
        seen.add(key)
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("page", [p for p in PAGES if p not in PENDING])
def test_every_number_on_the_page_has_an_entry(page):
    text = (ROOT / page).read_text()
    clean, found = numbers(text)
    covered = [s for e in load() if e.get("page") == page for s in spans(clean, e)]
    missing = [f"{page}:{line_of(text, a)}: {tok!r} in "
               f"{' '.join(text.splitlines()[line_of(text, a) - 1].split())[:100]!r}"
               for a, b, tok in found if not any(s <= a and b <= t for s, t in covered)]
    assert not missing, (f"{len(missing)} number(s) of {page} without an entry in docs/claims.toml:\n"
                         + "\n".join(missing))


def test_no_entry_is_stale():
    """Each entry's figure (or table) still stands in its page's prose."""
    stale = []
    for e in load():
        page = ROOT / e["page"]
        if page.exists() and not spans(prose(page.read_text()), e):
            stale.append(f"{e['page']}: {e.get('number', e.get('table'))!r} is no longer on the page")
    assert not stale, "\n".join(stale)


def _as_printed(token, figure):
    """Whether `figure` (a number in a result file) is `token` (a number on a page) as the page
    prints it: equal, or rounded to the token's decimals (significant figures for 1.4e-12)."""
    token, figure = token.replace(",", ""), figure.replace(",", "")
    if token == figure:
        return True
    mantissa, _, exponent = token.lower().partition("e")
    if exponent:
        digits = len(mantissa.replace(".", "").lstrip("0")) - 1
        return f"{float(figure):.{digits}e}" == f"{float(token):.{digits}e}"
    decimals = len(mantissa.partition(".")[2])
    return f"{float(figure):.{decimals}f}" == token


def _functions(path):
    return {n.name for n in ast.walk(ast.parse(path.read_text()))
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}


def test_every_backing_exists():
    """A `test` names a test function that exists; a `result` file exists and holds every number
    the entry covers, as written or as the page rounds it (0.51 for 0.510, 1.4e-12 for
    1.39e-12), or `in_result`, the figure as the file writes it."""
    problems = []
    for e in load():
        label = f"{e['page']}: {e.get('number', e.get('table'))!r}"
        if "test" in e:
            for ref in [e["test"]] + e.get("also", []):
                path, _, func = ref.partition("::")
                if not (ROOT / path).is_file():
                    problems.append(f"{label}: no test file {path}")
                elif not func.startswith("test") or func not in _functions(ROOT / path):
                    problems.append(f"{label}: no test function {func} in {path}")
        if "result" in e:
            files = [e["result"]] if isinstance(e["result"], str) else e["result"]
            missing = [f for f in files if not (ROOT / f).is_file() or not f.startswith("benchmarks/results/")]
            if missing:
                problems.append(f"{label}: no committed result file {missing} under benchmarks/results/")
                continue
            written = "\n".join((ROOT / f).read_text() for f in files)
            held = set(NUMBER.findall(written))
            if "in_result" in e:
                if e["in_result"] not in written:
                    problems.append(f"{label}: {e['in_result']!r} is not in {e['result']}")
                continue
            text = (ROOT / e["page"]).read_text()
            clean, found = numbers(text)
            for s, t in spans(clean, e):
                for a, b, tok in found:
                    if s <= a and b <= t and not any(_as_printed(tok, f) for f in held):
                        problems.append(f"{label}: {tok} is not in {e['result']}")
    assert not problems, "\n".join(problems)
