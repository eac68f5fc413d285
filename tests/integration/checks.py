# Shared by the integration scripts: record and print checks, then exit with their verdict.
# SPDX-License-Identifier: BSL-1.0
import sys

failures = []


def check(cond, what):
    """Prints ok/FAIL for one check and remembers failures."""
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def finish():
    """Exits 1 if any check failed, else 0."""
    print(f"\n{len(failures)} check(s) failed" if failures else "\nall checks passed")
    sys.exit(1 if failures else 0)
