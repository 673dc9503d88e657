"""Console addresses, RAM fields, stable-retro's RAM, and reading them all after each step.

An :class:`AddressSpace` maps console addresses onto the core's memory buffers
(the system RAM, or the regions of the core's memory map), undoing the byte
swap of systems such as the Genesis. It also knows the RAM as stable-retro
shows it (``get_ram()``, RAM observations): its blocks (:class:`RamBlock`),
one rule for every system. A :class:`FieldReader` compiles a game's fields
once into a plan the native host executes in a single call.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from retrokit.errors import CoreError, FieldNotFoundError, InvalidArgumentError, did_you_mean
from retrokit.host import primitives
from retrokit.host.fields import FieldSpec
from retrokit.host.systems import System
from retrokit.host.typecodes import UNSIGNED, parse_type

_LITTLE_HOST = sys.byteorder == "little"
_CONST = 1  # RETRO_MEMDESC_CONST: read-only memory such as ROM


@dataclass(frozen=True)
class Region:
    """A run of console addresses backed by one memory buffer."""

    start: int
    length: int
    buffer: memoryview
    swap: int = 1

    def offset(self, address: int) -> int:
        """Return the buffer offset of a console address inside this region."""
        relative = address - self.start
        return relative ^ (self.swap - 1) if _LITTLE_HOST else relative


@dataclass(frozen=True)
class RamBlock:
    """One block of the RAM stable-retro shows: ``length`` bytes from console address ``start``, as the core keeps them.

    Attributes:
        start: The console address of its first byte.
        length: Its size in bytes.
        region: The index of the :class:`Region` whose buffer holds it (from its start), or ``None`` where
            the core put no memory behind the descriptor: stable-retro shows zeros there.
    """

    start: int
    length: int
    region: int | None


def stable_retro_blocks(descriptors: Sequence[tuple[int, int, int | None]]) -> list[RamBlock]:
    """The blocks of stable-retro's RAM, from a core's writable memory descriptors, in their order.

    stable-retro keeps one block per descriptor by its start address, so a later
    descriptor at the same start replaces an earlier one, and lays them out in
    ascending order of address (``Emulator::reconfigureAddressSpace`` and
    ``RetroEnv.get_ram`` in its sources).

    Args:
        descriptors: ``(start, length, region index or None)`` of each descriptor that is not read-only.
    """
    by_start = {start: RamBlock(start, length, region) for start, length, region in descriptors}
    return [by_start[start] for start in sorted(by_start)]


class AddressSpace:
    """Console addresses over a core's memory.

    Args:
        regions: The mapped regions, searched in order.
        ram_blocks: stable-retro's RAM (:func:`stable_retro_blocks`); by default each region, in address order.
    """

    def __init__(self, regions: Sequence[Region], ram_blocks: Sequence[RamBlock] | None = None) -> None:
        self.regions = list(regions)
        self.buffers = [r.buffer for r in self.regions]
        if ram_blocks is None:
            ram_blocks = stable_retro_blocks([(r.start, r.length, i) for i, r in enumerate(self.regions)])
        self.ram_blocks = tuple(ram_blocks)
        #: The bytes of stable-retro's RAM: its blocks' lengths added up.
        self.ram_size = sum(block.length for block in self.ram_blocks)
        # Where each block goes in the RAM and comes from in its buffer: (at, end, region or None, from, to).
        self._ram_plan: list[tuple[int, int, int | None, int, int]] = []
        at = 0
        for block in self.ram_blocks:
            rel = 0 if block.region is None else block.start - self.regions[block.region].start
            last = self._ram_plan[-1] if self._ram_plan else None
            if last is not None and block.region is not None and last[2] == block.region and last[4] == rel:
                # the block follows the last one in the same buffer (the NES's ten): one copy for both
                self._ram_plan[-1] = (last[0], at + block.length, block.region, last[3], rel + block.length)
            else:
                self._ram_plan.append((at, at + block.length, block.region, rel, rel + block.length))
            at += block.length
        self._layout = self._describe(self.regions, self.ram_blocks)

    @staticmethod
    def _describe(regions: Sequence[Region], blocks: Sequence[RamBlock]) -> list[tuple[int, ...]]:
        return [(r.start, r.length, r.swap) for r in regions] + [(b.start, b.length, -1) for b in blocks]

    def copy_ram(self, out: np.ndarray) -> np.ndarray:
        """Copy the RAM as stable-retro shows it into ``out`` (``uint8``, :attr:`ram_size` bytes) and return ``out``.

        Each block's bytes come as the core keeps them (a Genesis's 16-bit words
        host-order, as stable-retro's ``get_ram`` gives them), one after the other
        in ascending order of address; a block the core put no memory behind is zeros.
        """
        view = memoryview(out).cast("B")
        buffers = self.buffers
        for at, end, region, start, stop in self._ram_plan:
            if region is None:
                out[at:end] = 0
            else:
                view[at:end] = buffers[region][start:stop]
        return out

    def release(self) -> None:
        """Let go of every buffer onto the core's memory (before a reload frees it), until :meth:`rebind`.

        An array made from a buffer keeps the core's memory exported even so (a
        memoryview shares what it looks through): the native host refuses the
        reload while any such export lives.

        Raises:
            CoreError: A buffer is still exported directly (then it stays alive).
        """
        held = []
        for region in self.regions:
            try:
                region.buffer.release()
            except BufferError:  # something took a buffer from it directly
                held.append(f"{region.start:#x}-{region.start + region.length - 1:#x}")
        self.regions.clear()
        self.buffers.clear()
        if held:
            raise CoreError(
                f"Expected no array onto the emulator's memory to be alive before its game is reloaded (a reload "
                f"frees that memory); found one onto {', '.join(held)}. Copy the values to keep (array.copy()) "
                "and drop the array before loading a state."
            )

    def rebind(self, fresh: AddressSpace) -> None:
        """Look at the memory of ``fresh`` from now on, in place: whoever holds this space reads the new memory.

        Raises:
            CoreError: ``fresh`` lays its regions out otherwise (the core changed its map on a reload).
        """
        found = self._describe(fresh.regions, fresh.ram_blocks)
        if found != self._layout:
            raise CoreError(
                f"Expected the core to map the same memory after reloading its game ({self._layout}); found "
                f"{found}. Report the core: its fields cannot be read across a reload."
            )
        self.regions[:] = fresh.regions
        self.buffers[:] = fresh.buffers

    @classmethod
    def for_emulator(cls, system: System, emulator: primitives.NativeEmulator) -> AddressSpace:
        """Build the address space of a loaded emulator.

        The core's memory map is used where it gives one (skipping read-only
        regions, as Gym Retro does); otherwise the system RAM sits at the
        system's RAM base. stable-retro's RAM follows the same rule: the map's
        writable descriptors (one with no memory behind it too, as zeros), or
        else the system RAM at the descriptor's ``ram.base``.

        Descriptors that follow each other in console addresses and in memory
        make one region (FCEUmm maps the NES's 2 KiB of RAM as two 1 KiB
        descriptors over one array), so a field across them reads the bytes
        that follow, as stable-retro reads it.
        """
        regions: list[Region] = []
        descriptors: list[tuple[int, int, int | None]] = []
        run: tuple[int, int] | None = None  # the last region's first descriptor and how many it holds, if it may grow
        for index, desc in enumerate(emulator.memory_maps()):
            if desc["flags"] & _CONST:
                run = None
                continue
            length = desc["length"]
            if desc["select"]:
                by_select = ((~desc["select"] & ~desc["start"]) + 1) & desc["select"]
                length = min(length, by_select) if length else by_select
            memory = desc["memory"]
            if memory is None:
                descriptors.append((desc["start"], length, None))
                run = None
                continue
            whole = length == len(memory)  # the region is all of the descriptor's memory: the next may follow it
            last = regions[-1] if regions else None
            if run is not None and whole and last is not None and desc["start"] == last.start + last.length:
                first, count = run
                span = emulator.memory_span(first, count + 1)  # None unless the memory follows too
                if span is not None:
                    regions[-1] = Region(last.start, last.length + length, span, system.ram_swap)
                    descriptors.append((desc["start"], length, len(regions) - 1))
                    run = (first, count + 1)
                    continue
            descriptors.append((desc["start"], length, len(regions)))
            regions.append(Region(desc["start"], length, memory, system.ram_swap))
            run = (index, 1) if whole else None
        if not regions:
            ram = emulator.memory(primitives.MEMORY_SYSTEM_RAM)
            if ram is not None:
                regions.append(Region(system.ram_base, len(ram), ram, system.ram_swap))
                if not descriptors:
                    descriptors.append((system.ram_base, len(ram), 0))
        return cls(regions, stable_retro_blocks(descriptors))

    def locate(self, address: int, width: int = 1) -> tuple[int, int]:
        """Return ``(buffer index, region-relative start)`` of ``width`` bytes at ``address``.

        Raises:
            InvalidArgumentError: The bytes are not all inside one mapped region.
        """
        index = self._region_of(address, width)
        if index is not None:
            return index, address
        mapped = ", ".join(f"{r.start:#x}-{r.start + r.length - 1:#x}" for r in self.regions) or "none"
        raise InvalidArgumentError(
            f"Expected an address inside the mapped memory ({mapped}), got {address:#x} (width {width}). "
            f"Check the field's address: it is a console address, not a buffer offset."
        )

    def holds(self, address: int, width: int = 1) -> bool:
        """Whether ``width`` bytes at ``address`` all lie inside one mapped region (where :meth:`locate` finds them)."""
        return self._region_of(address, width) is not None

    def _region_of(self, address: int, width: int) -> int | None:
        for index, region in enumerate(self.regions):
            if region.start <= address and address + width <= region.start + region.length:
                return index
        return None

    def offsets(self, address: int, width: int) -> tuple[int, list[int]]:
        """Return the buffer index and the buffer offset of each byte at ``address``."""
        index, _ = self.locate(address, width)
        region = self.regions[index]
        return index, [region.offset(address + i) for i in range(width)]

    def read_bytes(self, address: int, width: int) -> bytes:
        """Read ``width`` bytes in console order."""
        index, offs = self.offsets(address, width)
        buf = self.buffers[index]
        return bytes(buf[o] for o in offs)

    def write_bytes(self, address: int, data: bytes) -> None:
        """Write bytes in console order."""
        index, offs = self.offsets(address, len(data))
        buf = self.buffers[index]
        for o, b in zip(offs, data):
            buf[o] = b

    def peek(self, address: int, type_code: str = "|u1") -> int:
        """Read one value of a type at a console address."""
        ftype = parse_type(type_code)
        return ftype.decode(self.read_bytes(address, ftype.width))

    def poke(self, address: int, value: int, type_code: str = "|u1") -> None:
        """Write one value of a type at a console address."""
        ftype = parse_type(type_code)
        self.write_bytes(address, ftype.encode(value))


class FieldReader:
    """Reads every field of a game in one native call.

    Args:
        fields: The fields, as specs or a name-to-spec mapping.
        space: The address space they live in.
    """

    def __init__(self, fields: Iterable[FieldSpec] | Mapping[str, FieldSpec], space: AddressSpace) -> None:
        specs = list(fields.values()) if isinstance(fields, Mapping) else list(fields)
        self.space = space
        self.specs = {s.name: s for s in specs}
        self.names = list(self.specs)
        self.plan = np.zeros((len(specs), primitives.PLAN_COLUMNS), dtype=np.int64)
        for row, spec in zip(self.plan, specs):
            ftype = spec.field_type
            try:
                index, offs = space.offsets(spec.address, ftype.width)
            except InvalidArgumentError as exc:  # name the field, so the data file can be fixed
                raise InvalidArgumentError(f"Field {spec.name!r} ({spec.address:#x}, {spec.type}): {exc}") from None
            row[0], row[1], row[2] = index, ftype.width, ftype.kind
            row[3] = -1 if spec.mask is None else spec.mask
            row[4 : 4 + ftype.width] = [offs[i] for i in ftype.significance()]
        self.values = np.zeros(len(specs), dtype=np.int64)
        self._names = tuple(self.names)
        # 8-byte unsigned fields may not fit int64: values then holds their two's complement.
        self.fits_int64 = not any(s.field_type.kind == UNSIGNED and s.field_type.width == 8 for s in specs)

    def read_array(self) -> np.ndarray:
        """Decode every field into ``self.values`` (reused between calls) and return it.

        The array is int64: an 8-byte unsigned field of 2**63 or more reads
        as its two's-complement negative here; :meth:`read` corrects it.
        """
        primitives.read_fields(self.space.buffers, self.plan, self.values)
        return self.values

    def read(self) -> dict[str, int]:
        """Return every field's value by name."""
        return primitives.read_fields(self.space.buffers, self.plan, self.values, self._names)

    def spec(self, name: str) -> FieldSpec:
        """Return a field's spec by name.

        Raises:
            FieldNotFoundError: No field has that name.
        """
        try:
            return self.specs[name]
        except KeyError:
            raise FieldNotFoundError(
                f"Expected one of the game's fields ({', '.join(self.names)}), got {name!r}."
                + did_you_mean(name, self.names)
            ) from None

    def write(self, name: str, value: int) -> None:
        """Write a field's value into RAM."""
        spec = self.spec(name)
        self.space.poke(spec.address, value, spec.type)
