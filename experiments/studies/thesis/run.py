#!/usr/bin/python3
"""The thesis suite: `hexrefine reproduce` writes the records (results/thesis.jsonl, with
--quick results/quick/) and then runs report.py beside this script (tables.md, plots, renders).

    python3 experiments/studies/thesis/run.py [--hexrefine build/experiments/hexrefine]
        [--quick] [--resume] [--quiet] [--no-plots]

Every argument but --hexrefine goes to `hexrefine reproduce` (see `hexrefine reproduce --help`);
the report alone, on records at hand: python3 experiments/studies/thesis/report.py --help.
"""

import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402

if __name__ == "__main__":
    harness.run_command_study(harness.first_line(__doc__), "reproduce")
