"""Engine benchmarks: `python benchmarks/run.py [scenes] [--csv benchmarks/results]`
(identical to `planarsim bench`; `--help` lists the options).

The scenes and the runner live in planarsim/bench*.py so that `planarsim bench` runs the same
thing from an installed package; the peer comparison needs `pip install planarsim[compare]`.
"""
import sys

from planarsim.bench import main

if __name__ == "__main__":
    sys.exit(main())
