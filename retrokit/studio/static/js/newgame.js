// New game: make a game from a ROM file on this machine, as `retrokit new` does (its system told from the ROM's
// header or extension), then play it in the studio; or open another known game by name. Either way the session
// plays another game, so the page starts afresh (its buttons, states and fields are the new game's).

import { post } from "./api.js";
import { byId, el, replace } from "./dom.js";
import { attemptOnSubmit } from "./status.js";

const RESUME = "retrokit-studio-resume";

/** Reload the page on the game the session now plays, and play it: a reload closes the socket, which pauses
 * the game, and the user asked to play this game, not to look at its first frame. */
function reloadAndPlay(delay) {
  sessionStorage.setItem(RESUME, "1");
  setTimeout(() => location.reload(), delay);
}

/** Called once the page is up: resume if the reload was ours. */
export function afterReload(send) {
  if (sessionStorage.getItem(RESUME)) {
    sessionStorage.removeItem(RESUME);
    send({ type: "resume" });
  }
}

async function make() {
  const body = { rom: byId("new-rom").value.trim(), name: byId("new-name").value.trim(), open: true };
  const system = byId("new-system").value.trim();
  if (system) body.system = system;
  const answer = await post("newgame", body);
  replace(byId("new-result"),
    el("p", { class: "ok" }, `Made ${answer.game} (told by ${answer.told_by}) in ${answer.folder}; the ROM (SHA-1 ${answer.sha1}) is ${answer.rom}.`),
    el("p", { class: "dim" }, "Reloading the studio on it…"));
  reloadAndPlay(1500);
  return `Made ${answer.game}; the studio plays it now.`;
}

async function openGame() {
  const game = byId("open-game").value.trim();
  const answer = await post("game", { game });
  reloadAndPlay(500);
  return `Opening ${answer.game}…`;
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
    el("div", { id: "new-result" }),
    el("h3", {}, "Open another game"),
    el("form", { id: "open-form", class: "row" },
      el("label", {}, "game ", el("input", { id: "open-game", size: 24, placeholder: "Airstriker-Genesis" })),
      el("button", { type: "submit", id: "open-make" }, "Open")));
  attemptOnSubmit(byId("new-form"), make, (line) => line);
  attemptOnSubmit(byId("open-form"), openGame, (line) => line);
}

export function shown() {}
