"""Campaign progress display: a tqdm bar on a terminal, periodic plain lines (no carriage return) otherwise."""

from __future__ import annotations

import io

from approachsim.campaign import runner
from approachsim.campaign.result import RunResult
from approachsim.campaign.runner import Progress


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def _results(n: int, failed: int = 0) -> list[RunResult]:
    return [RunResult.failed(i, "x") if i < failed else RunResult(run=i, ok=True) for i in range(n)]


def test_redirected_output_is_plain_periodic_lines(monkeypatch):
    clock = [100.0]
    monkeypatch.setattr(runner.time, "monotonic", lambda: clock[0])
    out = io.StringIO()
    bar = Progress(total=10, stream=out, label="default[grade=nav-0.4]", interval_s=10.0)
    bar.start()
    for k in range(10):
        clock[0] += 3.0  # a run every 3 s: a line at most every 10 s
        bar.update(_results(1, failed=1 if k == 4 else 0))
    text = out.getvalue()
    assert "\r" not in text
    lines = text.splitlines()
    assert lines[0] == "default[grade=nav-0.4]: 0/10 runs, 0 failed, 0 s elapsed"
    assert lines[-1] == "default[grade=nav-0.4]: 10/10 runs, 1 failed, 30 s elapsed, done"
    assert 3 <= len(lines) <= 5  # start, every ~10 s of the 30 s, the end; not one line per run
    assert any("about" in ln and "s left" in ln for ln in lines[1:-1])


def test_terminal_gets_a_tqdm_bar_naming_the_campaign():
    out = _Tty()
    bar = Progress(total=4, stream=out, label="default[calm]")
    bar.start()
    bar.update(_results(2, failed=1))
    bar.update(_results(2))
    text = out.getvalue()
    assert "default[calm]" in text and "4/4" in text and "1 failed" in text
    assert "\r" in text  # redrawn in place


def test_disabled_writes_nothing():
    out = _Tty()
    bar = Progress(total=3, stream=out, enabled=False)
    bar.start()
    bar.update(_results(3))
    assert out.getvalue() == ""
