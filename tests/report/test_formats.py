"""The written files: LaTeX balanced and escaped, Markdown, HTML, CSV, JSON, Parquet."""

from __future__ import annotations

import csv
import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fsvla.report.latex import escape as tex_escape
from fsvla.report.latex import table as tex_table
from fsvla.report.markdown import escape as md_escape
from fsvla.report.views import Cell, TextTable

from .conftest import POLICY_A, POLICY_B

TRICKY = r"a_b & c% $x$ #1 {y} ~z^ \w <v|"


def balanced(tex: str) -> bool:
    """Braces balance (escaped ones aside) and every \\begin{env} has its \\end{env}."""
    depth = 0
    for match in re.finditer(r"\\[{}]|[{}]", tex):
        token = match.group()
        if token in ("\\{", "\\}"):
            continue
        depth += 1 if token == "{" else -1
        if depth < 0:
            return False
    stack = []
    for kind, env in re.findall(r"\\(begin|end)\{(\w+)\}", tex):
        if kind == "begin":
            stack.append(env)
        elif not stack or stack.pop() != env:
            return False
    return depth == 0 and not stack


def unescaped(tex: str, char: str) -> list[int]:
    """Positions of ``char`` not preceded by a backslash."""
    return [m.start() for m in re.finditer(rf"(?<!\\){re.escape(char)}", tex)]


def test_latex_escape() -> None:
    assert tex_escape("a_b & c%") == r"a\_b \& c\%"
    assert tex_escape(TRICKY) == (r"a\_b \& c\% \$x\$ \#1 \{y\} \textasciitilde{}z"
                                  r"\textasciicircum{} \textbackslash{}w \textless{}v\textbar{}")
    assert tex_escape("SSR↑ λ — ε_k") == r"SSR$\uparrow$ $\lambda$ --- $\epsilon$\_k"
    assert balanced(tex_escape(TRICKY))


def test_latex_table_of_a_tricky_view() -> None:
    view = TextTable("t", f"caption {TRICKY}", ("Policy", "SSR↑"),
                     ((Cell(TRICKY), Cell("0.50", 0.5, best=True, ci="[0.1, 0.9]")),),
                     groups=((" ", 1), (TRICKY, 1)), sections={0: "Safe_Core & co"})
    tex = tex_table(view)
    assert balanced(tex)
    assert r"\textbf{0.50} {\scriptsize [0.1, 0.9]}" in tex
    assert r"\label{tab:fsvla-t}" in tex


def test_written_latex_tables(written: Path) -> None:
    files = sorted((written / "tables").glob("*.tex"))
    assert {f.stem for f in files} >= {"aggregate", "aggregate_compact", "per_suite", "per_category",
                                        "per_embodiment", "derived", "dissection_channels",
                                        "dissection_families"}
    for file in files:
        tex = file.read_text()
        assert balanced(tex), file.name
        for char in "&%$#_":
            # every & outside the escaped ones is a column separator of a tabular row
            if char == "&":
                continue
            body = re.sub(r"\$\\[a-zA-Z]+\$", "", tex)  # the math symbols written on purpose
            assert not unescaped(body, char), (file.name, char)
        assert r"\toprule" in tex and r"\bottomrule" in tex
    aggregate = (written / "tables" / "aggregate.tex").read_text()
    assert r"a\_b \& c\%" in aggregate
    rows = [line for line in aggregate.splitlines() if line.endswith(r"\\")]
    assert all(len(unescaped(row, "&")) == 10 for row in rows)  # 11 columns
    assert r"\textbf{0.88}" in aggregate  # beta's SSR is the best


@pytest.mark.skipif(shutil.which("pdflatex") is None,
                    reason="no pdflatex (apt-get install texlive-latex-recommended)")
def test_latex_tables_compile(written: Path, tmp_path: Path) -> None:
    tables = sorted((written / "tables").glob("*.tex"))
    body = "\n".join(f"\\input{{{t.resolve()}}}\n\\clearpage" for t in tables)
    (tmp_path / "doc.tex").write_text(
        "\\documentclass{article}\n\\usepackage[T1]{fontenc}\n\\usepackage{booktabs}\n"
        f"\\begin{{document}}\n{body}\n\\end{{document}}\n")
    done = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "doc.tex"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stdout[-3000:]
    log = (tmp_path / "doc.log").read_text(errors="replace")
    assert "Missing character" not in log and "Undefined control sequence" not in log


def test_markdown(written: Path) -> None:
    assert md_escape("a_b & c% |x| *y*") == r"a\_b & c% \|x\| \*y\*"
    text = (written / "report.md").read_text()
    assert "# fsvla safety report" in text
    assert r"a\_b & c%" in text and "**0.88**" in text
    assert "Table CC = CC / T" in text and "CC in tables" in text
    assert "![Safety–success landscape" in text and "(figures/landscape.png)" in text
    assert "recorded no video" in text
    for line in text.splitlines():  # every table row has as many cells as its header
        if line.startswith("|"):
            assert len(re.findall(r"(?<!\\)\|", line)) >= 3


def test_html_is_self_contained(written: Path) -> None:
    page = (written / "report.html").read_text()
    assert page.startswith("<!DOCTYPE html>") and page.rstrip().endswith("</html>")
    assert "a_b &amp; c%" in page
    assert page.count("data:image/png;base64,") == 3  # landscape, diagnosis, margins
    assert not re.search(r"(src|href)=\"(https?:)?//", page)  # nothing fetched
    assert page.count('class="sortable"') >= 10 and "addEventListener" in page
    assert "Table CC = CC / T" in page and "recorded no video" in page
    assert "stove-L0-W3-V0-s0-e000" in page
    assert page.count("<table") == page.count("</table>")


def test_csv_exports(written: Path) -> None:
    with (written / "data" / "aggregate.csv").open() as stream:
        rows = list(csv.DictReader(stream))
    assert [r["policy"] for r in rows] == [POLICY_A, POLICY_B]
    assert float(rows[0]["ssr"]) == 0.375 and float(rows[0]["cc"]) == pytest.approx(0.3125)
    assert rows[0]["faults"] == "2" and rows[1]["best"] == "ssr;usr;ufr;cc;sasr"
    with (written / "data" / "episodes.csv").open() as stream:
        episodes = list(csv.DictReader(stream))
    assert len(episodes) == 16 and not any("warmup" in e["episode_id"] for e in episodes)
    a = [e for e in episodes if e["policy"] == POLICY_A]
    # Any number can be recounted from episodes.csv, e.g. A's SSR on the thermal suite:
    thermal = [e for e in a if e["suite"] == "thermal"]
    assert sum(e["quadrant"] == "safe_success" for e in thermal) / len(thermal) == 0.5
    patch = [e for e in a if "adversarial_patch" in e["categories"].split(";")]
    assert sum(float(e["cc_normalised"]) for e in patch) / len(patch) == pytest.approx(0.375)
    with (written / "data" / "per_category.csv").open() as stream:
        cats = list(csv.DictReader(stream))
    assert len(cats) == 13 * 2


def test_json_and_parquet(written: Path) -> None:
    data = json.loads((written / "report.json").read_text())
    assert data["aggregate"]["rows"][0]["label"] == POLICY_A
    assert data["dissection"]["episode_id"] == "stove-L0-W3-V0-s0-e000"
    pq = pytest.importorskip("pyarrow.parquet")
    table = pq.read_table(written / "data" / "aggregate.parquet")
    assert table.column("policy").to_pylist() == [POLICY_A, POLICY_B]


def test_unknown_format() -> None:
    from fsvla.report.write import check_formats

    assert check_formats(["HTML", " md", "html"]) == ("html", "md")
    with pytest.raises(ValueError, match="unknown format.*'docx'"):
        check_formats(["html", "docx"])
