"""The check of .ci/function_lengths.py on small trees: a long function needs a reason, the
baseline only shrinks, algorithms/ takes no baseline entry, readers are exempt."""

import os
import pathlib
import subprocess
import sys

import pytest

SCRIPT = pathlib.Path(__file__).resolve().parents[2] / ".ci" / "function_lengths.py"


def cpp_function(name, lines, reason=False):
    head = "/// Length: one pass kept whole.\n" if reason else "/// Does things.\n"
    body = "".join(f"  x += {i};\n" for i in range(lines - 4))
    return f"{head}int {name}() {{\n  int x = 0;\n{body}  return x;\n}}\n"


def run(tree, baseline_lines=()):
    (tree / ".ci").mkdir(exist_ok=True)
    (tree / ".ci" / "function_lengths_baseline.txt").write_text(
        "# header\n" + "".join(line + "\n" for line in baseline_lines))
    p = subprocess.run([sys.executable, str(SCRIPT), "--root", str(tree)],
                       capture_output=True, text=True)
    return p.returncode, p.stdout


def write(tree, path, text):
    f = tree / path
    f.parent.mkdir(parents=True, exist_ok=True)
    f.write_text(text)


def test_short_functions_pass(tmp_path):
    write(tmp_path, "algorithms/a.cpp", cpp_function("short_one", 99))
    code, out = run(tmp_path)
    assert code == 0, out
    assert "0 long functions without a reason" in out


def test_long_function_without_reason_fails_and_is_named(tmp_path):
    write(tmp_path, "algorithms/a.cpp", cpp_function("long_one", 100))
    code, out = run(tmp_path)
    assert code == 1
    assert "NEW: algorithms/a.cpp long_one is 100 lines" in out


def test_a_reason_comment_lets_it_pass(tmp_path):
    write(tmp_path, "algorithms/a.cpp", cpp_function("long_one", 150, reason=True))
    code, out = run(tmp_path)
    assert code == 0, out


def test_python_docstring_reason(tmp_path):
    body = "".join(f"    x += {i}\n" for i in range(110))
    write(tmp_path, "experiments/s.py", f'def f():\n    """Length: a table."""\n    x = 0\n{body}    return x\n')
    assert run(tmp_path)[0] == 0
    write(tmp_path, "experiments/s.py", f'def f():\n    """No reason."""\n    x = 0\n{body}    return x\n')
    code, out = run(tmp_path)
    assert code == 1 and "experiments/s.py f" in out and "'# Length:'" in out


def test_baseline_lists_known_ones_and_only_shrinks(tmp_path):
    write(tmp_path, "experiments/a.cpp", cpp_function("old_one", 120))
    code, out = run(tmp_path, ["experiments/a.cpp old_one"])
    assert code == 0 and "known, no reason yet: experiments/a.cpp old_one" in out
    write(tmp_path, "experiments/a.cpp", cpp_function("old_one", 50))
    code, out = run(tmp_path, ["experiments/a.cpp old_one"])
    assert code == 1 and "remove its line" in out


def test_algorithms_take_no_baseline_entry(tmp_path):
    write(tmp_path, "algorithms/a.cpp", cpp_function("long_one", 120))
    code, out = run(tmp_path, ["algorithms/a.cpp long_one"])
    assert code == 1 and "algorithms/ takes no baseline entry" in out


def test_readers_are_exempt(tmp_path):
    write(tmp_path, "mesh/io_foo.cpp", cpp_function("foo_read", 200))
    write(tmp_path, "mesh/other.cpp", cpp_function("foo_read", 200))
    code, out = run(tmp_path)
    assert code == 1 and "mesh/other.cpp foo_read" in out and "io_foo" not in out
