"""Packaging metadata (issue 25 item 6): an SPDX licence, bounded setuptools, project URLs, completion."""

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_license_is_an_spdx_expression_with_its_file():
    project = PYPROJECT["project"]
    assert project["license"] == "MIT"
    assert project["license-files"] == ["LICENSE"] and (ROOT / "LICENSE").read_text().startswith("MIT")


def test_setuptools_has_bounds_that_read_spdx():
    (req,) = [r for r in PYPROJECT["build-system"]["requires"] if r.startswith("setuptools")]
    low, high = re.fullmatch(r"setuptools>=(\d+),<(\d+)", req).groups()
    assert int(low) >= 77 and int(high) > int(low)  # PEP 639 licence expressions: setuptools 77


def test_project_urls():
    urls = PYPROJECT["project"]["urls"]
    assert set(urls) == {"Homepage", "Documentation", "Source", "Issues", "Changelog"}
    assert all(u.startswith("https://github.com/bendpam/bendpam") for u in urls.values())


def test_citation_has_version_and_date():
    from bendpam.version import __version__

    text = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    assert f'version: "{__version__}"' in text and re.search(r'date-released: "\d{4}-\d\d-\d\d"', text)


def test_readme_mentions_shell_completion():
    assert "bendpam --install-completion" in (ROOT / "README.md").read_text(encoding="utf-8")
