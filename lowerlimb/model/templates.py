"""The shipped lower-limb URDF templates (``urdf/`` in the source tree, inside the wheel).

Run ``python -m lowerlimb.model.templates`` to regenerate them from
:meth:`LegGeometry.from_anthropometry` (1.75 m, 75 kg, de Leva 1996); a test
checks that the shipped files match the generator.
"""

from __future__ import annotations

from pathlib import Path

from ..conventions import SIDES, check_side
from .geometry import LegGeometry

TEMPLATE_HEIGHT_M = 1.75
TEMPLATE_MASS_KG = 75.0


def template_dir() -> Path:
    """Folder holding the URDF templates: inside the installed package, else the source tree."""
    package = Path(__file__).resolve().parent.parent
    for candidate in (package / "_urdf", package.parent / "urdf"):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError("lowerlimb URDF templates not found; reinstall lowerlimb")


def template_path(side: str = "left") -> Path:
    """Path of the template URDF of one side."""
    return template_dir() / f"lowerlimb_{check_side(side)}.urdf"


def render_template(side: str) -> str:
    """URDF text of the template leg of one side."""
    return LegGeometry.from_anthropometry(side, TEMPLATE_HEIGHT_M, TEMPLATE_MASS_KG).to_urdf_string()


def main() -> None:
    """Regenerate ``urdf/lowerlimb_{left,right}.urdf`` in the source tree."""
    out = Path(__file__).resolve().parent.parent.parent / "urdf"
    out.mkdir(exist_ok=True)
    for side in SIDES:
        (out / f"lowerlimb_{side}.urdf").write_text(render_template(side), encoding="utf-8")
        print(f"wrote {out / f'lowerlimb_{side}.urdf'}")


if __name__ == "__main__":
    main()
