#!/usr/bin/env python3
"""Lists the functions of 100 lines or more that give no reason for their length, and fails on new ones.

DEVELOPERS.md: a function of 100 lines or more needs a stated reason. The reason is a comment line
that starts with `Length:` in the comment block right above the function (C++: `/// Length: ...`,
Python: `# Length: ...`) or, for Python, in its docstring. The format readers (the `*_read`
functions of mesh/io_*.cpp and their lambdas) and the Python binding (PYBIND11_MODULE) are exempt:
a reader follows the format's sections, one after the other.

Functions that were long before this check existed are listed in .ci/function_lengths_baseline.txt
(one `path function` a line): they are printed as a reminder but do not fail the check, so the
check fails only on a new long function without a reason. algorithms/ may have no baseline entry:
every long function there states its reason. A baseline line whose function is gone or now short
fails too, so the list only shrinks.

Needs universal-ctags (Debian `universal-ctags`, .ci/setup.sh). Usage, from the repository root:
  python3 .ci/function_lengths.py [--limit 100] [--baseline .ci/function_lengths_baseline.txt]
Exit 0: no new long function without a reason; 1: some (listed); 2: ctags missing or bad usage.
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys

FOLDERS = ["mesh", "algorithms", "experiments", "tests", ".ci"]


def ctags_binary():
    for name in ("ctags-universal", "universal-ctags", "ctags"):
        path = shutil.which(name)
        if path:
            return path
    return None


def function_tags(root):
    """Every function and lambda with its span: [(path, name, first line, last line)]."""
    binary = ctags_binary()
    if binary is None:
        sys.exit("function_lengths.py: universal-ctags not found (apt-get install universal-ctags)")
    folders = [f for f in FOLDERS if os.path.isdir(os.path.join(root, f))]
    out = subprocess.run(
        [binary, "--output-format=json", "--fields=+neK", "--languages=C++,Python",
         "--kinds-C++=f", "--kinds-Python=fm", "-R", "-f", "-", *folders],
        cwd=root, check=True, capture_output=True, text=True).stdout
    tags = []
    lambdas = {}  # lambdas are named by their enclosing function and their rank in it
    for line in out.splitlines():
        tag = json.loads(line)
        if tag.get("_type") != "tag" or "end" not in tag:
            continue
        name = tag["name"]
        if name.startswith("__anon"):
            scope = tag.get("scope", "")
            lambdas[(tag["path"], scope)] = lambdas.get((tag["path"], scope), 0) + 1
            parent = scope.split(".")[-1].split("::")[-1]
            name = f"{parent}::lambda#{lambdas[(tag['path'], scope)]}"
        tags.append((tag["path"], name, int(tag["line"]), int(tag["end"])))
    return tags


def exempt(path, name):
    if re.fullmatch(r"mesh/io_[a-z0-9_]*\.cpp", path) and re.match(r"[a-z0-9_]*_read\b", name):
        return True
    return name.startswith("PYBIND11_MODULE")


def has_reason(lines, first, last, python):
    """Whether the comment block above line `first` (1-based) or a Python docstring says Length:."""
    i = first - 2
    while i >= 0:
        text = lines[i].strip()
        if python and text.startswith("@"):  # decorators sit between the comment and the def
            i -= 1
            continue
        if not (text.startswith("//") or text.startswith("#") or text.startswith("*")
                or text.startswith("/*") or text.startswith("template")):
            break
        if re.search(r"\bLength:", text):
            return True
        i -= 1
    if python:
        body = "\n".join(lines[first:min(last, first + 40)])
        doc = re.match(r'\s*(?:"""|\'\'\')(.*?)(?:"""|\'\'\')', body, re.S)
        if doc and re.search(r"\bLength:", doc.group(1)):
            return True
    return False


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=int, default=100)
    parser.add_argument("--baseline", default=".ci/function_lengths_baseline.txt")
    parser.add_argument("--root", default=".")
    args = parser.parse_args()
    root = args.root
    baseline = set()
    baseline_path = os.path.join(root, args.baseline)
    if os.path.exists(baseline_path):
        with open(baseline_path) as f:
            for line in f:
                line = line.strip()
                if line and not line.startswith("#"):
                    path, name = line.split(maxsplit=1)
                    baseline.add((path, name))
    cache = {}
    unreasoned = []
    for path, name, first, last in sorted(function_tags(root)):
        length = last - first + 1
        if length < args.limit or exempt(path, name):
            continue
        if path not in cache:
            with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
                cache[path] = f.read().splitlines()
        if not has_reason(cache[path], first, last, path.endswith(".py")):
            unreasoned.append((path, name, length))
    new = [u for u in unreasoned if (u[0], u[1]) not in baseline]
    known = [u for u in unreasoned if (u[0], u[1]) in baseline]
    seen = {(u[0], u[1]) for u in unreasoned}
    stale = sorted(b for b in baseline if b not in seen)
    in_algorithms = sorted(b for b in baseline if b[0].startswith("algorithms/"))
    for path, name, length in known:
        print(f"function_lengths: known, no reason yet: {path} {name} ({length} lines)")
    for path, name, length in new:
        print(f"function_lengths: NEW: {path} {name} is {length} lines and states no reason: "
              f"split it, or say why in a '{'#' if path.endswith('.py') else '///'} Length:' comment "
              f"above it")
    for path, name in stale:
        print(f"function_lengths: {args.baseline}: '{path} {name}' is no longer a long function "
              f"without a reason: remove its line")
    for path, name in in_algorithms:
        print(f"function_lengths: {args.baseline}: '{path} {name}': algorithms/ takes no "
              f"baseline entry, state the reason in the code")
    failed = bool(new or stale or in_algorithms)
    print(f"function_lengths: {len(unreasoned)} long functions without a reason "
          f"({len(known)} known, {len(new)} new); {'FAILED' if failed else 'ok'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
