"""Execute every notebook in notebooks/ in place and save it with its outputs (figures included).

    python tools/run_notebooks.py [NOTEBOOK ...]

Run from the repository root after changing a notebook or anything it shows; the test suite
checks that the committed notebooks hold their outputs (tests/test_notebooks.py).
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]


def main(paths: list[str]) -> int:
    nbs = [Path(p) for p in paths] or sorted((ROOT / "notebooks").glob("*.ipynb"))
    for path in nbs:
        t0 = time.perf_counter()
        nb = nbformat.read(path, as_version=4)
        with tempfile.TemporaryDirectory() as d:
            NotebookClient(
                nb, timeout=1200, kernel_name="python3", resources={"metadata": {"path": d}}
            ).execute()
        nbformat.write(nb, path)
        print(f"{path.name}: executed and saved in {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
