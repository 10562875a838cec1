#!/usr/bin/env python3
"""Checks docs/cli.md's table of method parameters against `lidarloop dump-config --markdown`, the
table the methods' declarations give (docs/options.md): the lines between the markers
'<!-- dump-config --markdown -->' and '<!-- end dump-config --markdown -->' must be its output.

Usage: docs_parameters_test.py LIDARLOOP DOCS_CLI_MD
"""

import difflib
import subprocess
import sys

BEGIN = "<!-- dump-config --markdown -->"
END = "<!-- end dump-config --markdown -->"


def main():
    lidarloop, docs = sys.argv[1], sys.argv[2]
    with open(docs, encoding="utf-8") as file:
        lines = file.read().splitlines()
    if lines.count(BEGIN) != 1 or lines.count(END) != 1:
        raise SystemExit(f"{docs}: expected one '{BEGIN}' ... '{END}' block")
    documented = lines[lines.index(BEGIN) + 1:lines.index(END)]
    generated = subprocess.run([lidarloop, "dump-config", "--markdown"], check=True,
                               capture_output=True, text=True).stdout.splitlines()
    if documented != generated:
        print(f"{docs}: the method parameters differ from `lidarloop dump-config --markdown` "
              "(paste its output between the markers):")
        sys.stdout.writelines(line + "\n" for line in
                              difflib.unified_diff(documented, generated, "docs", "dump-config",
                                                   lineterm=""))
        return 1
    print(f"{docs}: {len(generated) - 2} method parameters agree with dump-config --markdown")
    return 0


if __name__ == "__main__":
    sys.exit(main())
