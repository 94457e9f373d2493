"""Collection rules for the whole repository (tests/ and the docstring examples in src/bendpam).

The modules that only alias a moved module (``bendpam.law`` -> ``bendpam.physics.law``, kept for one
release) are not collected for doctests: importing them warns, and their module is collected at
its new home.

Every docstring example (``--doctest-modules``) runs in an empty temporary folder of its own and
fails if it leaves anything there: examples that write files must write them into a
``tempfile.TemporaryDirectory()``, never into the folder the user runs them in.
"""

from pathlib import Path

import pytest

try:
    from pytest import DoctestItem
except ImportError:  # pytest before 8.1
    from _pytest.doctest import DoctestItem

_SRC = Path(__file__).parent / "src" / "bendpam"

collect_ignore = [str(p) for p in _SRC.rglob("*.py") if "alias_module(__name__" in p.read_text(encoding="utf-8")]


@pytest.fixture(autouse=True)
def _doctest_writes_nothing(request, tmp_path_factory, monkeypatch):
    """For a docstring example: run it in an empty folder and fail if it wrote anything there."""
    if not isinstance(request.node, DoctestItem):
        yield
        return
    folder = tmp_path_factory.mktemp("doctest-cwd")
    monkeypatch.chdir(folder)
    yield
    left = sorted(p.name for p in folder.iterdir())
    if left:
        pytest.fail(f"the example wrote into the folder it ran in: {', '.join(left)} "
                    "(write into a tempfile.TemporaryDirectory() instead)", pytrace=False)
