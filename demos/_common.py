"""Helpers shared by the scripts in ``demos/``: their ``--out``/``--quick`` arguments and tables."""

from __future__ import annotations

import argparse
from pathlib import Path


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    """A Markdown table from a header and rows of cell strings."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def demo_parser(description: str | None, quick_help: str, default_out: Path) -> argparse.ArgumentParser:
    """The arguments every script in ``demos/`` takes: ``--out DIR`` and ``--quick``."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", type=Path, default=default_out, help="output folder (default: %(default)s)")
    parser.add_argument("--quick", action="store_true", help=quick_help)
    return parser


def demo_output(args: argparse.Namespace, name: str) -> Path:
    """``args.out / name``, created."""
    out = Path(args.out) / name
    out.mkdir(parents=True, exist_ok=True)
    return out


def publish(out: Path, name: str, table: str) -> None:
    """Write the demo's Markdown table to ``out/<name>.md`` and print it."""
    (out / f"{name}.md").write_text(table, encoding="utf-8")
    print(table)
    print(f"wrote {out}/")
