"""The distribution as users meet it: its name on the index, its links, and the guides it ships.

"retrokit" on the package index is another project, so every hint that installs
retrokit names ``retrokit-rl``; help texts and errors point at guides with
``retrokit docs TOPIC``, which works from a wheel (CI's tools/wheel_smoke.py runs it there).
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from retrokit.cli import main
from retrokit.errors import DISTRIBUTION, install_extra
from retrokit.paths import doc_topics

REPO = Path(__file__).resolve().parent.parent
PACKAGE = REPO / "retrokit"


def package_texts() -> list[Path]:
    """Every text file of the package, as a wheel ships it (the bundled games aside)."""
    kinds = {".py", ".json", ".yaml", ".lark", ".pyi", ".h", ".c"}
    return sorted(p for p in PACKAGE.rglob("*") if p.suffix in kinds and not {"_games", "_docs"} & set(p.parts))


def user_facing_texts() -> list[Path]:
    """The package, the README, the guides, the tools and CI: everything a user copies a command from."""
    return [*package_texts(), REPO / "README.md", *sorted((REPO / "docs").glob("*.md")),
            *sorted((REPO / "tools").glob("*.py")), REPO / ".ci" / "run"]  # fmt: skip


def test_the_distribution_is_named_retrokit_rl_with_its_links() -> None:
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    assert project["name"] == DISTRIBUTION == "retrokit-rl"
    assert project["scripts"] == {"retrokit": "retrokit.cli:main"}  # the command keeps its name
    urls = project["urls"]
    assert set(urls) == {"Homepage", "Documentation", "Source", "Issues"}
    assert all(url.startswith("https://github.com/retrokit-rl/retrokit") for url in urls.values())
    assert install_extra("ray") == "pip install 'retrokit-rl[ray]'"


@pytest.mark.parametrize("path", user_facing_texts(), ids=lambda p: p.relative_to(REPO).as_posix())
def test_no_hint_installs_the_other_project(path: Path) -> None:
    """``pip install 'retrokit[plot]'`` would replace this project with the unrelated ``retrokit`` 1.0.1."""
    text = path.read_text(encoding="utf-8")
    assert not re.findall(r"(?<![\w.-])retrokit\[", text)
    assert not re.findall(r"pip install (?:-\S+ )*'?retrokit(?![\w-])", text)


def pointers() -> list[tuple[str, str]]:
    """(file, topic) for every guide the package names: ``docs/X.md`` or ``retrokit docs X``."""
    found = []
    for path in package_texts():
        text = path.read_text(encoding="utf-8")
        for topic in re.findall(r"docs/([\w-]+)\.md|retrokit docs ([a-z][\w-]*)", text):
            found.append((path.relative_to(REPO).as_posix(), topic[0] or topic[1]))
    return found


def test_every_guide_the_package_points_at_exists() -> None:
    found = pointers()
    assert len(found) > 20  # the regexes do find them
    topics = set(doc_topics())
    assert {"integrate", "scenarios", "evaluate", "cores"} <= topics
    missing = [f"{where} names {topic}" for where, topic in found if topic not in topics]
    assert not missing


def test_help_texts_and_errors_point_at_guides_a_wheel_has() -> None:
    """What a user reads in a terminal says ``retrokit docs X``: a wheel has no docs/ folder beside it."""
    from retrokit.cli import build_parser

    parser = build_parser()
    helps = parser.format_help() + "".join(
        sub.format_help() for action in parser._subparsers._group_actions for sub in action.choices.values()
    )
    assert "retrokit docs integrate" in helps and "docs/" not in helps.replace("docs/*.md", "")


def test_docs_lists_the_guides(capsys) -> None:
    assert main(["docs"]) == 0
    out = capsys.readouterr().out
    for path in sorted((REPO / "docs").glob("*.md")):
        title = path.read_text().partition("\n")[0].lstrip("# ")
        assert f"{path.stem}  " in out and title in out


@pytest.mark.parametrize("topic", ["integrate", "integrate.md", "docs/integrate.md"])
def test_docs_prints_a_guide(capsys, topic: str) -> None:
    assert main(["docs", topic]) == 0
    assert capsys.readouterr().out == (REPO / "docs" / "integrate.md").read_text()


@pytest.mark.parametrize(
    "topic, hint",
    [("integrat", "Did you mean 'integrate'?"), ("../README", "got '../README'"), ("", "got ''")],
    ids=["typo", "path-out-of-the-folder", "empty"],
)
def test_an_unknown_guide_is_one_line_with_a_suggestion(capsys, topic: str, hint: str) -> None:
    assert main(["docs", topic]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("retrokit: error: Expected one of retrokit's guides")
    assert hint in err and "Traceback" not in err


def test_the_studio_page_ships_in_the_wheel_whole() -> None:
    """Every file of the page (HTML, CSS, JS modules, the vendored editor and its license) is package data,
    and every file the page loads (``src``/``href``, ``import ... from "./x.js"``) is one of them."""
    static = PACKAGE / "studio" / "static"
    patterns = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["retrokit"]
    shipped = {p for pattern in patterns for p in PACKAGE.glob(pattern) if p.is_file()}
    files = {p for p in static.rglob("*") if p.is_file()}
    assert {static / "index.html", static / "vendor" / "codemirror" / "LICENSE"} <= files
    assert files <= shipped, sorted(str(p.relative_to(static)) for p in files - shipped)
    loaded = []
    for page in files:
        text = page.read_text(encoding="utf-8")
        if page.suffix == ".html":
            loaded += [(page, name) for name in re.findall(r'(?:src|href)="([^":#]+)"', text)]
        elif page.suffix == ".js" and "vendor" not in page.parts:
            loaded += [(page, name) for name in re.findall(r'^import .*? from "(\./[^"]+)";$', text, re.MULTILINE)]
    assert len(loaded) > 20
    missing = [f"{page.name} loads {name}" for page, name in loaded if not (page.parent / name).resolve().is_file()]
    assert not missing
