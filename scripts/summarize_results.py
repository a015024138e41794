#!/usr/bin/env python3
"""Sums gtest and rostest JUnit XML results and prints "N passed, N failed" last.

Exit status: 0 when at least one test ran and none failed, 1 otherwise.
A result file that cannot be parsed, or a test binary that wrote no result
(catkin then writes a "MISSING-RESULT" placeholder), counts as a failure.
"""
import pathlib
import sys
import xml.etree.ElementTree as ET


def count_file(path):
    """Returns (passed, failed, failed_names) for one JUnit XML file."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as err:
        return 0, 1, [f"{path.name}: unreadable result ({err})"]
    cases = root.iter("testcase")
    passed, failed, names = 0, 0, []
    for case in cases:
        if case.find("skipped") is not None or case.get("status") == "notrun":
            continue
        if case.find("failure") is not None or case.find("error") is not None:
            failed += 1
            names.append(f"{case.get('classname')}.{case.get('name')}")
        else:
            passed += 1
    return passed, failed, names


def main():
    folder = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    files = sorted(folder.rglob("*.xml")) if folder.is_dir() else []
    passed = failed = 0
    failures = []
    for path in files:
        p, f, names = count_file(path)
        passed += p
        failed += f
        failures += [f"{path.name}: {n}" for n in names]
    for name in failures:
        print(f"FAILED: {name}")
    print(f"{len(files)} result file(s) in {folder}")
    print(f"{passed} passed, {failed} failed")
    return 0 if passed > 0 and failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
