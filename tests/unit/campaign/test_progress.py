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


def test_first_campaign_says_it_compiles_and_leaves_the_compile_out_of_the_estimate(monkeypatch):
    """Issue 42: the first campaign's line said "1/20 runs, 65 s elapsed, about 1239 s left" while the kernels
    compiled. With a warm-up note: the note until runs finish, then an estimate from the runs after the first."""
    clock = [0.0]
    monkeypatch.setattr(runner.time, "monotonic", lambda: clock[0])
    out = io.StringIO()
    bar = Progress(total=20, stream=out, label="default", interval_s=0.0, warmup="compiling the kernels")
    bar.start()
    clock[0] = 65.0  # the first run finishes after the compile
    bar.update(_results(1))
    clock[0] = 67.0  # then one run every 2 s
    bar.update(_results(1))
    clock[0] = 69.0
    bar.update(_results(1))
    lines = out.getvalue().splitlines()
    assert lines[0] == "default: 0/20 runs, 0 failed, 0 s elapsed, compiling the kernels"
    assert lines[1] == "default: 1/20 runs, 0 failed, 65 s elapsed, kernels ready after 65 s, time estimate after " \
        "the next runs"
    assert lines[2] == "default: 2/20 runs, 0 failed, 67 s elapsed, about 36 s left"  # 2 s a run x 18, not 67/2 x 18
    assert lines[3] == "default: 3/20 runs, 0 failed, 69 s elapsed, about 34 s left"
    # on a terminal the note is one line and the bar (its rate) starts with the first finished runs
    tty = _Tty()
    bar = Progress(total=3, stream=tty, label="default", warmup="compiling the kernels")
    bar.start()
    assert tty.getvalue() == "default: 0/3 runs, compiling the kernels\n" and bar._bar is None
    bar.update(_results(1))
    bar.update(_results(2))
    assert "3/3" in tty.getvalue()


def test_compile_note_follows_the_marker_in_the_kernel_cache(monkeypatch, tmp_path):
    from approachsim.campaign import kernels

    monkeypatch.setattr(kernels, "cache_dir", lambda: tmp_path)
    assert kernels.compile_note("closed") == kernels.COMPILE_NOTE
    kernels.mark_compiled("closed")
    assert kernels.compile_note("closed") is None and kernels.compile_note("open") == kernels.COMPILE_NOTE
    assert (tmp_path / "approachsim-campaign-closed.done").is_file()
