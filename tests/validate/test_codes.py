"""The FSV7xx catalogue: every code is documented, with the meaning the code table gives."""

from __future__ import annotations

import re
from pathlib import Path

from fsvla.validate import codes

DOCS = Path(__file__).resolve().parents[2] / "docs"


def test_every_code_is_in_the_table_and_the_docs() -> None:
    constants = {v for k, v in vars(codes).items() if k.isupper() and isinstance(v, str)}
    assert constants == set(codes.CODES)
    assert all(re.fullmatch(r"FSV7\d\d", code) for code in codes.CODES)
    rows = {m.group(1): m.group(2) for m in re.finditer(
        r"^\| (FSV7\d\d) \| (?:warning|error) \| ([^|]+) \|", (DOCS / "validate.md").read_text(
            encoding="utf-8"), re.MULTILINE)}
    assert {code: meaning.strip() for code, meaning in rows.items()} == codes.CODES
    language = (DOCS / "language.md").read_text(encoding="utf-8")
    assert "validate.md#diagnostic-codes-fsv7xx" in language
    assert all(code in language for code in ("FSV701", "FSV702", "FSV703", "FSV704", "FSV730"))
