#!/usr/bin/env python3
"""Rewrites the expected output of every console block of a guide page that runs one
`langevin-fem ... --help` command, with what the binary prints now (`make docs`).

The docs test (tests/docs.rs) fails when a page's `--help` output drifts from the program;
this is how a maintainer brings the pages up to date after changing a flag. Only blocks
holding exactly one command ending in `--help` are rewritten; every other block is left
as it is.

Usage: refresh_help.py BINARY PAGE...
"""
import re
import subprocess
import sys


def refresh(binary: str, path: str) -> int:
    text = open(path, encoding="utf-8").read()
    block = re.compile(r"(```console\n\$ langevin-fem ((?:[^\n])*?--help)\n)(.*?)(```)", re.S)
    count = 0

    def replace(m: re.Match) -> str:
        nonlocal count
        args = m.group(2).split()
        out = subprocess.run([binary, *args], capture_output=True, text=True, check=True)
        count += 1
        return m.group(1) + out.stdout.rstrip("\n") + "\n" + m.group(4)

    new = block.sub(replace, text)
    if new != text:
        open(path, "w", encoding="utf-8").write(new)
    return count


if __name__ == "__main__":
    binary, pages = sys.argv[1], sys.argv[2:]
    for page in pages:
        print(f"{page}: {refresh(binary, page)} --help block(s) refreshed")
