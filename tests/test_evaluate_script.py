"""An evaluation started from a user's script: each level's worker imports that script again (multiprocessing's
rule for the fork server and spawn), so a script must start it under ``if __name__ == "__main__":``. Without the
guard, the workers refuse in one line each and the evaluation says what to change; with it, the run is normal. A
script read from stdin (``python - < script``) has no file to import again, and runs as it is."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

GUARD = 'put the code that starts the evaluation under `if __name__ == "__main__":`'
START = (
    'retrokit.cli.main(["evaluate", "--benchmark", "dasher", "--levels", "Zone2.Act2", "--timesteps", "100", '
    '"--no-progress", "--agent", "random", "--out", "run"])'
)


def run_script(folder: Path, guarded: bool, *, from_stdin: bool = False) -> subprocess.CompletedProcess:
    """Write and run a script that evaluates one Dasher level for 100 timesteps, with or without the guard
    (``from_stdin``: piped into ``python -``, without it)."""
    body = f'if __name__ == "__main__":\n    {START}\n' if guarded else f"{START}\n"
    script = folder / "my_evaluation.py"
    script.write_text(f"import retrokit.cli\n\n{body}")
    command = [sys.executable, "-"] if from_stdin else [sys.executable, str(script)]
    with open(script if from_stdin else os.devnull, "rb") as stdin:
        return subprocess.run(command, cwd=folder, capture_output=True, text=True, timeout=180, stdin=stdin,
                              check=False)  # fmt: skip


@pytest.mark.parametrize(("guarded", "from_stdin"), [(False, False), (True, False), (False, True)],
                         ids=["without-the-guard", "with-the-guard", "read-from-stdin"])
def test_a_script_that_starts_an_evaluation(tmp_path: Path, guarded: bool, from_stdin: bool) -> None:
    done = run_script(tmp_path, guarded, from_stdin=from_stdin)
    assert "Traceback" not in done.stderr and "bootstrapping" not in done.stderr, done.stderr
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    if guarded or from_stdin:
        assert summary["complete"] and GUARD not in done.stderr, done.stderr
        return
    lines = done.stderr.splitlines()
    # The worker's own line, then the evaluation's failure, which names the level and the fix.
    assert lines[0] == f"retrokit: error: Expected no evaluation to start inside an evaluation's worker: {GUARD} " \
        "(as multiprocessing asks): every level's worker imports the script that started the evaluation again, " \
        "and this one starts an evaluation when imported.", done.stderr
    assert "The worker for level Dasher-Genesis/Zone2.Act2 exited with status 2 before it started the level" \
        in lines[-1] and GUARD in lines[-1] and "--resume" in lines[-1], done.stderr
    assert not summary["complete"] and summary["levels"] == {}, summary
