"""``gazebot render eyes --out`` with a file name that is not UTF-8 (bytes a shell passes on as
they are): the image is written under exactly that name, no crash in OpenCV."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]


def _run(args: list[bytes]) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(REPO), "SDL_VIDEODRIVER": "dummy"}
    return subprocess.run(
        [sys.executable.encode(), b"-m", b"gazebot", b"render", b"eyes", *args],
        capture_output=True,
        env=env,
        timeout=120,
    )


def test_a_non_utf8_output_name_is_written_as_given(tmp_path):
    out = os.fsencode(tmp_path) + b"/eyes-\xff\xfe.png"
    res = _run([b"--width", b"64", b"--height", b"48", b"--out", out])
    assert res.returncode == 0, res.stderr.decode(errors="replace")
    assert open(out, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
    assert b"wrote " in res.stdout and b"\\udcff\\udcfe.png (64x48)" in res.stdout


def test_a_non_utf8_missing_folder_is_a_one_line_error(tmp_path):
    out = os.fsencode(tmp_path) + b"/no-\xff/eyes.jpg"
    res = _run([b"--width", b"64", b"--height", b"48", b"--out", out])
    assert res.returncode == 2
    err = res.stderr.decode()
    assert err.count("\n") == 1 and "output folder does not exist" in err and "\\udcff" in err


def test_any_input_error_naming_a_non_utf8_file_is_printed_escaped(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    missing = os.fsencode(tmp_path) + b"/rec-\xff.csv"
    res = subprocess.run(
        [sys.executable.encode(), b"-m", b"gazebot", b"phases", missing],
        capture_output=True,
        env=env,
        timeout=120,
    )
    assert res.returncode == 2
    assert res.stderr.decode().endswith("rec-\\udcff.csv: no such file\n")
