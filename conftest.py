"""Collection rules for the whole repository (tests/ and the docstring examples in src/bendpam).

The modules that only alias a moved module (``bendpam.law`` -> ``bendpam.physics.law``, kept for one
release) are not collected for doctests: importing them warns, and their module is collected at
its new home.
"""

from pathlib import Path

_SRC = Path(__file__).parent / "src" / "bendpam"

collect_ignore = [str(p) for p in _SRC.rglob("*.py") if "alias_module(__name__" in p.read_text(encoding="utf-8")]
