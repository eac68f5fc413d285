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


def tool(program):
    """The two helpers a script that drives the rcb4 tool needs: run(*args) -> (exit code, stdout,
    stderr), and serve(*args), a context manager that runs `rcb4 serve --pty ARGS` for the duration
    of a with block and yields its device path."""
    import contextlib
    import subprocess

    def run(*args, stdin=None, timeout=60):
        p = subprocess.run([program, *args], input=stdin, capture_output=True, text=True, timeout=timeout)
        return p.returncode, p.stdout, p.stderr

    @contextlib.contextmanager
    def serve(*args):
        srv = subprocess.Popen([program, "serve", "--pty", *args], stdout=subprocess.PIPE, text=True)
        try:
            yield srv.stdout.readline().strip()
        finally:
            srv.terminate()
            srv.wait(timeout=10)

    return run, serve


def ics_server(program, *args):
    """A context manager: `rcb4 ics serve --pty ARGS` for the duration of a with block, yielding its
    device path; it must end with 0 on SIGTERM (checked)."""
    import contextlib
    import subprocess

    @contextlib.contextmanager
    def serving():
        srv = subprocess.Popen([program, "ics", "serve", "--pty", *args], stdout=subprocess.PIPE, text=True)
        try:
            yield srv.stdout.readline().strip()
        finally:
            srv.terminate()
            srv.wait(timeout=10)
            check(srv.returncode == 0, f"ics serve {' '.join(args)} ends with 0 on SIGTERM (got {srv.returncode})")

    return serving()
