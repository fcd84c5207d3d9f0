#!/usr/bin/python3
"""Counts the JUnit results under a folder, prints each failure and the closing line
"Tests: N passed, M failed", and exits non-zero on any failure or when no test ran."""
import pathlib
import sys
import xml.etree.ElementTree as ET


def main(folder):
    passed, failed = 0, []
    for path in sorted(pathlib.Path(folder).rglob("*.xml")):
        for case in ET.parse(path).getroot().iter("testcase"):
            name = f"{case.get('classname')}.{case.get('name')}"
            problems = case.findall("failure") + case.findall("error")
            if problems:
                failed.append((name, problems[0].get("message") or problems[0].text or ""))
            elif case.find("skipped") is None:
                passed += 1
    for name, message in failed:
        print(f"FAILED {name}: {message.strip().splitlines()[0] if message.strip() else ''}")
    print(f"Tests: {passed} passed, {len(failed)} failed")
    return 1 if failed or passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
