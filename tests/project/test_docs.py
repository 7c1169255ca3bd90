"""The documentation site builds in strict mode (a broken link, a missing anchor, a page
left out of the navigation or named in it but missing all fail), its Urdu pages read
right to left, and the README's links into it lead somewhere."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def test_the_site_builds_in_strict_mode_with_no_warning(tmp_path: Path) -> None:
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict",
                           "--site-dir", str(tmp_path / "site")],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "WARNING" not in done.stderr, done.stderr
    assert (tmp_path / "site" / "students" / "quickstart" / "index.html").exists()


def test_urdu_pages_are_laid_out_right_to_left() -> None:
    pages = sorted((DOCS / "ur").rglob("*.md"))
    assert {p.relative_to(DOCS / "ur").as_posix() for p in pages} >= {
        "students/quickstart.md", "students/first-hour.md"}
    for page in pages:
        text = page.read_text(encoding="utf-8")
        if text.startswith("---\n"):  # front matter (hide: toc) comes first
            text = text.split("\n---\n", 1)[1].lstrip("\n")
        # md_in_html: `markdown` keeps the Markdown inside the block working.
        assert text.startswith('<div dir="rtl" lang="ur" markdown>\n\n'), page
        assert text.rstrip().endswith("</div>"), page


def test_readme_links_into_the_docs_lead_to_pages() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    links = re.findall(r"\]\((docs/[^)#\s]+)(?:#[^)]*)?\)", readme)
    assert links, "README.md links to no documentation page"
    for link in links:
        assert (ROOT / link).is_file(), link


def test_urdu_pages_follow_the_glossary(tmp_path: Path) -> None:
    """The checks `autograder i18n check` gives the exercises' Urdu READMEs: one rendering
    per term, agreement, no Latin word opening a block (it would be laid out left to
    right)."""
    from autograder.i18n.glossary import load_glossary

    glossary = load_glossary(ROOT / "locales" / "ur" / "glossary.yaml")
    for page in sorted((DOCS / "ur").rglob("*.md")):
        text = page.read_text(encoding="utf-8")
        if text.startswith("---\n"):
            text = text.split("\n---\n", 1)[1].lstrip("\n")
        # As a README wraps it: md_in_html's `markdown` attribute is the site's alone.
        copy = tmp_path / page.name
        copy.write_text(text.replace(' lang="ur" markdown>', ' lang="ur">', 1), encoding="utf-8")
        assert [str(p) for p in glossary.check_readme(copy)] == [], page
