"""gazebot's benchmarks: each ``bench_*.py`` module times real work against a peer in the
same run."""
