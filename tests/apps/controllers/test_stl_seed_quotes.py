"""The documentation's Table 4.2 section quotes the seed's sentences (4.3.2-4.3.3) word for word."""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]


def _table_4_2_quotes() -> list[str]:
    page = (REPO / "docs" / "seed" / "controllers.md").read_text()
    rows = [ln for ln in page.splitlines() if ln.startswith("| t_")]
    quotes = [q for ln in rows for q in re.findall(r'"([^"]+)"', ln.split(" | ")[1])]
    return [part.strip() for q in quotes for part in q.split("...")]


def test_every_table_4_2_quote_in_the_readme_is_the_seeds(seed_text):
    quotes = _table_4_2_quotes()
    assert len(quotes) >= 10  # t_1 .. t_9, two of them in two parts
    seed = " ".join(seed_text.split())
    missing = [q for q in quotes if q not in seed]
    assert missing == []
