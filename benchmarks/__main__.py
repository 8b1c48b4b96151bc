"""``python -m benchmarks [--markdown FILE] [NAME ...]``: run every ``bench_*`` module (or the
named ones) and print median timings with the ratio against the peer measured in the same run;
``--markdown`` also writes them as the documentation's results page (``make bench`` writes
``docs/benchmark-results.md``), with the machine and its load."""

from __future__ import annotations

import argparse
import datetime
import importlib
import os
import pkgutil
import platform
import sys
from pathlib import Path

import benchmarks
from benchmarks.common import Result, markdown_rows, print_results


def _machine() -> str:
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    return (f"{platform.python_implementation()} {platform.python_version()} on "
            f"{platform.system()} {platform.machine()}, {os.cpu_count()} cores, load average "
            f"{load} at the start")


def write_markdown(path: Path, sections: dict[str, list[Result]], machine: str) -> None:
    """The results page: one table per benchmark module."""
    today = datetime.date.today().isoformat()
    lines = [
        "# Benchmark results",
        "",
        f"Written by `make bench` on {today}: {machine}. Each line is a median over repeated runs,",
        "beside its peer measured in the same run; the ratio says how many times better ours is",
        "(above 1: ours better). [Benchmarks](benchmarks.md) says what each peer is and why.",
        "",
    ]
    for name, results in sections.items():
        lines += [f"## {name}", "", "| benchmark | ours | peer | ratio | note |",
                  "| --- | --- | --- | --- | --- |", *markdown_rows(results), ""]
    path.write_text("\n".join(lines), encoding="utf-8")


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks")
    parser.add_argument("--markdown", type=Path, help="also write the results page here")
    parser.add_argument("names", nargs="*", help="run only the modules whose name contains one")
    args = parser.parse_args(argv)
    names = sorted(
        m.name for m in pkgutil.iter_modules(benchmarks.__path__) if m.name.startswith("bench_")
    )
    if args.names:
        names = [n for n in names if any(a in n for a in args.names)]
    machine = _machine()
    sections: dict[str, list[Result]] = {}
    for name in names:
        module = importlib.import_module(f"benchmarks.{name}")
        title = name[len("bench_") :]
        print(f"\n## {title}")
        sections[title] = module.run()
        print_results(sections[title])
    if args.markdown:
        write_markdown(args.markdown, sections, machine)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
