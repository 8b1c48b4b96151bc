"""``python -m benchmarks [NAME ...]``: run every ``bench_*`` module (or the named ones) and print
median timings with the ratio against the peer measured in the same run."""

from __future__ import annotations

import importlib
import pkgutil
import sys

import benchmarks
from benchmarks.common import print_results


def main(argv: list[str]) -> int:
    names = sorted(
        m.name for m in pkgutil.iter_modules(benchmarks.__path__) if m.name.startswith("bench_")
    )
    if argv:
        names = [n for n in names if any(a in n for a in argv)]
    for name in names:
        module = importlib.import_module(f"benchmarks.{name}")
        print(f"\n## {name[len('bench_') :]}")
        print_results(module.run())
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
