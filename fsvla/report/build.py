"""A whole report as data: the protocol header, every table, the §5.2 statements and the
dissected episode. :func:`build_report` computes it from loaded runs; the writers
(:mod:`fsvla.report.write`) only format it, so every format shows the same numbers.
"""

from __future__ import annotations

from collections.abc import Sequence

from pydantic import BaseModel, ConfigDict

from fsvla.report.data import RunData
from fsvla.report.dissection import Dissection, dissect
from fsvla.report.protocol import Protocol, protocol
from fsvla.report.tables import (
    SEVERITY_DIMENSIONS,
    AggregateTable,
    Derived,
    GroupTable,
    Settings,
    aggregate_table,
    derived,
    group_table,
    overall_statements,
    severity_table,
)

#: Group tables in the order a report shows them.
GROUPINGS = ("suite", "category", "embodiment")


class Report(BaseModel):
    """Everything one ``fsvla report`` shows."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    protocol: Protocol
    aggregate: AggregateTable  # Table 2
    groups: dict[str, GroupTable]  # Table 3 (suite), per category, per embodiment
    severity: dict[str, GroupTable]  # Fig. 4: per level of L, W and V (severity_table)
    derived: tuple[Derived, ...]  # §5.2, per policy
    statements: tuple[str, ...]  # §5.2, across policies
    dissection: Dissection | None  # Fig. 5 / Table 4

    @property
    def policies(self) -> tuple[str, ...]:
        return tuple(r.label for r in self.aggregate.rows)


def build_report(runs: Sequence[RunData], *, episode: str | None = None,
                 settings: Settings | None = None) -> Report:
    """Compute the report of ``runs`` (one policy each)."""
    settings = settings or Settings()
    table = aggregate_table(runs, settings)
    groups = {by: group_table(runs, by, settings) for by in GROUPINGS}
    severity = {by: severity_table(runs, by, settings) for by in SEVERITY_DIMENSIONS}
    return Report(
        protocol=protocol(runs, settings), aggregate=table, groups=groups, severity=severity,
        derived=tuple(derived(r, settings.confidence) for r in runs),
        statements=tuple(overall_statements(table, groups["suite"])),
        dissection=dissect(runs, episode))


__all__ = ["GROUPINGS", "Report", "build_report"]
