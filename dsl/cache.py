"""The result cache of `fsvla check`: a file's diagnostics, kept until any input changes.

One entry per checked file and context, in a folder of the user's cache
(:func:`cache_folder`). The entry is named by a SHA-256 over the context: the fsvla
code that checks (:func:`code_fingerprint`: fsvla's version, the grammar, every module
of this package, the lark, pydantic and Python versions), the current folder, the
folder names are shown relative to, the allowed roots and the path given. It holds the
diagnostics, the sources they quote, and every :data:`~fsvla.dsl.loader.Fact` the load
depended on: the SHA-256 of the file's text and of every base it extends, each path it
resolved, each file it looked for (bases, assets), found or not. A lookup asks each of
those questions again and uses the entry only when every answer is the same, so a
change to any input, or a new file that a search would now find first, is a miss.

The cache is an accelerator, never a source of truth: an entry that cannot be read or
decoded is a miss, a write that fails is skipped, and entries are written whole (a
temporary file, then :func:`os.replace`). Deleting the folder at any time is safe.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from importlib.util import find_spec
from pathlib import Path

from pydantic import BaseModel, ConfigDict

from .diagnostics import Diagnostic
from .loader import Fact, LoadResult, ScenarioLoader

#: Environment variable naming the cache folder (fsvla's; results go in its `check/`).
CACHE_DIR_VARIABLE = "FSVLA_CACHE_DIR"
#: Environment variable that turns the cache off when set to anything but "" or "0".
NO_CACHE_VARIABLE = "FSVLA_NO_CACHE"
#: Version of the entry layout; part of every entry's name.
ENTRY_FORMAT = 1

_PACKAGE_DIR = Path(__file__).resolve().parent


@dataclass
class CheckedFile:
    """What `fsvla check` prints of one file: its diagnostics and the sources they quote
    (a :class:`~fsvla.dsl.loader.LoadResult` without the IR)."""

    path: str
    diagnostics: list[Diagnostic]
    abstract: bool = False
    sources: dict[str, str] = field(default_factory=dict)

    @classmethod
    def of(cls, result: LoadResult) -> CheckedFile:
        return cls(result.path, result.diagnostics, result.abstract, result.sources)

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if d.is_error]

    @property
    def ok(self) -> bool:
        return not self.errors


class CacheEntry(BaseModel):
    """One cached check, as stored: the context's hash, the facts it holds while, the result."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    format: int
    context: str
    inputs: tuple[Fact, ...]
    path: str
    abstract: bool
    diagnostics: tuple[Diagnostic, ...]
    sources: dict[str, str]


def cache_folder(environ: Mapping[str, str] | None = None) -> Path | None:
    """The folder of check results, or None when the cache is off.

    ``$FSVLA_CACHE_DIR/check`` when that is set, else ``$XDG_CACHE_HOME/fsvla/check``
    (an absolute XDG_CACHE_HOME only, as the XDG spec says), else ``~/.cache/fsvla/check``;
    None when FSVLA_NO_CACHE is set (to anything but "" or "0") or no home is known.
    """
    environ = os.environ if environ is None else environ
    if environ.get(NO_CACHE_VARIABLE, "") not in ("", "0"):
        return None
    if environ.get(CACHE_DIR_VARIABLE):
        return Path(environ[CACHE_DIR_VARIABLE]) / "check"
    xdg = environ.get("XDG_CACHE_HOME", "")
    if xdg and Path(xdg).is_absolute():
        return Path(xdg) / "fsvla" / "check"
    try:
        return Path.home() / ".cache" / "fsvla" / "check"
    except (RuntimeError, KeyError):  # no HOME and no password entry
        return None


@lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """SHA-256 over what turns a file into diagnostics: fsvla's version, the grammar, the
    source of every module of the language package, and the lark, pydantic and Python
    versions (lark's by its `__init__.py`, found without importing lark)."""
    import pydantic
    import pydantic_core

    from .. import __version__
    from ..resources import grammar_path

    digest = hashlib.sha256()
    for label, value in (("fsvla", __version__), ("python", sys.version),
                         ("pydantic", pydantic.VERSION), ("pydantic-core", pydantic_core.__version__)):
        digest.update(f"{label}={value}\0".encode())
    lark = find_spec("lark")
    files = {"grammar": grammar_path()}
    files.update((str(p.relative_to(_PACKAGE_DIR)), p) for p in sorted(_PACKAGE_DIR.rglob("*.py")))
    if lark is not None and lark.origin:
        files["lark"] = Path(lark.origin)
    for label, path in files.items():
        digest.update(f"{label}\0".encode())
        digest.update(hashlib.sha256(path.read_bytes()).digest())
    return digest.hexdigest()


class CheckCache:
    """Check results in ``folder``: :meth:`load` gives a file's from its entry while every
    input is unchanged, and otherwise loads it with ``loader`` and stores the entry."""

    def __init__(self, loader: ScenarioLoader, folder: Path):
        self.loader = loader
        self.folder = folder

    def load(self, path: Path) -> CheckedFile:
        """The diagnostics of the file at ``path``, from the cache where they are current."""
        context = self.context(path)
        target = self.folder / f"{context}.json"
        cached = self._lookup(target, context)
        if cached is not None:
            return cached
        result = self.loader.load(path)
        self._store(target, context, result)
        return CheckedFile.of(result)

    def context(self, path: Path) -> str:
        """SHA-256 naming ``path``'s entry: the checking code and what the loader was told."""
        parts = [ENTRY_FORMAT, code_fingerprint(), os.getcwd(), str(self.loader.display_root),
                 [str(root) for root in self.loader.allowed_roots], str(path)]
        return hashlib.sha256(json.dumps(parts).encode("utf-8")).hexdigest()

    def _lookup(self, target: Path, context: str) -> CheckedFile | None:
        """The entry at ``target`` when it is whole, of ``context`` and every fact holds."""
        try:
            entry = CacheEntry.model_validate_json(target.read_bytes())
        except (OSError, ValueError):  # unreadable, not JSON, or not an entry (ValidationError)
            return None
        if entry.format != ENTRY_FORMAT or entry.context != context or not entry.inputs:
            return None
        try:
            if not all(self.loader.still_holds(fact) for fact in entry.inputs):
                return None
        except (OSError, ValueError, RuntimeError):  # RuntimeError: a symbolic link loop
            return None
        return CheckedFile(entry.path, list(entry.diagnostics), entry.abstract, dict(entry.sources))

    def _store(self, target: Path, context: str, result: LoadResult) -> None:
        """Write ``result``'s entry whole, or not at all (a failure is only a lost entry)."""
        if not result.inputs:
            return
        entry = CacheEntry(format=ENTRY_FORMAT, context=context, inputs=result.inputs,
                           path=result.path, abstract=result.abstract,
                           diagnostics=tuple(result.diagnostics), sources=result.sources)
        temporary = None
        try:
            data = entry.model_dump_json().encode("utf-8")
            self.folder.mkdir(parents=True, exist_ok=True)
            handle, temporary = tempfile.mkstemp(dir=self.folder, prefix=f".{context}.", suffix=".tmp")
            with os.fdopen(handle, "wb") as stream:
                stream.write(data)
            os.replace(temporary, target)
        except (OSError, ValueError):
            if temporary is not None:
                Path(temporary).unlink(missing_ok=True)
