"""Sweep campaigns (`multilift sweep`, `multilift plot-sweep`): parse --set and --sample,
expand the grid, draw the samples, fly the runs, build and write the table.

- `spec`: the --set and --sample options, the scenario edits they make (KEY paths, values);
- `plan`: a checked campaign and its runs, each with its own seed;
- `runs`: one run (`run_one`) or a task's runs as engine batches (`run_chunk`), never raising;
- `table`: the table of the runs' rows, CSV or Parquet, written and read back;
- `sweep`: `multilift sweep`, the executor: tasks of up to 64 runs on a Dask cluster;
- `plot_sweep`: `multilift plot-sweep`, figures and the worst runs of a sweep table.

The first four are the campaign's API, imported here. No Dask in them, so every piece is
unit-testable and `run_one` is a plain top-level function a Dask scheduler and its workers can
unpickle by reference (its arguments are plain data: the scenario's YAML mapping and the run's
overrides).
"""
from multilift_tools.campaign.plan import Campaign, RunSpec, build_campaign, load_base, run_seeds
from multilift_tools.campaign.runs import (STATISTICS, STATUSES, error_message, run_chunk, run_one,
                                           run_statistics_row)
from multilift_tools.campaign.spec import (DISTRIBUTIONS, GridAxis, SampleSpec, SweepError,
                                           apply_edit, edited, format_value, parse_key,
                                           parse_sample, parse_set, parse_value, split_values)
from multilift_tools.campaign.table import (make_row, metadata_path, read_table, table_columns,
                                            table_text, write_table)

__all__ = ['Campaign', 'DISTRIBUTIONS', 'GridAxis', 'RunSpec', 'STATISTICS', 'STATUSES',
           'SampleSpec', 'SweepError', 'apply_edit', 'build_campaign', 'edited', 'error_message',
           'format_value', 'load_base', 'make_row', 'metadata_path', 'parse_key', 'parse_sample',
           'parse_set', 'parse_value', 'read_table', 'run_chunk', 'run_one', 'run_seeds',
           'run_statistics_row', 'split_values', 'table_columns', 'table_text', 'write_table']
