"""The RAM search engine on made-up snapshots: types, scales, filters, undo and redo."""

from __future__ import annotations

import numpy as np
import pytest

from retrokit.errors import FieldTypeError, InvalidArgumentError, RamSearchError
from retrokit.host.typecodes import parse_type
from retrokit.ramsearch.engine import Engine, list_candidates
from retrokit.ramsearch.filters import OPS
from retrokit.ramsearch.ram import RamLayout
from retrokit.ramsearch.scales import SCALES, Scale, scale_labels
from retrokit.ramsearch.types import SEARCH_TYPES, decode_all, parse_search_types, require_type

BASE = 0xFF0000
LAYOUT = RamLayout(((BASE, 256),))


def engine(*rows: dict[int, int], types: str | None = None) -> Engine:
    """An engine over 256 zero bytes per snapshot, with the given bytes set (offset: byte)."""
    search = Engine(LAYOUT, parse_search_types(types))
    for row in rows:
        data = np.zeros(256, dtype=np.uint8)
        for offset, byte in row.items():
            data[offset] = byte
        search.add_snapshot(data)
    return search


def found(search: Engine) -> set[tuple[int, str]]:
    return {
        (int(LAYOUT.addresses(np.array([p]))[0]), search.types[t].code)
        for t, alive in enumerate(search.candidates.alive)
        for p in np.flatnonzero(alive)
    }


# --- types -------------------------------------------------------------------------------------


@pytest.mark.parametrize("code", SEARCH_TYPES)
def test_every_type_decodes_as_the_reference_reader(code):
    data = np.random.default_rng(7).integers(0, 256, 4096).astype(np.uint8)
    data[:64] = np.arange(0x90, 0xD0) % 256  # BCD nibbles above 9, which Gym Retro wraps
    ftype = parse_type(code)
    (values,) = decode_all(data, [ftype])
    for position in [*range(64), *range(64, 4096 - 8, 61)]:
        assert int(values[position]) == ftype.decode(bytes(data[position : position + ftype.width])), position


def test_a_listing_reads_each_candidates_values_as_the_reference_reader():
    rng = np.random.default_rng(3)
    search = engine(*({int(k): int(v) for k, v in zip(rng.integers(0, 256, 40), rng.integers(0, 256, 40))}
                      for _ in range(6)))
    search.filter("changed", than="first")
    listed = list_candidates(search)
    assert listed and list_candidates(search, 7) == listed[:7]
    assert [(c.address, SEARCH_TYPES.index(c.type)) for c in listed] == sorted(
        (c.address, SEARCH_TYPES.index(c.type)) for c in listed)
    for row in listed:
        ftype, at = parse_type(row.type), row.address - BASE
        assert row.values == tuple(ftype.decode(bytes(s[at : at + ftype.width])) for s in search.snapshots)
        assert row.changes == sum(a != b for a, b in zip(row.values, row.values[1:]))


def test_searched_types_cover_what_gym_retro_infers():
    kinds = {(t.kind, t.width, t.order) for t in parse_search_types(None)}
    for order in (">", "<", "><", "<>"):
        for kind in range(4):
            assert (kind, 4, order) in kinds
    assert {("|u1"), (">i2"), ("<u2"), (">d8"), (">n6")} <= set(SEARCH_TYPES)


def test_unknown_type_names_the_fix():
    with pytest.raises(FieldTypeError, match="Did you mean '|u1'"):
        require_type("u1")
    with pytest.raises(FieldTypeError, match="twice"):
        parse_search_types(["|u1", "|u1"])
    with pytest.raises(FieldTypeError, match="searched types"):
        require_type(">u8", SEARCH_TYPES)


# --- scales and value searches -----------------------------------------------------------------


@pytest.mark.parametrize(
    ("scale", "shown", "stored"),
    [("", 3, 3), ("+1", 3, 2), ("-1", 3, 4), ("x10", 1230, 123), ("x16", 0x30, 3), ("/2", 3, 6), ("/16", 3, 0x30)],
    ids=["itself", "plus-one", "minus-one", "times-10", "times-16", "doubled", "nibble-shift"],
)
def test_scale_inverts(scale, shown, stored):
    (match,) = [s for s in SCALES if s.label == scale]
    assert match.stored(shown) == stored
    values, ok = match.shown(np.array([stored]))
    assert ok[0] and values[0] == shown
    assert Scale("/2", div=2).stored(3) == 6 and Scale("x10", mult=10).stored(3) is None


@pytest.mark.parametrize(
    ("stored", "scale"),
    [(3, ""), (2, "+1"), (4, "-1"), (6, "/2"), (12, "/4"), (0x30, "/16")],
    ids=["itself", "stored-minus-one", "stored-plus-one", "doubled", "quadrupled", "nibble-shift"],
)
def test_value_search_finds_scaled_values_and_pins_the_scale(stored, scale):
    search = engine({0x10: stored}, types="|u1")
    search.filter("equal", 3)
    t = 0
    assert 0x10 in np.flatnonzero(search.candidates.alive[t])
    assert scale_labels(int(search.candidates.scale[t][0x10])) == (scale,)
    # The pinned scale reads the next value the same way: 3 -> 2 on screen.
    search.add_snapshot(
        np.where(np.arange(256) == 0x10, {"": 2, "+1": 1, "-1": 3, "/2": 4, "/4": 8, "/16": 0x20}[scale], 0)
    )
    search.filter("equal", 2)
    assert search.candidates.alive[t][0x10]


def test_a_stored_value_keeps_every_scale_it_is_consistent_with():
    # At `equal 1`, a stored 2 reads as "shown + 1" (-1) and as "shown x 2" (/2); a level stored as 2n.
    search = engine({0x10: 2}, types="|u1")
    search.filter("equal", 1)
    assert scale_labels(int(search.candidates.scale[0][0x10])) == ("-1", "/2")
    search.add_snapshot(np.where(np.arange(256) == 0x10, 4, 0).astype(np.uint8))
    search.filter("equal", 2)  # 4 is 2 shown x 2, not 2 + 1: the word survives, its scale now known
    assert search.candidates.alive[0][0x10]
    assert scale_labels(int(search.candidates.scale[0][0x10])) == ("/2",)
    (row,) = [c for c in list_candidates(search) if c.address == BASE + 0x10]
    assert row.scale == "/2" and row.values == (2, 4)


def stable_retro_rule(rows: list[np.ndarray], values: list[int], code: str) -> set[int]:
    """The positions stable-retro keeps after a value search per snapshot: each (position, scale) on its own.

    Its search keeps a candidate per (address, mult, div, bias) that matched the
    first value, and drops each one the next values do not match: a position
    survives while any of its scales does.
    """
    ftype = parse_type(code)
    kept = set()
    for position in range(256 - ftype.width + 1):
        stored = [ftype.decode(bytes(row[position : position + ftype.width])) for row in rows]
        for scale in SCALES:
            if ftype.kind not in scale.kinds:
                continue
            if all(scale.stored(v) == s for v, s in zip(values, stored)):
                kept.add(position)
    return kept


@pytest.mark.parametrize("code", ["|u1", ">u2", "<i2", ">d2"])
def test_value_searches_keep_a_superset_of_stable_retros_candidates(code):
    rng = np.random.default_rng(3)
    rows = [rng.integers(0, 6, 256).astype(np.uint8) for _ in range(3)]
    for row, value in zip(rows, (1, 2, 3)):  # plant words that read 1, 2, 3 through each simple scale
        row[0x10], row[0x20], row[0x30], row[0x40] = value, value - 1, value + 1, 2 * value
    values = [1, 2, 3]
    search = Engine(LAYOUT, parse_search_types(code))
    for row, value in zip(rows, values):
        search.add_snapshot(row)
        search.filter("equal", value)
    theirs = stable_retro_rule(rows, values, code)
    ours = set(np.flatnonzero(search.candidates.alive[0]).tolist())
    assert theirs <= ours and ours == theirs  # every one they keep, and nothing they would drop
    if code == "|u1":
        assert {0x10, 0x20, 0x30, 0x40} <= ours


def test_score_times_ten_and_bcd_are_found():
    search = engine({0x20: 0x01, 0x21: 0x23, 0x40: 123 >> 8, 0x41: 123 & 0xFF}, types="|u1,>u2,>d2")
    search.filter("equal", 1230)
    assert {(BASE + 0x40, ">u2"), (BASE + 0x20, ">d2")} <= found(search)


# --- filters -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("op", "value", "than", "kept"),
    [
        ("increased", None, None, {0x10}),
        ("decreased", None, None, {0x11}),
        ("changed", None, None, {0x10, 0x11}),
        ("unchanged", None, None, {0x12}),
        ("equal", None, None, {0x12}),
        ("greater", None, "first", {0x10}),
        ("changed-by", 5, None, {0x10}),
        ("changed-by", -1, None, {0x11}),
        ("less", 8, None, {0x11, 0x12}),
        ("greater-equal", 9, None, {0x10}),
        ("not-equal", 7, None, {0x10}),
        ("less-equal", 7, None, {0x11, 0x12}),
        ("equal", None, BASE + 0x12, {0x11, 0x12}),
        ("greater", None, BASE + 0x12, {0x10}),
        ("equal", 1, "changes", {0x10, 0x11}),
    ],
    ids=lambda v: str(v),
)
def test_filter_ops(op, value, than, kept):
    search = engine({0x10: 4, 0x11: 8, 0x12: 7}, {0x10: 9, 0x11: 7, 0x12: 7}, types="|u1")
    search.candidates.alive[0][:] = False
    search.candidates.alive[0][[0x10, 0x11, 0x12]] = True
    search.filter(op, value, than)
    assert set(np.flatnonzero(search.candidates.alive[0])) == kept


def test_every_op_is_tested():
    tested = {"equal", "not-equal", "less", "greater", "less-equal", "greater-equal", "changed-by"}
    assert set(OPS) == tested | {"increased", "decreased", "changed", "unchanged"}


@pytest.mark.parametrize("dtype", ["u1", "i1", "u2", "i2", "u4", "i4", "i8"])
@pytest.mark.parametrize("by", [0, 1, -1, 200, -200, 255, -255, 256, 70000, -70000])
def test_changed_by_in_the_arrays_own_dtype_matches_int64(dtype, by):
    from retrokit.ramsearch.engine import _changed_by

    info = np.iinfo(dtype)
    rng = np.random.default_rng(abs(by))
    cur = rng.integers(info.min, info.max, 4000, endpoint=True).astype(dtype)
    ref = rng.integers(info.min, info.max, 4000, endpoint=True).astype(dtype)
    ref[:1000] = (cur[:1000].astype(np.int64) - by).clip(info.min, info.max).astype(dtype)  # some true matches
    expected = cur.astype(np.int64) - ref.astype(np.int64) == by
    assert np.array_equal(_changed_by(cur, ref, by), expected)


def test_dense_and_sparse_filters_agree():
    rng = np.random.default_rng(3)
    first = rng.integers(0, 256, 256).astype(np.uint8)
    second = first.copy()
    second[rng.integers(0, 256, 40)] += 1
    searches = [Engine(LAYOUT, parse_search_types(None)) for _ in range(2)]
    for search in searches:
        search.add_snapshot(first)
        search.add_snapshot(second)
    searches[1].candidates.alive = [a & (np.arange(256) < 16) for a in searches[1].candidates.alive]  # few: sparse
    for search in searches:
        search.filter("increased")
    sparse = found(searches[1])
    assert sparse == {(a, t) for a, t in found(searches[0]) if a < BASE + 16}


def test_change_counts_over_many_snapshots():
    rows = [{0x10: k % 3, 0x11: 5, 0x12: k // 4} for k in range(10)]  # changes 9, 0 and 2 times
    search = engine(*rows, types="|u1")
    assert [int(search.change_counts()[0][p]) for p in (0x10, 0x11, 0x12)] == [9, 0, 2]
    search.filter("greater-equal", 2, "changes")
    assert {0x10, 0x12} <= set(np.flatnonzero(search.candidates.alive[0])) and not search.candidates.alive[0][0x11]


def test_undo_and_redo_round_trip():
    search = engine({0x10: 3}, {0x10: 2})
    start = search.candidates.copy()
    search.filter("decreased")
    after_one = search.candidates.copy()
    search.filter("equal", 2)
    after_two = search.candidates.copy()
    assert search.undo() == "equal 2" and search.candidates == after_one
    assert search.undo() == "decreased --than previous" and search.candidates == start
    assert search.redo() == "decreased --than previous" and search.candidates == after_one
    assert search.redo() == "equal 2" and search.candidates == after_two
    with pytest.raises(RamSearchError, match="undone filter to redo"):
        search.redo()
    search.undo()
    search.filter("changed")  # a new filter drops what could be redone
    with pytest.raises(RamSearchError):
        search.redo()


@pytest.mark.parametrize(
    ("args", "error", "message"),
    [
        (("decreased",), RamSearchError, "two snapshots"),
        (("equal",), RamSearchError, "two snapshots"),
        (("bigger", 3), InvalidArgumentError, "filter operation"),
        (("equl", 3), InvalidArgumentError, "Did you mean 'equal'"),
        (("equal", 3, "previous"), InvalidArgumentError, "not both"),
        (("increased", 3), InvalidArgumentError, "changed-by"),
        (("changed-by",), InvalidArgumentError, "difference"),
        (("equal", None, "frist"), InvalidArgumentError, "Did you mean 'first'"),
        (("equal", None, 0x10), InvalidArgumentError, "address in RAM"),
        (("equal", 2.5), InvalidArgumentError, "whole number"),
        (("equal", True), InvalidArgumentError, "whole number"),
    ],
    ids=[
        "decreased-first",
        "equal-previous-first",
        "unknown-op",
        "op-typo",
        "value-and-than",
        "increased-value",
        "changed-by-nothing",
        "than-typo",
        "than-outside-ram",
        "float",
        "bool",
    ],
)
def test_bad_filters(args, error, message):
    search = engine({0x10: 3})
    with pytest.raises(error, match=message):
        search.filter(*args)
    assert search.history == []


def test_layout_addresses_and_bounds():
    layout = RamLayout(((0xC000, 0x100), (0xE000, 0x10)))
    assert layout.addresses(np.array([0, 0xFF, 0x100, 0x10F])).tolist() == [0xC000, 0xC0FF, 0xE000, 0xE00F]
    assert layout.position(0xE004) == 0x104
    assert layout.format(0xE004) == "0xE004"
    with pytest.raises(InvalidArgumentError, match=r"0xC000-0xC0FF, 0xE000-0xE00F.*0xC0FF with 2 bytes"):
        layout.position(0xC0FF, 2)  # the second byte is past the region
    assert not layout.valid(2)[0xFF] and layout.valid(2)[0xFE]


def test_the_candidate_set_does_not_import_the_engine_that_uses_it():
    """candidates.py sits below engine.py: the listing of candidates lives in the engine, so no import circle."""
    import ast
    from pathlib import Path

    from retrokit.ramsearch import candidates

    tree = ast.parse(Path(candidates.__file__).read_text())
    imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    assert "retrokit.ramsearch.engine" not in imported and "retrokit.ramsearch.search" not in imported


def test_the_ramsearch_command_does_not_import_the_cli():
    import ast
    from pathlib import Path

    import retrokit.commands.ramsearch as command

    tree = ast.parse(Path(command.__file__).read_text())
    imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    imported |= {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names}
    assert "retrokit.cli" not in imported
