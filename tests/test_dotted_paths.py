"""Every ``retrokit.x.y`` the README and the docs write resolves after a plain ``import retrokit``, lazily."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
DOCUMENTS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
DOTTED = re.compile(r"\bretrokit(?:\.[A-Za-z_][A-Za-z0-9_]*)+")

# After ``import retrokit``, fork once per path: each resolves in a process that imported nothing else of
# retrokit, so one path's imports cannot make another one work. The third-party packages the paths pull in
# (numpy, gymnasium, jsonschema: ~0.3 CPU-s a fork) are imported once before forking: they are not what a
# path's resolving tests, and their top-level import is the same one a fresh process would run.
RESOLVE = """
import json, os, sys
import numpy, gymnasium, jsonschema
import retrokit

failures = {}
for path in json.loads(sys.argv[1]):
    reader, writer = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(reader)
        try:
            value = retrokit
            for part in path.split(".")[1:]:
                value = getattr(value, part)
            message = ""
        except Exception as error:
            message = repr(error)
        os.write(writer, message.encode())
        os._exit(0)
    os.close(writer)
    with os.fdopen(reader, "rb") as answer:
        message = answer.read().decode()
    os.waitpid(pid, 0)
    if message:
        failures[path] = message
print(json.dumps(failures))
"""


def documented_paths() -> list[str]:
    found = {match for path in DOCUMENTS for match in DOTTED.findall(path.read_text())}
    return sorted(found)


def test_the_docs_name_the_paths_users_type() -> None:
    paths = documented_paths()
    assert {"retrokit.envs.sonic.make", "retrokit.envs.multiplayer.parallel_env", "retrokit.dsl.convert_scenario_json"} <= set(paths)


def test_every_documented_dotted_path_resolves_after_import_retrokit() -> None:
    paths = documented_paths()
    # a path that starts another (retrokit.envs.sonic of retrokit.envs.sonic.make) resolves on the way to it,
    # in the same fresh process: only the longest are forked for
    leaves = [path for path in paths if not any(other.startswith(path + ".") for other in paths)]
    result = subprocess.run(
        [sys.executable, "-c", RESOLVE, json.dumps(leaves)], capture_output=True, text=True, timeout=300, check=False
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout) == {}, f"of {len(paths)} documented paths"


def test_import_retrokit_imports_none_of_them_until_used() -> None:
    code = (
        "import sys, retrokit\n"
        "before = {m for m in ('retrokit.dsl', 'retrokit.envs.sonic', 'retrokit.ramsearch') if m in sys.modules}\n"
        "retrokit.dsl.convert_scenario_json\n"
        "print(sorted(before), 'retrokit.dsl.gymretro' in sys.modules)\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert result.stdout.strip() == "[] True"


def test_a_name_that_is_no_submodule_is_an_attribute_error() -> None:
    import retrokit  # in this process: the lazy attribute hook answers the same whatever was imported before

    errors = []
    for path in ("envs.nothing", "dsl.nothing", "nothing", "envs.__wrapped__"):
        value = retrokit
        with pytest.raises(AttributeError) as caught:
            for part in path.split("."):
                value = getattr(value, part)
        errors.append(str(caught.value))
    assert errors == [
        "module 'retrokit.envs' has no attribute 'nothing'",
        "module 'retrokit.dsl' has no attribute 'nothing'",
        "module 'retrokit' has no attribute 'nothing'",
        "module 'retrokit.envs' has no attribute '__wrapped__'",
    ]
