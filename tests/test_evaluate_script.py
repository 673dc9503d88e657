"""An evaluation started from a user's script: each level's worker imports that script again (multiprocessing's
rule for the fork server and spawn), so a script must start it under ``if __name__ == "__main__":``. Without the
guard, the workers refuse in one line each and the evaluation says what to change; with it, the run is normal."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

GUARD = 'put the code that starts the evaluation under `if __name__ == "__main__":`'
START = (
    'retrokit.cli.main(["evaluate", "--benchmark", "dasher", "--levels", "Zone2.Act2", "--timesteps", "100", '
    '"--no-progress", "--agent", "random", "--out", "run"])'
)


def run_script(folder: Path, guarded: bool) -> subprocess.CompletedProcess:
    """Write and run a script that evaluates one Dasher level for 100 timesteps, with or without the guard."""
    body = f'if __name__ == "__main__":\n    {START}\n' if guarded else f"{START}\n"
    script = folder / "my_evaluation.py"
    script.write_text(f"import retrokit.cli\n\n{body}")
    return subprocess.run([sys.executable, str(script)], cwd=folder, capture_output=True, text=True, timeout=180,
                          stdin=subprocess.DEVNULL, check=False)


@pytest.mark.parametrize("guarded", [False, True], ids=["without-the-guard", "with-the-guard"])
def test_a_script_that_starts_an_evaluation(tmp_path: Path, guarded: bool) -> None:
    done = run_script(tmp_path, guarded)
    assert "Traceback" not in done.stderr and "bootstrapping" not in done.stderr, done.stderr
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    if guarded:
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
