"""The command line's front door: what a new user meets first. A duration that cannot be
recorded, an interrupt at any moment, the first compile, progress in pipes, tuning budgets,
the gaits `list` shows and the summary's files: each answered in one clear way."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from walkers.cli import main

ROOT = Path(__file__).resolve().parents[2]


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# a duration that cannot fit in memory ----------------------------------------------------------
def test_a_duration_that_cannot_be_recorded_is_one_line_naming_the_option(capsys):
    code, out, err = run_cli(capsys, "run", "simple-biped", "--duration", "1e9", "--json")
    assert code == 2
    assert out == ""
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "--duration" in err and "GiB" in err and "memory" in err
