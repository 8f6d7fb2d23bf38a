"""The paper's published Tables 3-6 as package data (Zhang 2020, doi:10.3390/math8020257)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from stewartid.errors import DataError
from stewartid.model.linearization import nominal_matrices
from stewartid.reference.published import (
    PAPER_ENTRIES,
    entry_label,
    entry_unit,
    load_published,
    relative_error_percent,
)


@pytest.fixture(scope="module")
def published():
    return load_published()


def test_tables_and_methods_as_in_the_paper(published):
    assert sorted(published.tables) == [3, 4, 5, 6]
    assert published.table(3).methods == ("A",) and published.table(3).coulomb == 0.0
    assert published.table(4).methods == ("A", "B") and published.table(4).matrices == ("M",)
    assert published.table(5).methods == ("A", "B") and published.table(5).matrices == ("B",)
    assert published.table(6).methods == ("B",) and published.table(6).coulomb == 30.0
    assert published.cases() == [("A", 0.0), ("A", 5.0), ("B", 5.0), ("B", 30.0)]
    # every reported (method, level) has all 20 entries, split over tables 4 and 5 at 5 N
    for method, coulomb in published.cases():
        assert all(published.entry(method, coulomb, key) for key in PAPER_ENTRIES)
    assert published.entry("B", 0.0, ("M", 0, 0)) is None


def test_relative_error_percent_by_hand():
    """ε against hand-computed values; NaN (not an exception) at a zero nominal value."""
    assert relative_error_percent(101.0, 100.0) == pytest.approx(1.0)
    assert relative_error_percent(-1178.0, -1096.0) == pytest.approx(7.481751824817518)
    assert relative_error_percent(0.0, 50.0) == pytest.approx(100.0)
    assert math.isnan(relative_error_percent(1.0, 0.0))
    eps = relative_error_percent(np.array([[2.0, 1.0]]), np.array([[4.0, 0.0]]))
    assert eps.shape == (1, 2) and eps[0, 0] == pytest.approx(50.0) and math.isnan(eps[0, 1])


def test_printed_nominal_column_matches_our_model(published, paper):
    """The paper's nominal column against our linearisation of Tables 1-2 (independent)."""
    M, B = nominal_matrices(paper)
    ours = {"M": M, "B": B}
    assert set(published.nominal) == set(PAPER_ENTRIES)
    for (matrix, row, col), value in published.nominal.items():
        computed = ours[matrix][row, col]
        assert relative_error_percent(value, computed) < 0.05, entry_label((matrix, row, col))


@pytest.mark.parametrize("number", [3, 4, 5, 6])
def test_printed_eps_consistent_with_printed_values(published, number):
    """Catches copying slips: each printed ε agrees with |value − nominal|/|nominal| to the
    paper's rounding (its Table 3 rounds 0.22 % down to 0.1 %), except the noted entry."""
    for method, entries in published.table(number).results.items():
        for key, entry in entries.items():
            eps = relative_error_percent(entry.value, published.nominal[key])
            if entry.note and "does not match" in entry.note:
                assert abs(eps - entry.eps) > 0.5, (number, method, entry.label)
                continue
            assert eps == pytest.approx(entry.eps, abs=0.13), (number, method, entry.label)
            # identified values keep the nominal's sign once typos are corrected
            assert np.sign(entry.value) == np.sign(published.nominal[key])


def test_table6_sign_typos_recorded(published):
    entries = published.table(6).results["B"]
    for key, printed in ((("B", 1, 3), 13358.0), (("B", 3, 1), 13120.0)):
        entry = entries[key]
        assert entry.corrected and entry.printed == printed and entry.value == -printed
        assert "typo" in entry.note
    uncorrected = [e for t in published.tables.values() for m in t.results.values()
                   for e in m.values() if e.corrected]
    assert len(uncorrected) == 2


def test_spot_values(published):
    """A few values read directly from the paper's tables."""
    assert published.entry("A", 5.0, ("B", 2, 2)).value == 3478  # Table 5, eps 70.6 %
    assert published.entry("A", 5.0, ("B", 2, 2)).eps == 70.6
    assert published.entry("B", 5.0, ("M", 1, 3)).value == -1178  # Table 4, eps 7.5 %
    assert published.entry("B", 30.0, ("M", 1, 3)).eps == 5.8  # Table 6 maximum
    assert published.entry("A", 0.0, ("M", 0, 4)).value == 1145  # Table 3, eps 4.5 %


def test_labels_and_units():
    assert entry_label(("M", 0, 4)) == "Mt(1,5)"
    assert entry_label(("B", 3, 1)) == "Bt(4,2)"
    assert entry_unit(("M", 3, 3)) == "kg·m²"
    assert entry_unit(("B", 0, 0)) == "N·s/m"
    assert entry_unit(("M", 0, 4)) == "kg·m"
    assert len(PAPER_ENTRIES) == 20 and len(set(PAPER_ENTRIES)) == 20


def test_bad_files_raise_clear_errors(tmp_path, published):
    with pytest.raises(DataError, match="no result table 7"):
        published.table(7)
    path = tmp_path / "bad.json"
    path.write_text("{not json")
    with pytest.raises(DataError, match="not valid JSON"):
        load_published(path)
    path.write_text(json.dumps({"nominal": {}}))
    with pytest.raises(DataError, match="top-level keys"):
        load_published(path)
    doc = {"source": {}, "nominal": {"M": {"7,1": 1.0}}, "tables": {}}
    path.write_text(json.dumps(doc))
    with pytest.raises(DataError, match="outside a 6x6 matrix"):
        load_published(path)
    doc = {"source": {}, "nominal": {}, "tables": {"3": {
        "coulomb": 0, "frequency_hz": 0.5,
        "results": {"A": {"M": {"1,1": {"value": "x", "eps": 1}}}}}}}
    path.write_text(json.dumps(doc))
    with pytest.raises(DataError, match="expected a finite number"):
        load_published(path)
