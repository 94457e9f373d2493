"""The example notebook docs/examples/quickstart.ipynb runs from top to bottom (issue 25 item 3).

The documentation site executes it too (mkdocs-jupyter, ``execute: true`` in mkdocs.yml); this test
runs it with nbclient where nbclient and ipykernel are installed (the ``test`` extra).
"""

import json
import os
from pathlib import Path

import pytest

NOTEBOOK = Path(__file__).resolve().parents[1] / "docs" / "examples" / "quickstart.ipynb"
SRC = Path(__file__).resolve().parents[1] / "src"


def test_notebook_is_small_and_unexecuted():
    nb = json.loads(NOTEBOOK.read_text(encoding="utf-8"))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert 5 <= len(code) <= 12
    assert all(not c["outputs"] and c["execution_count"] is None for c in code)  # outputs come from the build
    text = "".join(c["source"] if isinstance(c["source"], str) else "".join(c["source"]) for c in code)
    for step in ("presets.be_pam", "bendpam.moment", "free_curvature", "simulate_test", "process_tests",
                 "bendpam.fit", ".plot("):
        assert step in text, step
    assert "savefig(" not in text and "open(" not in text  # it writes no files


def test_notebook_runs(tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat", reason="nbformat is in the test extra (pip install -e .[test])")
    nbclient = pytest.importorskip("nbclient", reason="nbclient is in the test extra (pip install -e .[test])")
    pytest.importorskip("ipykernel", reason="ipykernel is in the test extra (pip install -e .[test])")
    # the kernel imports this checkout's bendpam, whatever is installed
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]))
    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": tmp_path}})
    client.execute()  # "python3": ipykernel's kernel of this interpreter
    outputs = {i: c["outputs"] for i, c in enumerate(nb.cells) if c.cell_type == "code"}
    assert all(o.get("output_type") != "error" for out in outputs.values() for o in out)
    html = [o["data"]["text/html"] for out in outputs.values() for o in out if "text/html" in o.get("data", {})]
    assert any("<b>Actuator BE-PAM" in h for h in html)  # the rich summaries of issue 25
    assert any("<b>ProcessedSet: 3 pressure(s)" in h for h in html)
    assert any("<b>FitResult: energy model (converged" in h for h in html)
    assert any("image/png" in o.get("data", {}) for o in outputs[max(outputs)])  # Figure 7
    assert list(tmp_path.iterdir()) == []  # the notebook wrote nothing
