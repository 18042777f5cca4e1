"""Engine benchmarks: `python benchmarks/run.py [scenes] [--csv benchmarks/results]`.

The scenes and the runner live in planarsim/bench_scenes.py and planarsim/bench.py so that
`planarsim bench` runs the same thing from an installed package.
"""
import sys

from planarsim.bench import main

if __name__ == "__main__":
    sys.exit(main())
