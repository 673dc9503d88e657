"""Numbers past a float's range or Python's digit limit, and a session's description bomb: one clear error each (issue 31 item 17)."""

from __future__ import annotations

import json
import subprocess
import zipfile

import numpy as np
import pytest
from numpy.lib import format as npy

import retrokit
from retrokit.envs.starts import check_weights, probabilities
from retrokit.errors import InvalidArgumentError
from retrokit.ramsearch import RamSearch

GAME = "Airstriker-Genesis"


def test_a_reward_clip_past_a_floats_range_is_refused():
    with pytest.raises(InvalidArgumentError, match="reward_clip to be False, True .* or a finite bound above 0"):
        retrokit.make(GAME, reward_clip=10**400)


def test_a_state_weight_past_a_floats_range_is_refused():
    with pytest.raises(InvalidArgumentError, match="to be a finite number of 0 or more"):
        check_weights({"Level1": 10**400})


def test_weights_near_a_floats_limit_still_make_probabilities():
    assert probabilities(check_weights({"a": 1e308, "b": 1e308})).tolist() == [0.5, 0.5]


@pytest.mark.parametrize("args, message", [
    (["--than", "9" * 5000], "a snapshot's number"),
    (["3", "--than", "0x" + "f" * 5000], "address to fit in 64 bits"),
    (["0x" + "f" * 5000], "number to fit in 64 bits"),
], ids=["5000-digit-snapshot", "20000-bit-address", "20000-bit-value"])
def test_a_number_of_thousands_of_digits_is_a_clear_error(tmp_path, args, message):
    from incli import retrokit_in_process

    def ramsearch(*argv: str) -> subprocess.CompletedProcess:  # a message, not a process: in this one
        return retrokit_in_process(tmp_path, "ramsearch", *argv)

    assert ramsearch("new", "Dasher-Genesis", "--state", "Zone1.Act1").returncode == 0
    done = ramsearch("filter", "equal", *args)
    assert done.returncode == 2 and message in done.stderr and "Traceback" not in done.stderr, done.stderr[-2000:]
    assert len(done.stderr.strip().splitlines()) == 1


def test_a_session_declaring_50_million_labels_is_refused_in_bounded_memory(tmp_path):
    from childproc import run_child

    good = tmp_path / "good.session"
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        search.save(good)
    bomb = tmp_path / "bomb.session"
    count = 50_000_000
    with zipfile.ZipFile(good) as source, zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as out:
        meta = json.loads(bytes(np.load(source.open("meta.npy"))).decode())
        head, _, tail = json.dumps({**meta, "labels": "LABELS"}).partition('"LABELS"')
        size = len(head) + 1 + 2 * count - 1 + 1 + len(tail)
        with out.open("meta.npy", "w", force_zip64=True) as member:  # streamed: the test never holds it whole
            npy.write_array_header_1_0(member, {"descr": "|u1", "fortran_order": False, "shape": (size,)})
            member.write((head + "[").encode())
            chunk = b"0," * 1_000_000
            for _ in range(count // 1_000_000 - 1):
                member.write(chunk)
            member.write(b"0," * 999_999 + b"0]" + tail.encode())
        for info in source.infolist():
            if info.filename != "meta.npy":
                out.writestr(info, source.read(info))
    assert bomb.stat().st_size < 2**20
    child = run_child(
        f"from retrokit.ramsearch.session import read_session\n"
        f"from retrokit.errors import SessionError\n"
        f"try:\n    read_session({str(bomb)!r})\nexcept SessionError as exc:\n    print(exc)\n",
        timeout=300,
    )
    assert child.returncode == 0 and "description (meta) of at most 4 MiB" in child.stdout, child.describe()
    assert child.peak_rss_mb < 300, child.describe()
