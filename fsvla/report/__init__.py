"""Reports of one or many runs (one policy each), made from their result stores alone.

The paper's §5 evaluation: Table 2 (aggregate), Table 3 and the per category and
embodiment breakdowns, Fig. 3 (safety–success landscape), Fig. 4 (diagnosis under L, W,
V variation), Fig. 5 / Table 4 (process-level dissection of one episode), the §5.2
derived statements, and a protocol header. See ``docs/report.md``.

::

    runs = load_runs([Path("runs/exp1"), Path("runs/exp2")])
    report = build_report(runs)
    write_report(report, runs, Path("report"))

Importing this package imports neither matplotlib nor pyarrow (figures and Parquet
import them when made).
"""

from fsvla.report.build import Report, build_report
from fsvla.report.data import Episode, ReportInputError, RunData, load_run, load_runs
from fsvla.report.tables import Settings
from fsvla.report.terminal import summary_table
from fsvla.report.write import DEFAULT_FORMATS, FORMATS, write_report

__all__ = ["DEFAULT_FORMATS", "FORMATS", "Episode", "Report", "ReportInputError", "RunData",
           "Settings", "build_report", "load_run", "load_runs", "summary_table", "write_report"]
