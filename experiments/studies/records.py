"""Reading the JSON Lines records of `hexrefine run` / `reproduce` / `study`, for the report
scripts (thesis/report.py, real_meshes/report.py), and numbers for their Markdown tables."""

import json

from harness import fail


def read_records(path, script):
    """Records of a JSON Lines file; a partial last line (a killed run) is skipped, any other bad
    line is an error naming the file and line."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().split("\n")
    except OSError as e:
        fail(script, "%s: %s" % (path, e.strerror))
    records = []
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            if number == len(lines):
                continue  # no final newline: cut short
            fail(script, "%s:%d: not a JSON record" % (path, number))
    return records


def fmt(value, digits=4):
    """A number for a Markdown table: thousands separators for integers, `digits` significant
    digits otherwise, "–" for None."""
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return "{:,}".format(value)
    if isinstance(value, float):
        if value != 0 and (abs(value) < 1e-3 or abs(value) >= 1e5):
            return "%.3g" % value
        return ("%." + str(digits) + "g") % value
    return str(value)
