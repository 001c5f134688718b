#!/usr/bin/python3
"""The real-mesh study: `hexrefine study` writes the records (results/real_meshes.jsonl, with
--quick results/quick/) and then runs report.py beside this script (real_meshes.md, the
quality histograms).

    python3 experiments/studies/real_meshes/run.py [--hexrefine build/experiments/hexrefine]
        [--meshes DIR]... [--no-shared] [--max-hexes-input N] [--out DIR] [--quick] [--resume]
        [--quiet] [--no-plots]

Every argument but --hexrefine goes to `hexrefine study` (see `hexrefine study --help`); the
report alone, on records at hand: python3 experiments/studies/real_meshes/report.py --help.
"""

import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402

if __name__ == "__main__":
    harness.run_command_study(harness.first_line(__doc__), "study")
