#!/usr/bin/env python3
"""Checks the defaults of docs/cli.md's Configuration table against `lidarloop dump-config`, so that
the two cannot drift apart (they did: the docs gave detection.top_k 5, the tool used 10).

Usage: docs_defaults_test.py LIDARLOOP DOCS_CLI_MD

A row names one key (`histogram.bins`) or several of one section (`histogram.height_min_m`,
`height_max_m`, whose defaults are then listed in the same order: "-3, 7"). Every key a row names
must be in dump-config's output with the default the row states. Exit 0 when all agree; else one
line per difference and exit 1.
"""

import re
import subprocess
import sys


def table_rows(markdown):
    """(line number, key cell, default cell) of the table under '## Configuration'."""
    inside = False
    for number, line in enumerate(markdown.splitlines(), 1):
        if line.startswith("## "):
            inside = line.strip() == "## Configuration"
            continue
        if not inside or not line.startswith("| `"):
            continue
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        yield number, cells[0], cells[1]


def documented_defaults(markdown):
    """{dotted key: (line number, default text)} from the table."""
    defaults = {}
    for number, key_cell, default_cell in table_rows(markdown):
        keys = re.findall(r"`([^`]+)`", key_cell)
        section = keys[0].rpartition(".")[0]
        keys = [keys[0]] + [f"{section}.{key}" if section else key for key in keys[1:]]
        values = [default_cell] if len(keys) == 1 else default_cell.split(", ")
        if len(values) != len(keys):
            raise SystemExit(f"docs line {number}: {len(keys)} keys but defaults {default_cell!r}")
        for key, value in zip(keys, values):
            defaults[key] = (number, value)
    return defaults


def dumped_defaults(lidarloop):
    """{dotted key: value text} of `lidarloop dump-config` (2-space indented YAML, comments)."""
    text = subprocess.run([lidarloop, "dump-config"], check=True, capture_output=True,
                          text=True).stdout
    values, path = {}, []
    for line in text.splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        depth = (len(line) - len(line.lstrip(" "))) // 2
        key, _, value = line.strip().partition(":")
        value = value.split("  #")[0].strip()
        path = path[:depth] + [key]
        if value:
            values[".".join(path)] = value
    return values


def normalised(text):
    """A default as comparable text: no backticks, '−' as '-', numbers as floats."""
    text = text.replace("`", "").replace("\u2212", "-").strip()
    try:
        return float(text)
    except ValueError:
        pass
    if text.startswith("[") and text.endswith("]"):
        return [normalised(item) for item in text[1:-1].split(",")]
    return text


def main():
    lidarloop, docs = sys.argv[1], sys.argv[2]
    with open(docs, encoding="utf-8") as file:
        documented = documented_defaults(file.read())
    if not documented:
        raise SystemExit(f"{docs}: no Configuration table found")
    dumped = dumped_defaults(lidarloop)
    problems = []
    for key, (number, value) in documented.items():
        if key not in dumped:
            problems.append(f"{docs}:{number}: `{key}` is not a key of dump-config")
        elif normalised(value) != normalised(dumped[key]):
            problems.append(f"{docs}:{number}: `{key}` default {value} but dump-config says "
                            f"{dumped[key]}")
    for problem in problems:
        print(problem)
    print(f"docs defaults: {len(documented)} keys checked, {len(problems)} differ")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
