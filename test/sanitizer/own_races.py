#!/usr/bin/env python3
"""Reads ThreadSanitizer report files of a process that runs the package's instrumented code
beside Debian's uninstrumented ROS libraries (a nodelet manager with the TSan runtime
preloaded, a rostest binary). TSan cannot see the locking inside those libraries and reports
races between two of their accesses, or between one of ours and one of theirs that their own
locks order. A race in the package's code has the package's sources in both stacks: those
are printed, and the exit status is 1 if there is one.

usage: own_races.py SOURCE_ROOT REPORT_FILE...
"""
import re
import sys


def stacks(report):
    """The access stacks of a report: 'Write/Read ... by ...' and 'Previous ...' blocks."""
    out, current = [], None
    for line in report.splitlines():
        if re.match(r"\s+(Previous )?(atomic )?(Read|Write) of size", line):
            current = []
            out.append(current)
        elif current is not None and re.match(r"\s+#\d+ ", line):
            current.append(line.strip())
        elif current is not None and not line.strip():
            current = None
    return out


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    root = sys.argv[1].rstrip("/") + "/"
    own = re.compile(re.escape(root) + r"(src|include)/")
    found = checked = 0
    for path in sys.argv[2:]:
        text = open(path, errors="replace").read()
        for report in text.split("==================\n"):
            if "WARNING: ThreadSanitizer" not in report:
                continue
            checked += 1
            accesses = stacks(report)
            if "data race" in report and len(accesses) >= 2 and all(
                    any(own.search(frame) for frame in s) for s in accesses):
                found += 1
                print("--- a race in the package's own code (%s):" % path)
                print(report)
    print("own_races: %d report(s) read, %d race(s) with the package's code in both stacks"
          % (checked, found))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
