"""`fsvla report`: what it writes, and its errors (a message and exit 1 or 2, no traceback)."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from rich.console import Console

from fsvla.cli import run
from fsvla.report import summary_table
from fsvla.results import ResultStore


def test_report_writes_tables_without_figures(run_dirs, tmp_path: Path, capsys) -> None:
    out = tmp_path / "report"
    code = run(["report", *map(str, run_dirs), "-o", str(out), "--no-figures",
                "--formats", "html,md,tex,csv", "--resamples", "50",
                "--label", "OpenVLA", "--label", "ACT"])
    assert code == 0, capsys.readouterr()
    assert {p.name for p in out.iterdir()} == {"report.html", "report.md", "tables", "data"}
    page = (out / "report.html").read_text()
    assert "OpenVLA" in page and "Figures were not drawn (--no-figures)." in page
    assert "wrote" in capsys.readouterr().out


def test_report_with_figures_and_an_episode(run_dirs, tmp_path: Path, capsys) -> None:
    pytest.importorskip("matplotlib")
    out = tmp_path / "report"
    code = run(["report", str(run_dirs[1]), "-o", str(out), "--formats", "png,json",
                "--resamples", "50", "--episode", "stove-L0-W3-V4-s0-e000"])
    assert code == 0, capsys.readouterr()
    assert sorted(p.name for p in (out / "figures").iterdir()) == [
        "diagnosis.png", "landscape.png", "margins.png"]
    assert '"episode_id": "stove-L0-W3-V4-s0-e000"' in (out / "report.json").read_text()


@pytest.mark.parametrize(("args", "code", "message"), [
    (["--episode", "nope"], 2, "no scored episode 'nope'"),
    (["--episode", "stove-L0-W3-V4-s0-e000"], 2, "write LABEL:stove-L0-W3-V4-s0-e000"),
    (["--formats", "html,docx"], 2, "unknown format"),
    (["--label", "one"], 2, "one --label per run folder"),
])
def test_report_usage_errors(run_dirs, tmp_path: Path, capsys, args, code, message) -> None:
    result = run(["report", *map(str, run_dirs), "-o", str(tmp_path / "r"), "--no-figures",
                  "--resamples", "20", *args])
    captured = capsys.readouterr()
    assert result == code
    assert message in " ".join((captured.err + captured.out).split())
    assert "Traceback" not in captured.err


def test_report_of_a_folder_without_a_run(tmp_path: Path, capsys) -> None:
    assert run(["report", str(tmp_path), "-o", str(tmp_path / "r")]) == 2
    assert "holds no run" in capsys.readouterr().err
    assert run(["report", str(tmp_path / "missing"), "-o", str(tmp_path / "r")]) == 2


def test_summary_table(run_dirs) -> None:
    with ResultStore.open(run_dirs[0], readonly=True) as store:
        table = summary_table(store)
    console = Console(file=io.StringIO(), width=120)
    console.print(table)
    text = console.file.getvalue()
    assert "a_b & c%: 8 scored episode(s)" in text
    assert "Thermal/Energy" in text and "Spatial Boundary" in text
    row = next(line for line in text.splitlines() if line.strip("│ ").startswith("all"))
    assert [t for t in row.split() if t != "│"] == ["all", "8", "2", "0.38", "0.12", "0.38",
                                                   "0.12", "0.31", "0.35"]
    assert "2 faulted episode(s) counted as failures" in " ".join(text.split())


def test_report_without_matplotlib(run_dirs, tmp_path: Path, capsys, monkeypatch) -> None:
    from fsvla.report import figures

    def missing(*_args: object) -> None:
        raise figures.FiguresUnavailable("figures need matplotlib: pip install 'fsvla[report]'")

    monkeypatch.setattr(figures, "_figure", missing)
    assert run(["report", str(run_dirs[0]), "-o", str(tmp_path / "r"), "--resamples", "20"]) == 1
    err = capsys.readouterr().err
    assert "pip install 'fsvla[report]'" in err and "Traceback" not in err
    assert run(["report", str(run_dirs[0]), "-o", str(tmp_path / "r"), "--resamples", "20",
                "--no-figures", "--formats", "md"]) == 0
