"""The numbers are what they were: the shipped walkers' and a stress-corpus set's bit-level
fingerprints (benchmarks/target_digests.py, BASELINE_SECONDS per walker) equal this platform's
committed baseline. A change of physics that moves them writes the baseline again
(`python benchmarks/target_digests.py --write-baseline`) and says in its commit which lines
moved and why. Across x86-64 CPUs the fingerprints are the same (CI checks the host's target
against a generic one and 1 against 2 threads); another architecture or C library may differ
in the last bits of sin / cos, so each platform has its own file, and one without a file
skips, saying so."""
import pytest

from benchmarks import target_digests


def test_fingerprints_equal_the_committed_baseline():
    path = target_digests.baseline_path()
    if not path.exists():
        pytest.skip(f"no committed baseline for this platform ({path.name}); "
                    "write one with: python benchmarks/target_digests.py --write-baseline")
    expected = path.read_text().splitlines()
    got = target_digests.fingerprints(target_digests.BASELINE_SECONDS)
    moved = [(a, b) for a, b in zip(expected, got) if a != b]
    assert len(got) == len(expected) and not moved, (
        f"{len(moved)} of {len(expected)} fingerprints moved from {path.name} "
        f"(first: {moved[:1]}); if the change of numbers is meant, write the baseline again "
        "and explain the moved lines in the commit")
