"""Every Gym Retro type code reads correctly from hand-made RAM, byte swap included."""

from __future__ import annotations

import random

import numpy as np
import pytest

from retrokit.errors import FieldTypeError, InvalidArgumentError
from retrokit.host.fields import FieldSpec
from retrokit.host.memory import AddressSpace, FieldReader, Region
from retrokit.host.typecodes import parse_type

BASE = 0xFF0000


def make_space(swap: int) -> tuple[AddressSpace, bytearray]:
    ram = bytearray(0x100)
    return AddressSpace([Region(BASE, len(ram), memoryview(ram), swap)]), ram


def place(ram: bytearray, swap: int, address: int, data: bytes) -> None:
    """Store console-order bytes the way the core's buffer holds them (little-endian host)."""
    for i, b in enumerate(data):
        ram[(address - BASE + i) ^ (swap - 1)] = b


def bcd(value: int, width: int) -> bytes:
    digits = str(value).rjust(2 * width, "0")
    return bytes(int(digits[i : i + 2], 16) for i in range(0, 2 * width, 2))


def halves(value: int, width: int) -> tuple[int, int]:
    half_bits = 8 * width // 2
    return value >> half_bits, value & ((1 << half_bits) - 1)


# (code, value, console-order bytes), each written independently of retrokit's code.
CASES = [
    ("|u1", 200, bytes([200])),
    ("|i1", -56, bytes([200])),
    ("|d1", 42, bytes([0x42])),
    ("|n1", 7, bytes([0xA7])),  # the high nibble is ignored
    (">u2", 0x1234, (0x1234).to_bytes(2, "big")),
    ("<u2", 0x1234, (0x1234).to_bytes(2, "little")),
    (">i2", -2, (-2).to_bytes(2, "big", signed=True)),
    ("<i2", -300, (-300).to_bytes(2, "little", signed=True)),
    (">u4", 0xDEADBEEF, (0xDEADBEEF).to_bytes(4, "big")),
    ("<i4", -123456, (-123456).to_bytes(4, "little", signed=True)),
    (">i4", -123456, (-123456).to_bytes(4, "big", signed=True)),
    (">d4", 12345678, bcd(12345678, 4)),
    ("<d4", 12345678, bcd(12345678, 4)[::-1]),
    (">n4", 1234, bytes([1, 2, 3, 4])),
    ("<n4", 1234, bytes([4, 3, 2, 1])),
    (">d6", 123456789012, bcd(123456789012, 6)),
    (">d8", 1234567890123456, bcd(1234567890123456, 8)),
    (">n8", 12345678, bytes([1, 2, 3, 4, 5, 6, 7, 8])),
    (">u3", 0x123456, (0x123456).to_bytes(3, "big")),
    (">d3", 123456, bcd(123456, 3)),  # an Atari score: six BCD digits in three bytes
    ("<d3", 123456, bcd(123456, 3)[::-1]),
    ("<i3", -70000, (-70000).to_bytes(3, "little", signed=True)),
    (">i5", -(2**33), (-(2**33)).to_bytes(5, "big", signed=True)),
    ("<u7", 2**55 + 3, (2**55 + 3).to_bytes(7, "little")),
    (">n5", 12345, bytes([1, 2, 3, 4, 5])),
    ("<>d6", 123456789012, bcd(789012, 3) + bcd(123456, 3)),  # little-endian words of big-endian BCD bytes
    ("<u8", 2**63 + 5, (2**63 + 5).to_bytes(8, "little")),
    (">i8", -(2**40), (-(2**40)).to_bytes(8, "big", signed=True)),
    # big-endian words of little-endian bytes: high word first
    ("><u4", 0x11223344, halves(0x11223344, 4)[0].to_bytes(2, "little") + halves(0x11223344, 4)[1].to_bytes(2, "little")),
    # little-endian words of big-endian bytes: low word first
    ("<>u4", 0x11223344, halves(0x11223344, 4)[1].to_bytes(2, "big") + halves(0x11223344, 4)[0].to_bytes(2, "big")),
    ("><i4", -5, halves(2**32 - 5, 4)[0].to_bytes(2, "little") + halves(2**32 - 5, 4)[1].to_bytes(2, "little")),
    ("><u8", 0x0102030405060708, (0x01020304).to_bytes(4, "little") + (0x05060708).to_bytes(4, "little")),
    # host-relative orders on a little-endian host
    ("=u2", 0x1234, (0x1234).to_bytes(2, "little")),
    (">=u4", 0x11223344, halves(0x11223344, 4)[0].to_bytes(2, "little") + halves(0x11223344, 4)[1].to_bytes(2, "little")),
    ("<=u4", 0x11223344, (0x11223344).to_bytes(4, "little")),
]


@pytest.mark.parametrize("swap", [1, 2], ids=["plain", "genesis-swap"])
@pytest.mark.parametrize("code,value,data", CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("address", [BASE + 0x10, BASE + 0x21], ids=["even", "odd"])
def test_type_reads_hand_made_ram(code: str, value: int, data: bytes, swap: int, address: int) -> None:
    space, ram = make_space(swap)
    place(ram, swap, address, data)
    reader = FieldReader([FieldSpec("f", address, code)], space)
    assert reader.read() == {"f": value}
    assert space.peek(address, code) == value


@pytest.mark.parametrize("code,value,data", CASES, ids=[c[0] for c in CASES])
def test_type_encodes_what_it_decodes(code: str, value: int, data: bytes) -> None:
    ftype = parse_type(code)
    if ftype.kind == 3:  # low-nibble BCD drops the high nibble, so compare values
        assert ftype.decode(ftype.encode(value)) == value
    else:
        assert ftype.encode(value) == data


def test_poke_writes_through_the_genesis_swap() -> None:
    space, ram = make_space(2)
    space.poke(BASE + 0x10, 0xABCD, ">u2")
    assert ram[0x10] == 0xCD and ram[0x11] == 0xAB  # byte-swapped words in the buffer
    assert space.peek(BASE + 0x10, ">u2") == 0xABCD


def test_bcd_nibbles_above_nine_wrap_like_gym_retro() -> None:
    space, ram = make_space(1)
    place(ram, 1, BASE, bytes([0xAB, 0x1F]))
    assert FieldReader([FieldSpec("f", BASE, ">d2")], space).read()["f"] == ((0xB % 10) + (0xA % 10) * 10) * 100 + 5 + 10


def test_mask_applies_after_decoding() -> None:
    space, ram = make_space(2)
    place(ram, 2, BASE, (-1).to_bytes(2, "big", signed=True))
    reader = FieldReader([FieldSpec("low", BASE, ">i2", mask=0x0F0F), FieldSpec("all", BASE, ">i2")], space)
    assert reader.read() == {"low": 0x0F0F, "all": -1}


def test_native_reader_matches_reference_decoder_on_random_ram() -> None:
    rng = random.Random(1)
    codes = [c[0] for c in CASES]
    space, ram = make_space(2)
    specs = [FieldSpec(f"f{i}", BASE + rng.randrange(0, 0xF0), rng.choice(codes)) for i in range(200)]
    reader = FieldReader(specs, space)
    for _ in range(20):
        ram[:] = bytes(rng.randrange(256) for _ in range(len(ram)))
        got = reader.read()
        for spec in specs:
            expected = spec.field_type.decode(space.read_bytes(spec.address, spec.field_type.width))
            assert got[spec.name] == expected, spec


def test_reader_reuses_its_output_array() -> None:
    space, ram = make_space(1)
    reader = FieldReader([FieldSpec("a", BASE, "|u1")], space)
    first = reader.read_array()
    ram[0] = 9
    assert reader.read_array() is first and first[0] == 9


BAD_CODES = [
    (">u9", "width of 1 to 8"),
    (">x2", "a kind"),
    ("u2", "byte order"),
    ("><u3", "even width"),
    (">u", "Expected a type code"),
    (2, "type code string"),
]


@pytest.mark.parametrize("code,message", BAD_CODES, ids=[repr(c[0]) for c in BAD_CODES])
def test_bad_type_codes_say_what_was_expected(code: object, message: str) -> None:
    with pytest.raises(FieldTypeError, match=message):
        parse_type(code)  # type: ignore[arg-type]


def test_bad_type_code_suggests_a_close_one() -> None:
    with pytest.raises(FieldTypeError, match=r"Did you mean.*'>u2'"):
        parse_type(">U2")


def test_address_outside_ram_is_a_clear_error() -> None:
    space, _ = make_space(2)
    with pytest.raises(InvalidArgumentError, match=r"inside the mapped memory \(0xff0000-0xff00ff\).*0xff00ff \(width 2\)"):
        FieldReader([FieldSpec("f", BASE + 0xFF, ">u2")], space)


def test_value_out_of_range_is_refused_on_poke() -> None:
    space, _ = make_space(1)
    with pytest.raises(InvalidArgumentError, match="from 0 to 255"):
        space.poke(BASE, 256, "|u1")


def test_corrupt_plan_is_refused_before_reading() -> None:
    from retrokit.native import _host

    ram = bytearray(4)
    plan = np.zeros((1, _host.PLAN_COLUMNS), dtype=np.int64)
    plan[0, :5] = [0, 1, 0, -1, 10]  # offset 10 is outside a 4-byte buffer
    with pytest.raises(InvalidArgumentError, match="outside its buffer"):
        _host.read_fields([ram], plan, np.zeros(1, dtype=np.int64))


class MappedEmulator:
    """Stands in for a core that gives a memory map (SET_MEMORY_MAPS), as SNES cores do."""

    def __init__(self) -> None:
        self.wram, self.rom, self.sram = bytearray(0x20000), bytearray(0x100), bytearray(0x800)

    def memory_maps(self) -> list[dict]:
        return [
            {"flags": 1, "start": 0x000000, "select": 0, "disconnect": 0, "length": 0x100,
             "addrspace": "", "memory": memoryview(self.rom)},  # read-only: skipped
            {"flags": 4, "start": 0x7E0000, "select": 0xFE0000, "disconnect": 0, "length": 0x20000,
             "addrspace": "", "memory": memoryview(self.wram)},
            {"flags": 8, "start": 0x700000, "select": 0xFFF800, "disconnect": 0, "length": 0,
             "addrspace": "", "memory": memoryview(self.sram)},  # length from select: 0x800
        ]

    def memory(self, kind: int) -> None:
        raise AssertionError("the memory map should be used instead of the system RAM")


def test_memory_maps_are_honoured() -> None:
    from retrokit.host.systems import get_system

    emu = MappedEmulator()
    space = AddressSpace.for_emulator(get_system("Snes"), emu)
    assert [(r.start, r.length) for r in space.regions] == [(0x7E0000, 0x20000), (0x700000, 0x800)]
    emu.wram[0x1234:0x1236] = (0x34).to_bytes(1, "little") + (0x12).to_bytes(1, "little")
    emu.sram[0x10] = 0x99
    reader = FieldReader([FieldSpec("a", 0x7E1234, "<u2"), FieldSpec("b", 0x700010, "|u1")], space)
    assert reader.read() == {"a": 0x1234, "b": 0x99}
    with pytest.raises(InvalidArgumentError, match="0x7e0000-0x7fffff, 0x700000-0x7007ff"):
        space.locate(0x000010)  # ROM is not mapped for fields


def test_ramsearch_decodes_every_width_of_every_kind_as_the_reference() -> None:
    """A RAM search of a 3-, 5-, 6- or 7-byte type (a signed one too: its sign bit extended) reads what fields read."""
    from retrokit.ramsearch.types import decode_all

    data = np.random.default_rng(0).integers(0, 256, 64, dtype=np.uint8)
    data[:8] = [0xFF, 0x80, 0x81, 0x99, 0x12, 0xF0, 0x01, 0x80]  # sign bits set, BCD nibbles above 9
    codes = [f"{order}{kind}{width}" for order in "<>" for kind in "uidn" for width in range(1, 9)]
    types = [parse_type(code) for code in [*codes, "><u4", "<>i6", "><d8"]]
    for ftype, values in zip(types, decode_all(data, types)):
        for position in range(len(data) - ftype.width):
            expected = ftype.decode(bytes(data[position : position + ftype.width]))
            assert int(values[position]) == expected, (ftype.code, position)
