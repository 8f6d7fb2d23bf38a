"""``stewartid reproduce``: the paper's Section 5 (Tables 3-6) with figures and a report."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def reproduce(
    out: Annotated[Path, typer.Option("--out", metavar="DIR", help="Output folder (created if missing).")]
    = Path("results/reproduce"),
    quick: Annotated[bool, typer.Option("--quick",
                                        help="Shortened records (6 s per experiment) for CI "
                                             "and tests.")] = False,
    jobs: Annotated[int | None, typer.Option("--jobs", metavar="N", min=1,
                                             help="Worker processes (default: all cores).")]
    = None,
    force: Annotated[bool, typer.Option("--force",
                                        help="Overwrite the results of an earlier run in "
                                             "--out.")] = False,
    seed: Annotated[int, typer.Option("--seed", metavar="N", min=0, help="Seed of the simulated noise.")]
    = 0,
) -> None:
    """Regenerate the paper's Tables 3-6 on the simulated plant, beside the published values:
    every method at Coulomb friction 0, 5 and 30 N·m, with tables (Markdown, CSV),
    results.json, figures (PNG, SVG) and report.md/report.html."""
    from stewartid.reproduction.run import run_reproduce

    output = run_reproduce(out=out, quick=quick, jobs=jobs, force=force, seed=seed,
                           progress=True)
    typer.echo(f"wrote {len(output.files)} files to {output.directory} in "
               f"{output.runtime_s:.1f} s; report: {output.directory / 'report.md'}")
    from stewartid.reproduction.report import summary_lines

    for line in summary_lines(output.results):
        typer.echo("  " + line.replace("**", ""))
