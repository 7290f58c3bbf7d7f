"""What the benchmark scripts share (imported as ``_common``: Python puts a script's own folder
first on ``sys.path``)."""

from __future__ import annotations

import csv
import os


def write_csv(path, rows) -> None:
    """Write ``rows`` (dicts with the keys of the first) to the CSV file ``path``, creating its
    folder."""
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
