"""The table of a sweep campaign: a row per run (input order: run, the parameters, seed, status,
message, the statistics, wall_time[, bag]), written as CSV or Parquet and read back.

The campaign's metadata (`Campaign.metadata`: which parameters are grid axes and which are
sampled, the seed, the scenario) travels with the table: in a Parquet file's schema metadata,
beside a CSV file as FILE.campaign.json (`metadata_path`), since a CSV column's values cannot
tell a grid from draws. Read back only when its parameters are the table's.
"""
from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import Any

from multilift_tools.campaign.plan import Campaign, RunSpec
from multilift_tools.campaign.runs import STATISTICS
from multilift_tools.campaign.spec import format_value


def table_columns(campaign: Campaign, bags: bool) -> list[str]:
    """run, the parameters, seed, status, message, the statistics, wall_time[, bag]."""
    return ['run', *campaign.keys, 'seed', 'status', 'message', *STATISTICS, 'wall_time',
            *(['bag'] if bags else [])]


def make_row(run: RunSpec, result: dict[str, Any]) -> dict[str, Any]:
    """A table row from a run's spec and `run_one`'s result."""
    return {'run': run.index, **run.params, 'seed': run.seed, **result}


def table_text(columns: list[str], rows: list[dict]) -> str:
    """CSV: floats in full precision (repr), None as an empty field, lists as JSON."""
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator='\n')
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_csv_cell(row.get(c)) for c in columns])
    return stream.getvalue()


def _csv_cell(value: Any) -> str:
    if value is None:
        return ''
    if isinstance(value, float):
        return repr(value)
    return format_value(value)


def metadata_path(path: Path) -> Path:
    """Where a CSV table's campaign metadata lies: FILE.campaign.json beside it."""
    return path.with_name(path.name + '.campaign.json')


def write_table(path: Path, columns: list[str], rows: list[dict],
                metadata: dict | None = None) -> None:
    """Parquet (pyarrow) when `path` ends in .parquet, CSV otherwise; rows as given; the
    metadata in the Parquet file or beside the CSV (`metadata_path`; a CSV written without
    metadata removes an older one's)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix != '.parquet':
        path.write_text(table_text(columns, rows))
        sidecar = metadata_path(path)
        if metadata is not None:
            sidecar.write_text(json.dumps(metadata, indent=1) + '\n')
        else:
            sidecar.unlink(missing_ok=True)
        return
    import pyarrow as pa
    import pyarrow.parquet as pq
    arrays = [_arrow_column(pa, [row.get(c) for row in rows]) for c in columns]
    table = pa.Table.from_arrays(arrays, names=columns)
    if metadata is not None:
        table = table.replace_schema_metadata({'multilift.campaign': json.dumps(metadata)})
    pq.write_table(table, path)


def _arrow_column(pa, values: list):
    """int64, float64, bool or string (lists and mixed kinds as their JSON text)."""
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present):
        return pa.array(values, pa.bool_())
    if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return pa.array(values, pa.int64())
    if present and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                       for v in present):
        return pa.array([None if v is None else float(v) for v in values], pa.float64())
    return pa.array([None if v is None else format_value(v) for v in values], pa.string())


def read_table(path: Path) -> tuple[list[str], list[dict], dict]:
    """(columns, rows, campaign metadata or {}) of a sweep table, Parquet or CSV (CSV cells:
    numbers where they parse, '' as None; the metadata from FILE.campaign.json when its grid
    and sampled keys are the table's parameter columns)."""
    if path.suffix == '.parquet':
        import pyarrow.parquet as pq
        table = pq.read_table(path)
        meta = (table.schema.metadata or {}).get(b'multilift.campaign')
        return table.column_names, table.to_pylist(), json.loads(meta) if meta else {}
    with path.open(newline='') as stream:
        reader = csv.DictReader(stream)
        rows = [{k: _csv_value(v) for k, v in row.items()} for row in reader]
        columns = list(reader.fieldnames or [])
    return columns, rows, _csv_metadata(path, columns)


def _csv_metadata(path: Path, columns: list[str]) -> dict:
    """FILE.campaign.json when it describes this table's parameters, else {}."""
    try:
        meta = json.loads(metadata_path(path).read_text())
    except (OSError, ValueError):
        return {}
    if not isinstance(meta, dict) or 'run' not in columns or 'seed' not in columns:
        return {}
    params = columns[columns.index('run') + 1:columns.index('seed')]
    keys = [*meta.get('grid', {}), *meta.get('sample', {})]
    return meta if sorted(keys) == sorted(params) else {}


def _csv_value(text: str | None) -> Any:
    if text is None or text == '':
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text
