"""Engine benchmarks: `python benchmarks/run.py [scenes] [--csv benchmarks/results]`
(identical to `planarsim bench`; `--help` lists the options).

The runner, scenes, metrics and report are in this folder (runner.py, scenes.py, metrics.py,
report.py), the peers in peers/; the package is installed with planarsim, so `planarsim bench`
runs the same thing anywhere. The peer comparison needs `pip install planarsim[compare]`.
"""
import sys

from benchmarks.runner import main

if __name__ == "__main__":
    sys.exit(main())
