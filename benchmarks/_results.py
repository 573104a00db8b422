"""Writing a benchmark's tables: ``<name>.json`` and ``<name>.md`` in the results folder."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any


def write_results(out: Path, name: str, data: Any, md: str) -> None:
    """Write ``data`` as ``<out>/<name>.json`` (numpy numbers as floats), ``md`` as ``.md``; print ``md``."""
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{name}.json").write_text(json.dumps(data, indent=1, default=float))
    (out / f"{name}.md").write_text(md)
    print(md)


def real_data_main(
    doc: str | None, name: str, run: Callable[[Path], Any], markdown: Callable[[Any], str]
) -> None:
    """The command line of a real-data benchmark: ``--data DIR --out DIR``, then run and write."""
    root = Path(__file__).resolve().parents[1]
    ap = argparse.ArgumentParser(description=doc.splitlines()[0] if doc else None)
    ap.add_argument("--data", type=Path, default=root.parent / "shared" / "data")
    ap.add_argument("--out", type=Path, default=root / "benchmarks" / "results")
    args = ap.parse_args()
    res = run(args.data)
    write_results(args.out, name, res, markdown(res))
