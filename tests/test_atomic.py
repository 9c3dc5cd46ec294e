"""Atomic writes: the target is replaced whole or not at all, no temporary file stays, and one
a killed writer left behind is told from one being written."""
import csv
import os
import subprocess
import sys

import pytest

from jaxswarm.runtime.atomic import abandoned_temporaries, atomic_path, write_atomically, write_csv


def test_a_write_replaces_the_file_and_leaves_nothing_behind(tmp_path):
    target = tmp_path / "deep" / "table.md"
    write_atomically(target, "first")
    write_atomically(target, b"second")
    assert target.read_text() == "second"
    assert [p.name for p in target.parent.iterdir()] == ["table.md"]


def test_a_failed_write_keeps_the_old_file_and_removes_the_temporary(tmp_path):
    target = tmp_path / "runs.csv"
    write_atomically(target, "old")
    with pytest.raises(RuntimeError, match="interrupted"):
        with atomic_path(target) as temporary:
            temporary.write_text("half")
            assert temporary.name.startswith(".runs.csv.") and temporary.parent == tmp_path
            raise RuntimeError("interrupted")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["runs.csv"]


def test_write_csv_keeps_the_column_order_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "out" / "rows.csv"
    write_csv(target, [dict(b=1, a="x"), dict(b=2, a="y,z")], columns=["b", "a"])
    with open(target, newline="", encoding="utf-8") as f:
        assert list(csv.reader(f)) == [["b", "a"], ["1", "x"], ["2", "y,z"]]
    assert [p.name for p in target.parent.iterdir()] == ["rows.csv"]


def test_only_the_temporaries_of_writers_that_stopped_are_abandoned(tmp_path):
    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)
    dead = int(ended.stdout)
    with atomic_path(tmp_path / "live.parquet") as live:
        live.write_text("being written")
        assert live.name.startswith(f".live.parquet.{os.getpid()}.")
        for name in (f".killed.parquet.{dead}.0123456789ab.tmp",  # its writer ended
                     ".old.parquet.0123456789ab.tmp"):  # no pid: nothing says it ended
            (tmp_path / name).write_text("half")
        assert [p.name for p in abandoned_temporaries(tmp_path)] == [
            f".killed.parquet.{dead}.0123456789ab.tmp"]
