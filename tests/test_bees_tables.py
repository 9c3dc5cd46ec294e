"""The bees paper's tables as sweeps/bees_tables.py quotes them: Table 6 read with its first two
columns swapped (as its text implies), Table 7 as printed, the best row by the rule of the text,
and f3's other unit as a row of Tables 2-5 only."""
import pytest

from repo_scripts import load_script

tables = load_script("sweeps/bees_tables.py")


def test_table_6_is_read_as_stdp_avgp_target():
    # Printed "0 34 137 30" under the header "avgP stdP target": avgP 34 would be below map #1's
    # shortest path (the paper's Table 1: avgP 66 at best), so 34 is stdP and 137 avgP.
    assert tables.paper_cycle_row(6, 0) == dict(cycles=0, target=30, avgP=137, stdP=34)
    assert tables.paper_cycle_row(6, 2) == dict(cycles=2, target=30, avgP=126, stdP=32)
    assert [tables.paper_cycle_row(6, i)["target"] for i in range(6)] == [30, 28, 30, 26, 20, 12]
    assert tables.paper_cells(6, 0) == ("30", "137", "34", "", "")


def test_table_7_is_read_as_printed():
    assert tables.paper_cycle_row(7, 0) == dict(cycles=0, target=13, avgP=205, stdP=72)
    assert tables.paper_cells(7, 4) == ("19", "137", "36", "", "")


def test_the_best_row_of_each_cycles_table_is_the_one_its_text_names():
    # Table 6: "the best target value was obtained when 2 iteration of cABC were executed ...
    # due to the shorter path": 0 and 2 cycles tie at 30 runs, and 126 < 137.
    paper6 = [tables.paper_cycle_row(6, i) for i in range(6)]
    assert tables.best_by_text(paper6)["cycles"] == 2
    # Table 7: "the best results are obtained for five cABC iterations" (target 19, avgP 137).
    assert tables.best_by_text([tables.paper_cycle_row(7, i) for i in range(6)])["cycles"] == 5


def _run(cycles, reached, length, variant="cabc"):
    w1, w2, w3 = tables.FIGURE_WEIGHTS["map1"]
    return dict(variant=variant, w1=w1, w2=w2, w3=w3, cycles=cycles, reached=reached,
                length=length)


def test_the_table_6_note_names_both_best_rows_and_the_runs():
    # Two runs a setting: 1 cycle arrives twice (lengths 70, 80: avgP 75), 2 cycles twice
    # (60 and 70: avgP 65, the shorter of the tie), the others once or never.
    lengths = {0: [90, None], 1: [70, 80], 2: [60, 70], 5: [None, None], 8: [100, None],
               10: [None, 95]}
    rows = [_run(c, length is not None, length if length is not None else float("inf"))
            for c, pair in lengths.items() for length in pair]
    rows += [_run(0, True, 10.0, variant="cabc, forbid_crossing")] * 2  # not cabc's
    (note,) = tables.cycles_notes(6, rows)
    assert "read as stdP, avgP, target" in note and "ours are 2 a row" in note
    assert ("the paper's 2 cycles (target 30, avgP 126; tied on target with 0 cycles, it has "
            "the shorter path)") in note
    assert "`cabc`'s 2 cycles (target 2/2, avgP 65.0)" in note


@pytest.mark.parametrize("table, has_unit_row", [(1, False), (2, True), (5, True), (6, False),
                                                  (7, False)])
def test_f3s_other_unit_is_a_row_of_tables_2_to_5(table, has_unit_row):
    labels = tables.variants(table)
    assert labels[0] == "cabc" and labels[-1] == "cabc, forbid_crossing"
    assert (f"cabc, f3 in {tables.OTHER_UNIT}" in labels) is has_unit_row
    assert {tables.UNIT, tables.OTHER_UNIT} == {"degrees", "radians"}


def test_the_note_says_so_when_no_run_arrived():
    rows = [_run(c, False, float("inf")) for c in (0, 1, 2, 5, 8, 10)]
    (note,) = tables.cycles_notes(6, rows)
    assert note.endswith("no run of `cabc` arrived.") and "ours are 1 a row" in note
