#!/usr/bin/env python3
"""Checks the style limits of the C++ sources: files under 400 lines, functions under 60.

A function is a brace block that opens on a line of its own at the indentation of the line
before it (this project's .clang-format puts every function's brace there) and is not a
class, struct, enum or namespace body. Prints each offender; exits 1 when there is one.
Usage: check_limits.py [ROOT]   (default: the repository this script is in)
"""
import os
import re
import sys

MAX_FILE_LINES = 400
MAX_FUNCTION_LINES = 60
FOLDERS = ("src", "include", "test", "bench")
NOT_A_FUNCTION = re.compile(r"^\s*(namespace|class|struct|enum|union)\b|=\s*$|^\s*(extern)\b")


def functions(lines):
    """Yields (name line number, length in lines) of each function body."""
    for i, line in enumerate(lines):
        stripped = line.rstrip("\n")
        if stripped.strip() != "{" or i == 0:
            continue
        indent = len(stripped) - len(stripped.lstrip())
        head = i - 1
        while head > 0 and lines[head].strip() == "":
            head -= 1
        # The signature may span lines: walk back to its first line.
        start = head
        while start > 0 and lines[start].startswith(" " * (indent + 1)) and lines[start - 1].strip():
            start -= 1
        signature = " ".join(l.strip() for l in lines[start:head + 1])
        if NOT_A_FUNCTION.search(lines[start]) or "(" not in signature:
            continue
        if re.match(r"^\s*(if|else|for|while|switch|do|try|catch)\b", lines[head]):
            continue
        close = " " * indent + "}"
        for j in range(i + 1, len(lines)):
            if lines[j].rstrip("\n") == close or lines[j].startswith(close + ";"):
                yield start + 1, j - start + 1
                break


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    problems = []
    for folder in FOLDERS:
        for base, _, names in os.walk(os.path.join(root, folder)):
            for name in sorted(names):
                if not name.endswith((".cpp", ".h")):
                    continue
                path = os.path.join(base, name)
                with open(path, encoding="utf-8", errors="replace") as f:
                    lines = f.readlines()
                rel = os.path.relpath(path, root)
                if len(lines) >= MAX_FILE_LINES:
                    problems.append(f"{rel}: {len(lines)} lines (limit {MAX_FILE_LINES})")
                for line, length in functions(lines):
                    if length > MAX_FUNCTION_LINES:
                        problems.append(f"{rel}:{line}: function of {length} lines (limit {MAX_FUNCTION_LINES})")
    for p in problems:
        print(p)
    print(f"check_limits: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
