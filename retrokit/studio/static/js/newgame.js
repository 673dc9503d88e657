// New game: make a game from a ROM file on this machine, as `retrokit new` does (its system told from the ROM's
// header or extension), then open it in the studio.

import { post } from "./api.js";
import { byId, el, replace } from "./dom.js";
import { attempt } from "./status.js";

async function make() {
  const body = { rom: byId("new-rom").value.trim(), name: byId("new-name").value.trim() };
  const system = byId("new-system").value.trim();
  if (system) body.system = system;
  const answer = await post("new", body);
  replace(byId("new-result"),
    el("p", { class: "ok" }, `Made ${answer.game ?? body.name} in ${answer.folder ?? ""}.`),
    answer.next ? el("p", { class: "dim" }, answer.next) : null,
    el("button", { type: "button", onclick: () => location.reload() }, "Reload the studio"));
  return `Made ${answer.game ?? body.name}.`;
}

export async function init() {
  replace(byId("newgame"),
    el("h2", {}, "New game"),
    el("p", { class: "dim" }, "From a ROM file on this machine that no known game matches, as `retrokit new` does: the game goes into your games folder with a game.yaml holding its system and the ROM's SHA-1, and the ROM is imported."),
    el("form", { id: "new-form" },
      el("div", { class: "row" }, el("label", {}, "ROM file ", el("input", { id: "new-rom", size: 40, placeholder: "/home/me/roms/runner.bin" }))),
      el("div", { class: "row" }, el("label", {}, "name ", el("input", { id: "new-name", size: 20, placeholder: "Runner-Genesis" })),
        el("label", {}, "system ", el("input", { id: "new-system", size: 8, placeholder: "(from the ROM)" })),
        el("button", { type: "submit", id: "new-make" }, "Make the game"))),
    el("div", { id: "new-result" }));
  byId("new-form").addEventListener("submit", (event) => {
    event.preventDefault();
    attempt(make, (line) => line);
  });
}

export function shown() {}
