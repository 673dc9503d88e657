"""Checking a game's data files against the shipped JSON Schemas (:mod:`retrokit.data.schema`).

``game.yaml`` is checked against ``game.schema.json``; every YAML scenario
against ``scenario.schema.json`` and the files it includes against
``scenario-include.schema.json``. Gym Retro folders (``data.json``) have no
schema here: their loader checks them.
"""

from __future__ import annotations

import os
from pathlib import Path

from retrokit.data.games import Game
from retrokit.data.schema import check_file
from retrokit.testing.report import FAIL, PASS, SKIP, GameReport

__all__ = ["check_schemas"]


def check_schemas(game: Game, report: GameReport) -> bool:
    """Check the game's YAML files against their schemas; add the results; return whether its game.yaml files conform."""
    ok = True
    # lexists, not is_file: an overlay game.yaml that is a FIFO, a folder or a loop fails here, not silently skipped
    data_files = [folder / "game.yaml" for folder in game.folders if os.path.lexists(folder / "game.yaml")]
    for path in data_files:
        ok = _check(report, path, "game", "") and ok
    if not data_files:
        report.add("schema", SKIP, f"{game.folders[0].name} is a Gym Retro folder (data.json): no game.yaml to check")
    seen: set[Path] = set()
    for name, path in _scenario_files(game):
        _check(report, path, "scenario", name)
        for include in _includes(path):
            if include not in seen:
                seen.add(include)
                _check(report, include, "include", name)
    return ok


def _check(report: GameReport, path: Path, kind: str, scenario: str) -> bool:
    issues = check_file(path, kind)
    for issue in issues:
        report.add("schema", FAIL, str(issue), scenario=scenario)
    if not issues:
        report.add("schema", PASS, f"{path.name} follows {kind}'s schema", scenario=scenario)
    return not issues


def _scenario_files(game: Game) -> list[tuple[str, Path]]:
    try:
        scenarios = game.scenarios
    except Exception:  # noqa: BLE001 - a broken folder is reported by the data check
        return []
    return [(name, path) for name, path in scenarios.items() if path.suffix.lower() in (".yaml", ".yml")]


def _includes(path: Path) -> list[Path]:
    """The files a scenario includes (directly), as far as it can be read."""
    import yaml

    from retrokit.data.yamlfile import load_yaml, read_yaml_text

    try:
        doc = load_yaml(read_yaml_text(path, "a scenario file"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):  # the scenario's own check reports it
        return []
    names = doc.get("include") if isinstance(doc, dict) else None
    if not isinstance(names, list):
        return []
    # lexists: an include that is a FIFO or a loop is checked, and fails, instead of being skipped
    return [path.parent / str(n) for n in names if os.path.lexists(path.parent / str(n))]
