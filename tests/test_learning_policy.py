"""The saved-policy format: written atomically, read checked; damaged, huge and foreign files are one line."""

from __future__ import annotations

import hashlib
import json
import os
import pickle

import pytest

from retrokit.errors import PolicyFileError
from retrokit.learning.policy import POLICY_FILE, find_policy, read_policy, write_policy

META = {
    "agent": "ppo", "library": "stable-baselines3 2.9.2", "config": {"agent": "ppo", "name": "paper", "values": {}},
    "actions": [["LEFT"], ["RIGHT"]], "x": "p1_x",
    "observation": {"shape": [4, 84, 84], "dtype": "uint8", "options": {"frame_stack": 4}},
    "benchmark": "dasher", "timesteps": 10,
}  # fmt: skip


@pytest.fixture
def saved(tmp_path):
    return write_policy(tmp_path / "run", META, b"weights-v1")


def test_a_policy_is_read_back_from_its_folder_or_its_file(saved) -> None:
    folder = saved.path.parent
    for path in (folder, folder / POLICY_FILE):
        policy = read_policy(path, "ppo")
        assert policy.meta["actions"] == META["actions"] and policy.read_weights() == b"weights-v1"
        assert policy.sha256 == hashlib.sha256(b"weights-v1").hexdigest()


def test_a_new_save_replaces_the_weights_and_leaves_no_old_file(saved) -> None:
    folder = saved.path.parent
    again = write_policy(folder, {**META, "timesteps": 20}, b"weights-v2")
    assert read_policy(folder).read_weights() == b"weights-v2"
    assert sorted(p.name for p in folder.iterdir()) == sorted([POLICY_FILE, again.weights_path.name])


def _rewrite(saved, **changes) -> None:
    data = json.loads(saved.path.read_text())
    data.update(changes)
    saved.path.write_text(json.dumps(data))


@pytest.mark.parametrize(("damage", "message"), [
    (lambda s: s.path.write_text("{not json"), "it is not JSON"),
    (lambda s: s.path.write_text('{"format": "something-else"}'), "it is not one"),
    (lambda s: s.path.write_text("[" * 100000 + "]" * 100000), "it is not JSON|of at most"),
    (lambda s: s.path.write_bytes(b" " * (2 << 20)), "of at most 1 MiB"),
    (lambda s: _rewrite(s, version=99), "its version is 99"),
    (lambda s: _rewrite(s, actions="LEFT"), "'actions' is not a list of button lists"),
    (lambda s: _rewrite(s, weights={"file": "../../etc/passwd", "bytes": 1, "sha256": "0" * 64}), "not a plain file name"),
    (lambda s: _rewrite(s, weights={"file": "x.pt"}), "'weights' is not"),
    (lambda s: _rewrite(s, timesteps=-1), "'timesteps' is not a whole number"),
    (lambda s: _rewrite(s, agent="rainbow"), "one of 'rainbow'; use --agent rainbow"),
    (lambda s: (s.path.unlink(), os.mkfifo(s.path)), "a FIFO"),
    (lambda s: (s.path.unlink(), s.path.symlink_to("/dev/zero")), "a device"),
], ids=["not-json", "foreign", "deep", "huge", "version", "actions", "traversal", "weights-shape", "timesteps",
        "other-agent", "fifo", "dev-zero"])
def test_bad_policy_files_are_one_line(saved, damage, message) -> None:
    damage(saved)
    with pytest.raises(PolicyFileError, match=message) as caught:
        read_policy(saved.path.parent, "ppo")
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize(("damage", "message"), [
    (lambda s: s.weights_path.write_bytes(b"weights-v2"), "its size or digest differs"),
    (lambda s: s.weights_path.unlink(), "No such file"),
    (lambda s: (s.weights_path.unlink(), s.weights_path.symlink_to("/dev/zero")), "a device"),
    (lambda s: os.truncate(s.weights_path, (64 << 20) + 1), "of at most 64 MiB"),
], ids=["changed", "missing", "dev-zero", "huge"])
def test_weights_that_are_not_the_named_ones_are_refused(saved, damage, message) -> None:
    damage(saved)
    with pytest.raises(PolicyFileError, match=message):
        read_policy(saved.path.parent).read_weights()


def test_no_policy_there(tmp_path) -> None:
    with pytest.raises(PolicyFileError, match="a `retrokit train` folder or its policy.json"):
        find_policy(tmp_path)


def test_weights_load_as_tensors_only_never_as_arbitrary_pickles(tmp_path) -> None:
    torch = pytest.importorskip("torch", reason="needs torch: pip install torch --index-url "
                                "https://download.pytorch.org/whl/cpu")
    from retrokit.learning.ppo import load_tensors

    marker = tmp_path / "ran"

    class Payload:
        def __reduce__(self):
            return (open, (str(marker), "w"))  # what loading it would do, were it unpickled blindly

    for data in (pickle.dumps(Payload()), b"garbage", _torch_file(torch, Payload())):
        with pytest.raises(PolicyFileError, match="cannot be loaded as them"):
            load_tensors(data, "the test's weights")
    assert not marker.exists()
    with pytest.raises(PolicyFileError, match="holds a list"):
        load_tensors(_torch_file(torch, [torch.zeros(2)]), "the test's weights")
    assert set(load_tensors(_torch_file(torch, {"w": torch.zeros(2)}), "w")) == {"w"}


def _torch_file(torch, value) -> bytes:
    import io

    out = io.BytesIO()
    torch.save(value, out)
    return out.getvalue()
