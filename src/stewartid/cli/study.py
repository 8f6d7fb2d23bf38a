"""``stewartid study``: a Monte Carlo study or parameter sweep on dask.distributed."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from stewartid.errors import StewartidError


def study(
    file: Annotated[Path, typer.Argument(metavar="FILE", help="Study file (TOML): [study] fixed settings, "
                                         "[grid] swept values; see docs/studies.md.")],
    out: Annotated[Path, typer.Option("--out", metavar="DIR", help="Output folder: results.parquet/, "
                                      "report.md/.html, figures/, tables/.")],
    scheduler: Annotated[str | None, typer.Option(
        "--scheduler", metavar="ADDRESS", help="Address of an existing dask scheduler (tcp://host:8786); "
        "default: a local cluster.")] = None,
    workers: Annotated[int | None, typer.Option(
        "--workers", metavar="N", min=1, help="Worker processes of the local cluster (default: one per "
        "core).")] = None,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Continue the study in --out: compute only its missing rows.")]
    = False,
    retries: Annotated[int, typer.Option(
        "--retries", metavar="N", min=0, help="Extra attempts of a task that raises.")] = 2,
) -> None:
    """Run every (grid point, seed) of a study: simulate the six experiments, identify them
    with every method, store one row per method in OUT/results.parquet and write a report
    with figures. Finished rows survive an interruption; --resume computes the others."""
    # imported when this command runs: every command's module is imported at start-up
    from stewartid.studies import load_study, run_study

    spec = load_study(file)
    if scheduler is not None and workers is not None:
        raise StewartidError("--workers sizes the local cluster and cannot be used with "
                             "--scheduler; size the existing cluster itself.")
    run = run_study(spec, out, scheduler=scheduler, workers=workers, resume=resume,
                    retries=retries, progress=True)
    typer.echo(f"{run.computed} tasks computed, {run.skipped} already done, "
               f"{len(run.failures)} failed; {len(run.rows)} rows in "
               f"{out / 'results.parquet'} ({run.runtime_s:.1f} s); report: "
               f"{out / 'report.md'}")
    if run.failures:
        first = run.failures[0]
        raise StewartidError(f"{len(run.failures)} of {spec.size} tasks failed (first: "
                             f"{first.label}: {first.message}); see {out / 'failed.json'} "
                             "and run again with --resume to retry them.")
