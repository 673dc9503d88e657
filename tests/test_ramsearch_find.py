"""Finding a field in one command, and the 3-byte types it may have (issue 44 items 1 and 3), on the NES cartridge.

Hopper's RAM map is in tools/nescart/README.md; its game.yaml names the
fields a search must find without reading it.
"""

from __future__ import annotations

import pytest

from retrokit.ramsearch import RamSearch
from retrokit.ramsearch.types import SEARCH_TYPES

FREE = 0x0700  # Hopper leaves the NES RAM's last page unused (tools/nescart/README.md)


@pytest.mark.parametrize(
    ("code", "value", "raw"),
    [
        ("<d3", 123456, b"\x56\x34\x12"),
        (">d3", 654321, b"\x65\x43\x21"),
        ("<u3", 0x9ABCDE, b"\xde\xbc\x9a"),
        (">u3", 0xFEDCBA, b"\xfe\xdc\xba"),
        ("<i3", -70000, (-70000 % (1 << 24)).to_bytes(3, "little")),
        (">i3", -1234567, (-1234567 % (1 << 24)).to_bytes(3, "big")),
    ],
)
def test_a_three_byte_value_is_found_by_the_default_search(code, value, raw):
    assert code in SEARCH_TYPES
    with RamSearch("Hopper-Nes", "Level1-1") as search:
        assert code in search.types
        search.poke(FREE, value, code)
        assert bytes(search.emulator.space.read_bytes(FREE, 3)) == raw  # the reader's layout, written by the host
        search.snapshot("poked")
        search.filter("equal", value)
        found = {(c.address, c.type): c for c in search.candidates()}
        assert found[FREE, code].values == (0, value) and not found[FREE, code].scale
