"""Files to checked scenarios: reading, `extends` resolution, allowed roots.

Loading never executes anything from a file. Every path a scenario names (the
file it extends, mesh and URDF assets) is resolved relative to the file that
names it and must stay inside the allowed roots, which default to the folder of
the file being checked; a scenario from a stranger cannot make fsvla read
``/etc/passwd`` or ``../../secrets``.

Every question a load asks of the file system (what a path resolves to, whether a
file is there, what a file holds) is recorded with its answer as a :data:`Fact`; the
result carries them (``LoadResult.inputs``), so that a cache of results
(:mod:`fsvla.dsl.cache`) can tell whether a load would still give the same result.
Importing this module is cheap: the parser and the checks load with the first file.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from .diagnostics import Diagnostic, DiagnosticSink, Severity
from .spans import Span

if TYPE_CHECKING:
    from . import ast
    from .models import Scenario

MAX_FILE_BYTES = 1_000_000
MAX_EXTENDS_DEPTH = 16
BASE_FOLDER = "_base"

#: One thing a load learnt from the file system: (question, path, answer). The questions
#: are "resolve" (answer: the resolved path), "is_file" ("yes" or "no") and "read" (the
#: :func:`read_digest` of what reading the file gave).
Fact = tuple[str, str, str]


@dataclass
class LoadResult:
    """What checking one file produced: the IR (None on errors) and every diagnostic."""

    path: str
    scenario: Scenario | None
    diagnostics: list[Diagnostic]
    abstract: bool = False
    sources: dict[str, str] = field(default_factory=dict)  # file -> text, for rendering
    inputs: tuple[Fact, ...] = ()  # what the load asked of the file system, in order

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if d.is_error]

    @property
    def ok(self) -> bool:
        return not self.errors


class ScenarioLoader:
    """Loads .fsv files; caches parsed files so a shared base is parsed once per run."""

    def __init__(self, allowed_roots: Sequence[Path] = (), display_root: Path | None = None):
        self.allowed_roots = [Path(r).resolve() for r in allowed_roots]
        self.display_root = (display_root or Path.cwd()).resolve()
        self._parsed: dict[Path, tuple[ast.ScenarioDecl | None, list[Diagnostic], str, str]] = {}
        self._facts: list[Fact] = []

    # ------------------------------------------------------------ public
    def load(self, path: Path | str) -> LoadResult:
        """Check the file at ``path``; the result lists the facts of the file system it used."""
        self._facts = []
        result = self._load(Path(path))
        result.inputs = tuple(self._facts)
        return result

    def still_holds(self, fact: Fact) -> bool:
        """Whether the file system answers ``fact``'s question as it did (an unknown
        question never holds)."""
        question, where, answer = fact
        return _ASK.get(question, _unknown)(self, Path(where)) == answer

    def _load(self, given: Path) -> LoadResult:
        from .check import ScenarioChecker
        from .merge import merge

        path = self._resolve(given)
        roots = self.allowed_roots or [path.parent]
        display = self.display(path)
        decl, diagnostics, text = self._parse(path)
        sources = {display: text}
        if decl is None:
            return LoadResult(display, None, diagnostics, sources=sources)
        sink = DiagnosticSink()
        for d in diagnostics:
            sink.add(d)
        chain = self._chain(path, decl, roots, sink, sources)
        if sink.has_errors:
            return LoadResult(display, None, sink.sorted(), decl.abstract, sources)
        merged = merge([c for _, c in chain], sink)
        digest = source_digest("\0".join(sources[self.display(p)] for p, _ in chain))
        lineage = tuple(self.display(p) for p, _ in reversed(chain[:-1]))
        checker = ScenarioChecker(decl, merged, sink, self._path_resolver(path, roots, sink),
                                  lineage, digest)
        scenario = checker.check()
        return LoadResult(display, scenario, _with_overflow_note(sink), decl.abstract, sources)

    def loads(self, text: str, name: str = "<string>") -> LoadResult:
        """Check scenario text that has no file; `extends` resolves from the current folder."""
        from .check import ScenarioChecker
        from .merge import merge

        decl, diagnostics = self._parse_text(text, name)
        if decl is None:
            return LoadResult(name, None, diagnostics, sources={name: text})
        sink = DiagnosticSink()
        for d in diagnostics:
            sink.add(d)
        sources = {name: text}
        base = Path.cwd().resolve()
        roots = self.allowed_roots or [base]
        chain = [(base / name, decl)]
        if decl.extends is not None:
            chain = self._chain(base / name, decl, roots, sink, sources)
        merged = merge([c for _, c in chain], sink)
        checker = ScenarioChecker(decl, merged, sink, self._path_resolver(base / name, roots, sink),
                                  (), source_digest(text))
        return LoadResult(name, checker.check(), sink.sorted(), decl.abstract, sources)

    def display(self, path: Path) -> str:
        try:
            return str(path.relative_to(self.display_root))
        except ValueError:
            return str(path)

    # ----------------------------------------------------------- reading
    def _parse(self, path: Path) -> tuple[ast.ScenarioDecl | None, list[Diagnostic], str]:
        if path not in self._parsed:
            display = self.display(path)
            text, problem = read_source(path, display)
            if problem is not None:
                self._parsed[path] = (None, [problem], "", read_digest(text, problem))
            else:
                decl, diagnostics = self._parse_text(text, display)
                self._parsed[path] = (decl, diagnostics, text, read_digest(text, None))
        decl, diagnostics, text, digest = self._parsed[path]
        self._facts.append(("read", str(path), digest))
        return decl, diagnostics, text

    def _resolve(self, path: Path) -> Path:
        """``path`` resolved (symbolic links followed), recorded as a fact."""
        resolved = path.resolve()
        self._facts.append(("resolve", str(path), str(resolved)))
        return resolved

    def _is_file(self, path: Path) -> bool:
        """Whether ``path`` is a file, recorded as a fact."""
        found = path.is_file()
        self._facts.append(("is_file", str(path), _yes_no(found)))
        return found

    @staticmethod
    def _parse_text(text: str, name: str) -> tuple[ast.ScenarioDecl | None, list[Diagnostic]]:
        """The AST, or None and every syntax error (lark's parse recovers to find them all)."""
        from .build import build_ast
        from .parser import parse_tree  # imports lark: only the commands that read files need it

        tree, diagnostics = parse_tree(text, name)
        if tree is None:
            return None, diagnostics
        return build_ast(tree, name), diagnostics

    # ----------------------------------------------------------- extends
    def _chain(self, path: Path, decl: ast.ScenarioDecl, roots: list[Path], sink: DiagnosticSink,
               sources: dict[str, str]) -> list[tuple[Path, ast.ScenarioDecl]]:
        """The inheritance chain, root base first and ``decl`` last."""
        chain = [(path, decl)]
        current_path, current = path, decl
        while current.extends is not None:
            extends = current.extends
            target = self._resolve_extends(current_path, extends, roots, sink)
            if target is None:
                return chain[::-1]
            visited = [p for p, _ in chain]
            if target in visited or len(chain) > MAX_EXTENDS_DEPTH:
                cycle = [c.name.value for _, c in chain] + [self._peek_name(target)]
                sink.error("FSV402", "cyclic inheritance: " + " extends ".join(cycle), extends.span,
                           "extends a scenario that extends this one",
                           help="a scenario may not extend itself, directly or through others")
                return chain[::-1]
            base_decl, diagnostics, text = self._parse(target)
            sources[self.display(target)] = text
            if base_decl is None:
                sink.error("FSV406", f"the base scenario `{extends.target}` has errors", extends.span,
                           "cannot extend it", notes=[f"{d.span}: {d.code} {d.message}" for d in diagnostics[:5]],
                           help=f"run `fsvla check {self.display(target)}`")
                return chain[::-1]
            if not extends.is_path and base_decl.name.value != extends.target:
                sink.error("FSV401", f"{self.display(target)} defines scenario `{base_decl.name.value}`, "
                           f"not `{extends.target}`", extends.span, "the names differ",
                           help=f"extend `{base_decl.name.value}` by path (`extends \"{self.display(target)}\"`), "
                                "or make the file name and the scenario name agree")
                return chain[::-1]
            chain.append((target, base_decl))
            current_path, current = target, base_decl
        return chain[::-1]

    def _peek_name(self, path: Path) -> str:
        decl = self._parse(path)[0]
        return decl.name.value if decl else path.stem

    def _resolve_extends(self, path: Path, extends: ast.Extends, roots: list[Path],
                         sink: DiagnosticSink) -> Path | None:
        if extends.is_path:
            candidate = self._resolve(path.parent / extends.target)
            if not _inside(candidate, roots):
                _outside_roots(sink, extends.span, extends.target, roots)
                return None
            if self._is_file(candidate):
                return candidate
            sink.error("FSV401", f"no file `{extends.target}` to extend", extends.span, "not found",
                       help=f"the path is relative to the scenario's folder (`{self.display(path.parent)}`)")
            return None
        searched = list(_base_candidates(path, extends.target, roots))
        for candidate in searched:
            if candidate != path and self._is_file(candidate):
                return candidate
        sink.error("FSV401", f"no scenario `{extends.target}` to extend", extends.span, "not found",
                   notes=[f"looked for {self.display(c)}" for c in searched[:6]],
                   help=f"put `{extends.target}.fsv` beside this file or in a `{BASE_FOLDER}/` folder "
                        "above it, or write a path: `extends \"../base.fsv\"`")
        return None

    # ------------------------------------------------------------- assets
    def _path_resolver(self, path: Path, roots: list[Path], sink: DiagnosticSink):
        def resolve(value: ast.String) -> str | None:
            candidate = self._resolve(path.parent / value.value)
            if not _inside(candidate, roots):
                _outside_roots(sink, value.span, value.value, roots)
                return None
            if not self._is_file(candidate):
                sink.error("FSV404", f"asset file `{value.value}` not found", value.span, "no such file",
                           help=f"paths are relative to the scenario's folder (`{self.display(path.parent)}`)")
                return None
            return str(candidate)
        return resolve


def source_digest(text: str) -> str:
    """SHA-256 of a scenario's text. A string given to ``loads`` may hold lone surrogates
    (a file never does: it is decoded strictly), which plain UTF-8 cannot encode."""
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


def read_digest(text: str, problem: Diagnostic | None) -> str:
    """What reading a file gave, as one string: the SHA-256 of its text, or of the
    diagnostic that says why it has none."""
    if problem is None:
        return source_digest(text)
    return "unreadable:" + hashlib.sha256(problem.model_dump_json().encode("utf-8")).hexdigest()


def _ask_resolve(loader: ScenarioLoader, path: Path) -> str:
    return str(path.resolve())


def _ask_is_file(loader: ScenarioLoader, path: Path) -> str:
    return _yes_no(path.is_file())


def _ask_read(loader: ScenarioLoader, path: Path) -> str:
    return read_digest(*read_source(path, loader.display(path)))


def _unknown(loader: ScenarioLoader, path: Path) -> None:
    return None


def _yes_no(found: bool) -> str:
    return "yes" if found else "no"


#: How each question of a :data:`Fact` is asked again.
_ASK = {"resolve": _ask_resolve, "is_file": _ask_is_file, "read": _ask_read}


def _with_overflow_note(sink: DiagnosticSink) -> list[Diagnostic]:
    """The sink's diagnostics, plus a note when it stopped recording some."""
    diagnostics = sink.sorted()
    if sink.dropped and diagnostics:
        last = diagnostics[-1]
        diagnostics.append(Diagnostic(code="FSV900", severity=Severity.WARNING,
                                      message=f"... and {sink.dropped} more diagnostics not shown",
                                      span=last.span, label="stopped here",
                                      help="fix the problems above and check again"))
    return diagnostics


def _base_candidates(path: Path, name: str, roots: list[Path]) -> Iterable[Path]:
    folder = path.parent
    yield folder / f"{name}.fsv"
    while True:
        yield folder / BASE_FOLDER / f"{name}.fsv"
        if any(folder == root for root in roots) or folder.parent == folder or not _inside(folder.parent, roots):
            return
        folder = folder.parent


def _inside(path: Path, roots: list[Path]) -> bool:
    return any(path == root or path.is_relative_to(root) for root in roots)


def _outside_roots(sink: DiagnosticSink, span: Span, written: str, roots: list[Path]) -> None:
    sink.error("FSV403", f"`{written}` is outside the allowed folders", span, "outside the allowed roots",
               notes=[f"allowed: {root}" for root in roots[:4]],
               help="keep assets and base scenarios inside the scenario's folder, or allow another "
                    "folder with `--root`")


def read_source(path: Path, display: str) -> tuple[str, Diagnostic | None]:
    """The text of a scenario file, or a diagnostic saying why it cannot be read."""
    span = Span.point(display, 1, 1)
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            return "", Diagnostic(code="FSV903", message=f"file too large ({size:,} bytes)", span=span,
                                  label="not read",
                                  help=f"a scenario file is at most {MAX_FILE_BYTES:,} bytes; split it "
                                       "with `extends`")
        data = path.read_bytes()
    except FileNotFoundError:
        return "", Diagnostic(code="FSV901", message="file not found", span=span, label="no such file")
    except IsADirectoryError:
        return "", Diagnostic(code="FSV901", message="is a folder, not a file", span=span, label="a folder")
    except OSError as error:
        return "", Diagnostic(code="FSV901", message=f"cannot read the file: {error.strerror}", span=span,
                              label="not read")
    if b"\0" in data:
        return "", Diagnostic(code="FSV902", message="not a text file", span=span,
                              label="contains NUL bytes", help="a scenario is UTF-8 text")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        column = error.start - (data.rfind(b"\n", 0, error.start) + 1) + 1
        return "", Diagnostic(code="FSV902", message="not valid UTF-8 text",
                              span=Span.point(display, line, column), label="invalid byte",
                              help="save the file as UTF-8")
    return text.lstrip("\ufeff"), None
