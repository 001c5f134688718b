"""Puts experiments/adaptive on sys.path for the tests of the adaptive loop (hexrefine itself comes
from PYTHONPATH, the build tree's experiments/python, as ctest sets it)."""

import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[3] / "experiments" / "adaptive"))
