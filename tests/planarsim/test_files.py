"""Output files: an interrupted write (even SIGKILL) leaves nothing at or beside the target,
and temporary files of dead processes are removed by the next write."""
import os
import signal
import subprocess
import sys
import tempfile

import pytest

from planarsim.files import remove_stale
from planarsim.trajectory import atomic_write

SLOW_WRITER = """
import sys, time
from planarsim.trajectory import atomic_write
def write(f):
    f.write(b"x" * 1000)
    f.flush()
    print("writing", flush=True)
    time.sleep(60)
atomic_write(sys.argv[1], write)
"""


@pytest.mark.skipif(sys.platform == "win32", reason="SIGKILL")
def test_sigkill_during_a_save_leaves_no_file_at_or_beside_the_target(tmp_path):
    target = tmp_path / "run.npz"
    proc = subprocess.Popen([sys.executable, "-c", SLOW_WRITER, str(target)],
                            stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert os.listdir(tmp_path) == []
    # the next write removes what the killed process left in the temporary folder
    atomic_write(target, lambda f: f.write(b"ok"))
    assert target.read_bytes() == b"ok"
    left = [n for n in os.listdir(tempfile.gettempdir()) if n.startswith(f"planarsim-{proc.pid}-")]
    assert left == []


def test_stale_parts_of_dead_processes_beside_the_target_are_removed(tmp_path):
    target = tmp_path / "walk.gif"
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / f".walk.gif.{dead.pid}.abc123.part.gif"
    stale.write_bytes(b"half")
    mine = tmp_path / f".walk.gif.{os.getpid()}.def456.part.gif"     # a live writer's: kept
    mine.write_bytes(b"busy")
    other = tmp_path / f".other.gif.{dead.pid}.abc.part"                # another target's: kept
    other.write_bytes(b"x")
    remove_stale(target)
    assert not stale.exists() and mine.exists() and other.exists()


def test_a_failed_write_leaves_nothing(tmp_path):
    target = tmp_path / "summary.json"

    def fail(f):
        f.write("{")
        raise RuntimeError("disk full")
    with pytest.raises(RuntimeError):
        atomic_write(target, fail, binary=False)
    assert os.listdir(tmp_path) == []
    assert not [n for n in os.listdir(tempfile.gettempdir())
                if n.startswith(f"planarsim-{os.getpid()}-")]


@pytest.mark.parametrize("where", ["folder", "proc"])
def test_a_target_that_cannot_be_written_is_named(tmp_path, where):
    """A write that fails at the end (the target is a folder; /proc, where the folder
    checks pass for root but no file can be made) names the target, not the temporary file
    it was staged in ('/proc/.x.npz.PID.xxxx.part': No such file or directory), and leaves
    nothing behind."""
    if where == "proc":
        if not (sys.platform.startswith("linux") and os.path.isdir("/proc")
                and os.access("/proc", os.W_OK)):
            pytest.skip("needs /proc that os.access calls writable (Linux, as root)")
        target = "/proc/planarsim-test.npz"
    else:
        target = tmp_path / "run.npz"
        target.mkdir()
    with pytest.raises(OSError) as err:
        atomic_write(target, lambda f: f.write(b"x"))
    said = str(err.value)
    assert said.startswith(f"cannot write {str(target)!r}: ") and ".part" not in said, said
    assert not [n for n in os.listdir(tempfile.gettempdir())
                if n.startswith(f"planarsim-{os.getpid()}-")]


def test_folder_refuses_says_why_no_file_can_be_made_and_leaves_nothing(tmp_path):
    """os.access says yes to root in /proc: only making a file there tells."""
    from planarsim.files import folder_refuses
    assert folder_refuses(tmp_path / "x.gif") is None
    assert list(tmp_path.iterdir()) == []
    if os.path.isdir("/proc"):
        assert folder_refuses("/proc/x.gif")          # the system's words, e.g. "No such file"
