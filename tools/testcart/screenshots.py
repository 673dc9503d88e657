#!/usr/bin/env python3
"""Take the README's Dasher screenshots, one per zone, with retrokit's host.

Usage (from the repository root):

    python tools/testcart/screenshots.py [--out docs/images] [--scale 2]

For each zone the script selects act 1 by writing the level-select bytes at
the title screen, presses START on both pads (two players), and lets a
scripted runner play: hold RIGHT, and jump when the RAM ground map shows a
pit, spikes or a wall ahead, or a crawler is near.  When player 1 passes the
zone's chosen x, it saves the frame as docs/images/dasher-zone<N>.png,
scaled up with nearest-neighbour pixels.  Everything is deterministic, so
reruns give the same images.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image

from retrokit.data.games import load_game
from retrokit.host.emulator import Emulator

REPO = Path(__file__).resolve().parents[2]
GAME = REPO / "games" / "Dasher-Genesis"
GROUND_MAP = 0xFF0100  # tools/testcart/src/ram.h: one byte per 8-pixel column
ENEMIES, ENEMY_SIZE = 0xFF0060, 12
SHOT_AT_X = {0: 760, 1: 700, 2: 1180}  # player 1's x for each zone's picture


class Runner:
    def __init__(self, rom: Path) -> None:
        self.emu = Emulator.for_rom(rom)
        self.fields = load_game(GAME).fields
        self.jumping = [False, False]

    def __getitem__(self, name: str) -> int:
        field = self.fields[name]
        return self.emu.peek(field.address, field.type)

    def __setitem__(self, name: str, value: int) -> None:
        field = self.fields[name]
        self.emu.poke(field.address, value, field.type)

    def danger_ahead(self, x: int, y: int) -> bool:
        for px in range(x + 6, x + 44, 4):
            ground = self.emu.peek(GROUND_MAP + px // 8)
            height = ground & 0x1F
            if height == 0 or ground & 0x20 or 224 - 8 * height < y - 8:
                return True
        for i in range(self["enemy_count"]):
            base = ENEMIES + ENEMY_SIZE * i
            if self.emu.peek(base + 8) and 0 < self.emu.peek(base, ">i2") - x < 56:
                return True
        return False

    def buttons(self, player: int) -> list[str]:
        p = f"p{player + 1}_"
        if self[p + "on_ground"]:
            self.jumping[player] = self.danger_ahead(self[p + "x"], self[p + "y"]) and not self.jumping[player]
        return ["RIGHT", "B"] if self.jumping[player] else ["RIGHT"]

    def step(self) -> None:
        self.emu.run([self.emu.system.mask(self.buttons(0)), self.emu.system.mask(self.buttons(1))], 1)


def shoot(rom: Path, zone: int, out: Path, scale: int) -> Path:
    run = Runner(rom)
    try:
        while run["frame"] < 30:
            run.emu.run([0, 0], 1)
        run["zone"], run["act"] = zone, 0  # the level select, read when START is pressed
        start = run.emu.system.mask(["START"])
        run.emu.run([start, start], 1)
        while run["game_mode"] != 1:
            run.emu.run([0, 0], 1)
        for _ in range(3000):
            if run["p1_x"] >= SHOT_AT_X[zone]:
                break
            run.step()
        else:
            raise SystemExit(f"zone {zone + 1}: player 1 never reached x {SHOT_AT_X[zone]}")
        image = Image.fromarray(np.ascontiguousarray(run.emu.screen()))
        image = image.resize((image.width * scale, image.height * scale), Image.NEAREST)
        path = out / f"dasher-zone{zone + 1}.png"
        image.save(path, optimize=True)
        return path
    finally:
        run.emu.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("--rom", type=Path, default=GAME / "rom.md")
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "images")
    parser.add_argument("--scale", type=int, default=2)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for zone in range(3):
        print(shoot(args.rom, zone, args.out, args.scale))


if __name__ == "__main__":
    main()
