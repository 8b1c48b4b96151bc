"""Output files appear whole or not at all, and an older whole file survives a failed rewrite."""

from __future__ import annotations

from pathlib import Path

import pytest

from gazebot.io.atomic import AtomicWriter, atomic_path, part_path


def test_a_finished_block_replaces_the_target(tmp_path: Path) -> None:
    out = tmp_path / "sub" / "a.csv"
    with atomic_path(out) as tmp:
        assert tmp.parent == out.parent and tmp.suffix == ".csv" and tmp.name.startswith(".")
        tmp.write_text("new")
    assert out.read_text() == "new"
    assert sorted(p.name for p in out.parent.iterdir()) == ["a.csv"]


def test_a_failing_block_keeps_the_old_file_and_leaves_no_partial(tmp_path: Path) -> None:
    out = tmp_path / "a.csv"
    out.write_text("old")
    with pytest.raises(RuntimeError), atomic_path(out) as tmp:
        tmp.write_text("half")
        raise RuntimeError("interrupted")
    assert out.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.csv"]


def test_part_paths_of_one_target_never_collide(tmp_path: Path) -> None:
    out = tmp_path / "v.mp4"
    assert len({part_path(out) for _ in range(50)}) == 50


class _Lines(AtomicWriter):
    def __init__(self, path: Path) -> None:
        super().__init__(path)
        self._fh = self.part.open("w")

    def write(self, line: str) -> None:
        self._fh.write(line + "\n")

    def close(self) -> Path:
        self._fh.close()
        return self._commit()

    def abort(self) -> None:
        self._fh.close()
        self.part.unlink(missing_ok=True)


def test_a_streaming_writer_commits_on_normal_exit_and_aborts_on_error(tmp_path: Path) -> None:
    good, bad = tmp_path / "good.txt", tmp_path / "bad.txt"
    with _Lines(good) as w:
        w.write("x")
    with pytest.raises(ValueError), _Lines(bad) as w:
        w.write("y")
        raise ValueError("stop")
    assert good.read_text() == "x\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["good.txt"]
