"""Write the API reference pages at build time (mkdocs-gen-files): one page per module of every
top-level package of the repository, found by walking the tree, so a module that moves never
breaks the build. The navigation is written as ``reference/SUMMARY.md`` (mkdocs-literate-nav)."""

from __future__ import annotations

from pathlib import Path

import mkdocs_gen_files

ROOT = Path(__file__).resolve().parent.parent
NOT_PACKAGES = {"tests", "docs", "site", "build"}
LAYERS = (
    "wbc protocols messages sim2d vision profiles scenes record analysis ros2 components launch "
    "view studies parsimony deploy bench"
).split()
"""The packages in layering order (lowest first); any other package follows, by name."""


def packages() -> list[str]:
    """The top-level packages: folders of the root with an ``__init__.py``."""
    found = {
        p.parent.name
        for p in ROOT.glob("*/__init__.py")
        if p.parent.name not in NOT_PACKAGES and not p.parent.name.startswith(".")
    }
    return sorted(found, key=lambda name: (LAYERS.index(name) if name in LAYERS else 99, name))


def main() -> None:
    """One page per module, and the literate navigation of them all."""
    nav = mkdocs_gen_files.Nav()
    for package in packages():
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            if "__pycache__" in parts or parts[-1] == "__main__":
                continue
            if any(
                not (ROOT.joinpath(*parts[:i]) / "__init__.py").is_file()
                for i in range(1, len(parts))
            ):
                continue  # a script folder, not a package
            doc = Path("reference", *parts).with_suffix(".md")
            if parts[-1] == "__init__":
                parts = parts[:-1]
                doc = doc.with_name("index.md")
            nav[parts] = doc.relative_to("reference").as_posix()
            with mkdocs_gen_files.open(doc, "w") as page:
                page.write(f"# `{'.'.join(parts)}`\n\n::: {'.'.join(parts)}\n")
            mkdocs_gen_files.set_edit_path(doc, path.relative_to(ROOT))
    with mkdocs_gen_files.open("reference/index.md", "w") as index:
        index.write("# API reference\n\nGenerated from the docstrings, one page per module.\n\n")
        index.writelines(f"- [`{name}`]({name}/index.md)\n" for name in packages())
    with mkdocs_gen_files.open("reference/SUMMARY.md", "w") as summary:
        summary.write("* [Packages](index.md)\n")
        summary.writelines(nav.build_literate_nav())


main()
