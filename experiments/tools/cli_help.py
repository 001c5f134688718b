#!/usr/bin/python3
"""Refreshes the help blocks of docs/cli.md from the built binary.

usage: python3 experiments/tools/cli_help.py [HEXREFINE]   (default build/experiments/hexrefine)

Each command's section ("## NAME") holds the command's own `--help` output in its first code
block, and the page's first code block the overall usage (`hexrefine help`): run this after a
command's options change, so the page says what the binary does.
"""

import os
import pathlib
import re
import subprocess
import sys

REPO = pathlib.Path(__file__).resolve().parents[2]


def output(binary, *args):
    r = subprocess.run([binary, *args], capture_output=True, text=True)
    return (r.stdout + r.stderr).rstrip("\n")


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else str(REPO / "build" / "experiments" / "hexrefine")
    path = str(REPO / "docs" / "cli.md")
    text = open(path, encoding="utf-8").read()
    first = text.index("```\n")
    end = text.index("```\n", first + 4)
    text = text[:first] + "```\n" + output(binary, "help") + "\n" + text[end:]
    commands = re.findall(r"^## ([a-z-]+)$", text, re.M)
    for command in commands:
        help_text = output(binary, command, "--help")
        if not help_text.startswith("usage: hexrefine " + command):
            continue  # a section that is not a command (selection specs, threads)
        head = text.index("## " + command + "\n")
        start = text.index("```\n", head)
        stop = text.index("```\n", start + 4)
        text = text[:start] + "```\n" + help_text + "\n" + text[stop:]
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


if __name__ == "__main__":
    main()
