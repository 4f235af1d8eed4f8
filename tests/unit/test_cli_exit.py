"""cli.run, the console script: the process ends with main's status, its standard streams flushed and Python's
exit handlers run, without the interpreter's teardown (cli.run docstring); an exception takes Python's own path."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

from approachsim.api import shipped_profiles


def _run(code: str, tmp_path: Path) -> tuple[int, str, str]:
    """Run code in a fresh interpreter with stdout and stderr redirected to files (block-buffered, as when a
    user's script redirects them): (status, stdout, stderr)."""
    out, err = tmp_path / "out.txt", tmp_path / "err.txt"
    with open(out, "w") as fo, open(err, "w") as fe:
        p = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], stdout=fo, stderr=fe)
    return p.returncode, out.read_text(), err.read_text()


def test_output_flushed_and_status_kept(tmp_path):
    rc, out, _ = _run("""
        import sys
        sys.argv = ["approachsim", "profiles"]
        from approachsim.cli import run
        run()
        """, tmp_path)
    assert rc == 0
    lines = [ln for ln in out.splitlines() if ln.strip()]
    assert [ln.split()[0] for ln in lines[:-1]] == sorted(shipped_profiles())  # every line written, none lost
    assert lines[-1].startswith("(in ") and "profiles init" in lines[-1]  # to the last


def test_error_status_and_exit_handlers(tmp_path):
    rc, out, err = _run("""
        import atexit, sys
        atexit.register(lambda: print("handler ran"))
        sys.argv = ["approachsim", "evaluate", "/nonexistent/profile.toml"]
        from approachsim.cli import run
        run()
        """, tmp_path)
    assert rc == 2
    assert out.strip() == "handler ran"
    assert len(err.strip().splitlines()) == 1 and "no such file" in err


def test_an_exception_takes_pythons_path(tmp_path):
    rc, _, err = _run("""
        import sys
        import approachsim.cli as cli
        def boom(argv=None):
            raise RuntimeError("boom")
        cli.main = boom
        cli.run()
        """, tmp_path)
    assert rc == 1 and "RuntimeError: boom" in err
