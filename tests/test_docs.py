"""The documentation site: built in strict mode from the tree as it is (a broken link or a
missing page fails), its API reference generated from every top-level package, and the README
and the pages standing on their own."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
QUIET = {"NO_MKDOCS_2_WARNING": "1", "DISABLE_MKDOCS_2_WARNING": "true"}
"""The theme's and a plugin's banners about MkDocs' future, which say nothing of this site."""
SAFETY_NET_S = 600


def mkdocs_build(config: Path, site: Path) -> subprocess.CompletedProcess[str]:
    """``mkdocs build --strict`` of ``config`` into ``site``."""
    return subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config), "-d", str(site)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env={**os.environ, **QUIET},
        timeout=SAFETY_NET_S,
    )


def texts() -> dict[Path, str]:
    """The README and every page of the site."""
    paths = [ROOT / "README.md", ROOT / "mkdocs.yml", *sorted(DOCS.rglob("*.md"))]
    return {path: path.read_text() for path in paths}


def test_the_site_builds_in_strict_mode_with_a_reference_page_per_package(tmp_path: Path) -> None:
    """Every page of the navigation is built, the equations are left for MathJax, and the API
    reference has a page for each top-level package of the tree."""
    result = mkdocs_build(ROOT / "mkdocs.yml", tmp_path)
    assert result.returncode == 0, result.stderr[-4000:]
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
    for page in re.findall(r"[\w/-]+\.md", yaml.safe_dump(config["nav"])):
        stem = Path(page).with_suffix("")
        folder = stem.parent if stem.name == "index" else stem
        assert (tmp_path / folder / "index.html").is_file(), page
    assert 'class="arithmatex"' in (tmp_path / "concepts" / "lp-law" / "index.html").read_text()
    packages = {p.parent.name for p in ROOT.glob("*/__init__.py")} - {"tests", "docs"}
    for package in packages:
        assert (tmp_path / "reference" / package / "index.html").is_file(), package


def test_a_broken_link_fails_the_build(tmp_path: Path) -> None:
    """The site's own validation settings, on a page that links to one that does not exist."""
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# Home\n\nSee [a page](missing.md).\n")
    small = {
        "site_name": "broken",
        "docs_dir": str(docs),
        "strict": config["strict"],
        "validation": config["validation"],
        "nav": [{"Home": "index.md"}],
    }
    (tmp_path / "mkdocs.yml").write_text(yaml.safe_dump(small))
    result = mkdocs_build(tmp_path / "mkdocs.yml", tmp_path / "site")
    assert result.returncode != 0
    assert "missing.md" in result.stderr


def test_nothing_points_outside_the_repository() -> None:
    """A clone has no ``../shared``: the dissertation is cited, the design is a page."""
    for path, text in texts().items():
        assert "../shared" not in text and "shared/" not in text, path
        assert ".venv/bin/parsimony" not in text, path


def test_the_readme_is_short_and_its_first_hour_is_the_guides() -> None:
    """At most about 150 lines; the guide's first hour runs the very same block."""
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 150
    block = re.compile(r"```sh\n(.*?)```", re.DOTALL)
    first_hour = readme.split("## Your first hour", 1)[1]
    guide = (DOCS / "guide" / "first-hour.md").read_text()
    assert block.search(first_hour).group(1) == block.search(guide).group(1)


def test_the_readmes_links_lead_to_files() -> None:
    for target in re.findall(r"\]\(([^)#]+)\)", (ROOT / "README.md").read_text()):
        assert (ROOT / target).is_file(), target


def test_each_module_a_page_runs_with_python_m_exists() -> None:
    """``python -m NAME`` in the README and the pages names a module of the tree."""
    for path, text in texts().items():
        for name in re.findall(r"python -m ([\w.]+)", text):
            assert importlib.util.find_spec(name) is not None, f"{path}: python -m {name}"


def test_each_result_page_says_the_command_that_regenerates_it() -> None:
    for page in sorted((DOCS / "results").glob("*.md")):
        if page.name != "index.md":
            assert '!!! example "Regenerate"' in page.read_text(), page
