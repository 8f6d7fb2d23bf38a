"""A reproduction's tables: the paper's Tables 3-6 with ours beside, every method per Coulomb level,
the largest error per method. ε: relative absolute error (%) against the simulated plant's nominal."""

from __future__ import annotations

from stewartid.reference.published import PAPER_ENTRIES, EntryKey, entry_label, entry_unit
from stewartid.reports.methods import method_name, paper_methods
from stewartid.reports.tables import Cell, ResultTable
from stewartid.reproduction.comparison import ComparisonResults


def _entry_cells(key: EntryKey) -> list[Cell]:
    return [entry_label(key), entry_unit(key)]


def paper_table(results: ComparisonResults, number: int) -> ResultTable:
    """The paper's Table ``number`` (3-6): per method our value and ε, then the paper's; both nominals."""
    published = results.published.table(number)
    letters = paper_methods()
    methods = [name for name, letter in letters.items() if letter in published.methods]
    columns = ["Parameter", "Unit"]
    kinds = ["text", "text"]
    for method in methods:
        letter = letters[method]
        columns += [f"{letter}: ours", f"{letter}: ε ours (%)",
                    f"{letter}: paper", f"{letter}: ε paper (%)"]
        kinds += ["value", "eps", "published", "published"]
    columns += ["Nominal (ours)", "Nominal (paper)"]
    kinds += ["value", "published"]
    rows = []
    notes = []
    keys = [k for k in PAPER_ENTRIES if k[0] in published.matrices]
    for key in keys:
        row = _entry_cells(key)
        for method in methods:
            ours = results.run(method, published.coulomb)
            entry = published.results[letters[method]][key]
            row += [None, None] if ours is None else [ours.value(key), results.eps(ours, key)]
            row += [entry.value, entry.eps]
            if entry.note:
                notes.append(f"{letters[method]}, {entry.label}: {entry.note}.")
        row += [results.nominal(key), results.published.nominal[key]]
        rows.append(tuple(row))
    missing = [method_name(m) for m in methods if results.run(m, published.coulomb) is None]
    if missing:
        notes.append(f"Not run here: {', '.join(missing)} (— in the table).")
    label = " and ".join(f"Method {letters[m]}" for m in methods)
    title = (f"Table {number}: {label}, Coulomb friction {published.coulomb:g} N·m "
             f"({published.frequency_hz:g} Hz sine excitation)")
    return ResultTable(f"table{number}", title, tuple(columns), tuple(kinds), tuple(rows),
                       tuple(notes))


def comparison_table(results: ComparisonResults, coulomb: float) -> ResultTable:
    """Every method at one Coulomb level: value and ε per entry, with the paper's where it reports them."""
    columns = ["Parameter", "Unit", "Nominal"]
    kinds = ["text", "text", "value"]
    runs = [r for r in (results.run(m, coulomb) for m in results.methods) if r is not None]
    for run in runs:
        columns += [method_name(run.method), "ε (%)"]
        kinds += ["value", "eps"]
    letters = paper_methods()
    reported = [run.method for run in runs
                if results.published_entry(run.method, coulomb, PAPER_ENTRIES[0])]
    for method in reported:
        columns += [f"paper {letters[method]}", "ε paper (%)"]
        kinds += ["published", "published"]
    rows = []
    for key in PAPER_ENTRIES:
        row = [*_entry_cells(key), results.nominal(key)]
        for run in runs:
            row += [run.value(key), results.eps(run, key)]
        for method in reported:
            entry = results.published_entry(method, coulomb, key)
            row += [entry.value, entry.eps]
        rows.append(tuple(row))
    title = f"All methods, Coulomb friction {coulomb:g} N·m"
    return ResultTable(f"comparison_coulomb{coulomb:g}", title, tuple(columns), tuple(kinds),
                       tuple(rows))


def summary_table(results: ComparisonResults) -> ResultTable:
    """Largest ε (%) over the 20 entries, per method and Coulomb level, ours and the paper's."""
    columns = ["Method", "Coulomb (N·m)", "max ε Mt (%)", "entry", "max ε Bt (%)", "entry",
               "paper max ε (%)", "paper entry"]
    kinds = ["text", "text", "eps", "text", "eps", "text", "published", "text"]
    rows = []
    for method in results.methods:
        for level in results.coulomb_levels:
            run = results.run(method, level)
            if run is None:
                continue
            key_m, eps_m = results.worst(run, "M")
            key_b, eps_b = results.worst(run, "B")
            paper = results.published_worst(method, level)
            rows.append((method_name(method), f"{level:g}", eps_m, entry_label(key_m),
                         eps_b, entry_label(key_b),
                         None if paper is None else paper[1],
                         None if paper is None else entry_label(paper[0])))
    return ResultTable("summary", "Largest error per method and Coulomb level",
                       tuple(columns), tuple(kinds), tuple(rows))


def build_tables(results: ComparisonResults) -> list[ResultTable]:
    """All tables of a run: summary, the paper's Tables 3-6, one comparison per level."""
    tables = [summary_table(results)]
    tables += [paper_table(results, n) for n in sorted(results.published.tables)]
    tables += [comparison_table(results, level) for level in results.coulomb_levels]
    return tables


__all__ = ["build_tables", "comparison_table", "paper_table", "summary_table"]
