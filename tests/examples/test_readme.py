"""README's Python code runs as written (the rolling disk, then a Ranger walk), in a temporary
folder, and gives what README says it gives; README's two commands and their expected times.
The documentation pages' blocks: tests/docs/test_doc_pages.py."""
import math
import re
import runpy
from pathlib import Path

import planarsim as ps

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_blocks_run_in_order(tmp_path, monkeypatch):
    blocks = re.findall(r"^```python\n(.*?)^```", README.read_text(), re.S | re.M)
    assert len(blocks) >= 2
    monkeypatch.chdir(tmp_path)
    # one script file, as a reader would paste it (numba caches a function by its file)
    script = tmp_path / "readme_blocks.py"
    script.write_text("\n".join(blocks))
    namespace = runpy.run_path(str(script), run_name="readme")
    # the rolling disk: the textbook's (2/3) g sin(slope) t^2 / 2 along the slope, as README says
    # (0.6849 m against 0.6846 m: the step's first-order error at dt = 1 ms), rolling, not sliding
    slope = namespace["slope"]
    theory = (2 / 3) * 9.81 * math.sin(slope) * 2.0 ** 2 / 2
    assert abs(namespace["travel"] - theory) < 2e-3 * theory, (namespace["travel"], theory)
    assert list(namespace["traj"].contact_mode[-1]) == [ps.ContactMode.PINNED]
    from planarsim.compiled import audit_counts
    assert not any(audit_counts(namespace["sim"].ws).values())
    # Ranger walks and its audit is all 0, as the comment says
    numbers = namespace["numbers"]
    assert numbers["distance"] > 0.5 and not numbers["fell"]
    assert numbers["audit"] and not any(numbers["audit"].values()), numbers["audit"]


TWO_COMMANDS = [
    "python3 -m venv .venv && .venv/bin/pip install -q -e . && .venv/bin/planarsim run simple-biped",
    "python3 -m venv .venv && .venv/bin/pip install -q -e '.[test]' && .venv/bin/python -m pytest -q",
]


def two_commands_section(text):
    """README's two commands and their times: the part the documentation's Getting started page
    includes (pymdownx.snippets' section markers)."""
    return text[text.index("--8<-- [start:two-commands]"):text.index("--8<-- [end:two-commands]")]


def test_readme_gives_the_two_commands_and_ci_runs_the_second():
    """The two commands, exactly: one installs and runs the main job, one installs and runs the
    tests; .ci/run runs the second as it stands (the documentation includes this section)."""
    text = README.read_text()
    part = two_commands_section(text)
    assert re.findall(r"^python3 -m venv .*$", part, re.M) == TWO_COMMANDS
    assert text.index("## Two commands") < text.index("--8<-- [start:two-commands]")
    ci = (README.parent / ".ci" / "run").read_text()
    assert re.search(r"^python3 -m venv .venv && .venv/bin/pip install -q -e '\.\[test\]' && "
                     r"\.venv/bin/python -m pytest -q$", ci, re.M)
    getting_started = (README.parent / "docs" / "getting-started.md").read_text()
    assert '--8<-- "README.md:two-commands"' in getting_started


def test_readme_gives_the_expected_time_of_both_commands(monkeypatch, capsys):
    """README's expected times agree with the figures they come from: each 'about N minutes'
    is its measured seconds rounded, command 2's parts add up to its total, the first compile's
    quiet-machine figure is the one the program quotes (compiled.TYPICAL_COMPILE_S), the
    program's message reads as README quotes it, and tests/README.md gives the same time for
    the test run. (The times themselves are measured by hand: benchmarks/startup.py.)"""
    from planarsim import compiled
    from walkers import cli
    text = README.read_text()
    part = " ".join(two_commands_section(text).split())
    minutes = {}
    for k in (1, 2):
        about, unit, measured = re.search(rf"command {k}: about (\d+) (minutes?) \((\d+) s measured\)", part).groups()
        assert int(about) == round(int(measured) / 60), (k, about, measured)
        assert unit == ("minute" if int(about) == 1 else "minutes"), (k, unit)
        minutes[k] = int(about)
    # command 2: the install and the tests add up to the measured total (README rounds each)
    total, install, tests = map(int, re.search(
        r"command 2: about \d+ minutes \((\d+) s measured\): the install with the test extras about (\d+) s, "
        r"then the tests (\d+) s", part).groups())
    assert abs(install + tests - total) <= 5, (install, tests, total)
    # the first compile on a quiet machine: what the program says where it has measured none
    quiet = float(re.search(r"the program's estimate for a quiet\s+machine, about (\d+) s", part).group(1))
    assert quiet == compiled.TYPICAL_COMPILE_S
    # the program's message after a first compile, as README quotes it (N: the seconds)
    monkeypatch.setattr(compiled, "record_compile", lambda seconds: None)   # keep this machine's record
    cli._said_compiled(37.4)
    quoted = re.search(r"\(`(first compile: [^`]*)`\)", part).group(1)
    assert quoted.replace("N", "37") in capsys.readouterr().err, quoted
    # tests/README.md states the test run's time in words: the same minutes as command 2's
    words = {"five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10}
    said = re.search(r"runs everything \(about (\w+) minutes", (README.parent / "tests" / "README.md").read_text())
    assert words.get(said.group(1), said.group(1)) in (minutes[2], str(minutes[2])), said.group(0)
    assert "about half a minute" not in text
