"""The import rules of docs/architecture.md, checked on the source (ast, nothing imported).

- ``solvers`` never imports ``lowerlimb``;
- nothing outside ``lowerlimb/cli`` imports ``lowerlimb.cli``;
- every import inside ``lowerlimb`` goes down the layer order below (or stays in its
  own unit), so the units' import graph has no cycle;
- one definition of ``FloatArray``; no module cites a file that is not in the repository.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: The layers of lowerlimb, bottom first. A unit is a top-level module or subpackage;
#: a unit may import its own modules and any unit of a LOWER layer, never one of its
#: own layer or above. ``lowerlimb`` itself (the version) is below everything.
LAYERS: list[set[str]] = [
    {"conventions", "methods", "side_by_side"},
    {"errors"},
    {"stillness"},
    {"io", "upsample"},
    {"orientation", "constraints"},
    {"calibration"},
    {"segments", "s2j", "gait"},
    {"model"},
    {"simulation"},
    {"pipeline"},
    {"bilateral"},
    {"viz", "export", "agreement"},
    {"outputs"},
    {"demo", "outputs_bilateral"},
    {"batch"},
    {"cli"},
]
LAYER_OF = {unit: k for k, layer in enumerate(LAYERS) for unit in layer}


def python_files(package: str) -> Iterator[Path]:
    yield from sorted((ROOT / package).rglob("*.py"))


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def imports(path: Path) -> Iterator[tuple[int, str]]:
    """``(line, absolute module)`` of every import in a file, nested ones included."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            yield node.lineno, target
            for alias in node.names:  # ``from lowerlimb import cli`` imports a submodule
                yield node.lineno, f"{target}.{alias.name}"


def unit_of(module: str) -> str | None:
    """The lowerlimb unit of a module name, ``""`` for the root, None outside lowerlimb."""
    parts = module.split(".")
    if parts[0] != "lowerlimb":
        return None
    if len(parts) == 1:
        return ""
    return parts[1] if parts[1] in LAYER_OF else ""  # ``lowerlimb.__version__`` → the root


def lowerlimb_edges() -> dict[tuple[str, str], list[str]]:
    edges: dict[tuple[str, str], list[str]] = {}
    for path in python_files("lowerlimb"):
        if path.name == "__init__.py" and path.parent.name == "lowerlimb":
            continue  # the lazy export table names every unit
        here = unit_of(module_name(path))
        for line, target in imports(path):
            there = unit_of(target)
            if here and there and there != here:
                edges.setdefault((here, there), []).append(f"{path.relative_to(ROOT)}:{line}")
    return edges


def present_units() -> set[str]:
    package = ROOT / "lowerlimb"
    units = {p.stem for p in package.glob("*.py") if p.name != "__init__.py"}
    return units | {p.name for p in package.iterdir() if (p / "__init__.py").is_file()}


def test_every_unit_has_a_layer():
    units = present_units()
    assert units <= set(LAYER_OF), f"units without a layer: {sorted(units - set(LAYER_OF))}"


def test_solvers_never_imports_lowerlimb():
    bad = [
        f"{path.relative_to(ROOT)}:{line} imports {target}"
        for path in python_files("solvers")
        for line, target in imports(path)
        if target.split(".")[0] == "lowerlimb"
    ]
    assert not bad, bad


def test_only_the_cli_imports_the_cli():
    bad = [
        f"{path.relative_to(ROOT)}:{line} imports {target}"
        for package in ("lowerlimb", "solvers")
        for path in python_files(package)
        if unit_of(module_name(path)) not in LAYERS[-1]
        for line, target in imports(path)
        if target == "lowerlimb.cli" or target.startswith("lowerlimb.cli.")
    ]
    assert not bad, bad


def test_imports_go_down_the_layers():
    bad = [
        f"{here} (layer {LAYER_OF[here]}) imports {there} (layer {LAYER_OF[there]}) at {', '.join(where)}"
        for (here, there), where in lowerlimb_edges().items()
        if LAYER_OF[there] >= LAYER_OF[here]
    ]
    assert not bad, "\n".join(bad)


def test_no_import_cycle_among_the_units():
    graph: dict[str, set[str]] = {}
    for here, there in lowerlimb_edges():
        graph.setdefault(here, set()).add(there)
    state: dict[str, int] = {}

    def visit(unit: str, path: list[str]) -> None:
        state[unit] = 1
        for nxt in sorted(graph.get(unit, ())):
            if state.get(nxt) == 1:
                pytest.fail("import cycle: " + " → ".join(path[path.index(nxt) :] + [nxt]))
            if nxt not in state:
                visit(nxt, path + [nxt])
        state[unit] = 2

    for unit in sorted(graph):
        if unit not in state:
            visit(unit, [unit])


def test_the_architecture_doc_lists_the_same_layers():
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    for unit in present_units():
        assert f"`{unit}`" in text, unit


def test_float_array_is_defined_once():
    defined = [
        str(path.relative_to(ROOT))
        for package in ("lowerlimb", "solvers")
        for path in python_files(package)
        if re.search(r"^FloatArray\s*(:[^=]*)?=", path.read_text(encoding="utf-8"), flags=re.M)
    ]
    assert defined == ["lowerlimb/conventions.py"]


def test_no_module_cites_a_missing_file():
    """DESIGN.md and NOTES.md live outside the repository; cite docs/ pages, which must exist."""
    bad = []
    for package in ("lowerlimb", "solvers", "benchmarks", "demos", "tests"):
        for path in python_files(package):
            if path.name == "test_architecture.py":
                continue
            text = path.read_text(encoding="utf-8")
            for word in ("DESIGN.md", "NOTES.md"):
                if word in text:
                    bad.append(f"{path.relative_to(ROOT)} cites {word}")
            for page in re.findall(r"docs/[\w-]+\.md", text):
                if not (ROOT / page).is_file():
                    bad.append(f"{path.relative_to(ROOT)} cites missing {page}")
    assert not bad, "\n".join(bad)


def test_each_method_family_has_one_registry():
    """The API, the CLI's choices and docs/methods.md all come from lowerlimb.methods."""
    from lowerlimb.calibration.options import METHODS as CALIBRATION
    from lowerlimb.cli import build_parser
    from lowerlimb.methods import CALIBRATION_METHODS, ORIENTATION_FILTERS
    from lowerlimb.orientation.estimate import FILTERS, METHODS

    assert tuple(FILTERS) == tuple(METHODS) == tuple(ORIENTATION_FILTERS)
    assert tuple(CALIBRATION) == tuple(CALIBRATION_METHODS)
    assert set(ORIENTATION_FILTERS) == {"mahony", "ftecf", "madgwick", "quest_kf"}
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    calibrate = sub.choices["calibrate"]  # type: ignore[attr-defined]
    choices = {a.dest: tuple(a.choices) for a in calibrate._actions if a.choices}
    assert choices["filter"] == tuple(ORIENTATION_FILTERS)
    assert choices["method"] == tuple(CALIBRATION_METHODS)
    doc = (ROOT / "docs" / "methods.md").read_text(encoding="utf-8")
    for name in (*ORIENTATION_FILTERS, *CALIBRATION_METHODS):
        assert f"`{name}`" in doc, name


def test_the_command_line_parser_loads_no_heavy_dependency():
    """``lowerlimb --help`` stays fast: building the parser loads no solver, filter or model library."""
    import subprocess
    import sys

    code = (
        "import sys, lowerlimb.cli as c; c.build_parser(); "
        "print(' '.join(m for m in ('casadi', 'pinocchio', 'numba', 'scipy', 'meshcat', "
        "'matplotlib', 'yourdfpy') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == ""
