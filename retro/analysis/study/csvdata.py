"""CSV text of the study's tables (chart, per frame, stability): one writer and one reader for all."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Sequence


def csv_text(header: Sequence[str], body: Iterable[Sequence[object]]) -> str:
    """A header row and the body rows as CSV text ("\\n" line ends)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(body)
    return out.getvalue()


def csv_records(text: str, columns: Sequence[str]) -> list[dict[str, str]]:
    """The rows of CSV text by column name; ValueError unless its columns are exactly `columns`."""
    reader = csv.DictReader(io.StringIO(text))
    if reader.fieldnames != list(columns):
        raise ValueError(f"CSV columns {reader.fieldnames} differ from {list(columns)}")
    return list(reader)
