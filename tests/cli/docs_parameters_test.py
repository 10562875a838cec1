#!/usr/bin/env python3
"""Checks docs/cli.md's generated tables against `lidarloop dump-config`: the lines between
'<!-- dump-config FLAG -->' and '<!-- end dump-config FLAG -->' must be the output of
`lidarloop dump-config FLAG`, for the method parameters (--markdown: the table the methods'
declarations give, docs/options.md) and the run options (--markdown-run-options: the flags and
Python keywords every run command shares).

Usage: docs_parameters_test.py LIDARLOOP DOCS_CLI_MD
"""

import difflib
import subprocess
import sys

TABLES = {"--markdown": "method parameters", "--markdown-run-options": "run options"}


def check(lidarloop, docs, lines, flag, what):
    """0 when the block of `flag` is dump-config's output, else 1 with a diff."""
    begin, end = f"<!-- dump-config {flag} -->", f"<!-- end dump-config {flag} -->"
    if lines.count(begin) != 1 or lines.count(end) != 1:
        print(f"{docs}: expected one '{begin}' ... '{end}' block")
        return 1
    documented = lines[lines.index(begin) + 1:lines.index(end)]
    generated = subprocess.run([lidarloop, "dump-config", flag], check=True,
                               capture_output=True, text=True).stdout.splitlines()
    if documented != generated:
        print(f"{docs}: the {what} differ from `lidarloop dump-config {flag}` "
              "(paste its output between the markers):")
        sys.stdout.writelines(line + "\n" for line in
                              difflib.unified_diff(documented, generated, "docs", "dump-config",
                                                   lineterm=""))
        return 1
    print(f"{docs}: {len(generated) - 2} {what} agree with dump-config {flag}")
    return 0


def main():
    lidarloop, docs = sys.argv[1], sys.argv[2]
    with open(docs, encoding="utf-8") as file:
        lines = file.read().splitlines()
    return max(check(lidarloop, docs, lines, flag, what) for flag, what in TABLES.items())


if __name__ == "__main__":
    sys.exit(main())
