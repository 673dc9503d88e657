// States and movies: the game's states (load, set as default), the moment saved as a named state with the same
// record `retrokit integrate` writes, and .bk2 movies recorded from the inputs played and replayed on screen.

import { get, post } from "./api.js";
import { byId, el, replace } from "./dom.js";
import { setStates } from "./play.js";
import { on } from "./socket.js";
import { attempt, attemptOnSubmit } from "./status.js";

let recording = false;

function showStates(answer) {
  const rows = answer.states.map((name) => {
    const isDefault = name === answer.default;
    return el("tr", { "data-state": name, class: name === answer.current ? "selected" : null },
      el("td", { class: "mono" }, name),
      el("td", {}, isDefault ? el("span", { class: "ok" }, "default") : ""),
      el("td", {},
        el("button", { type: "button", class: "load", onclick: () => attempt(() => load(name), `Loaded state ${name}.`) }, "Load"),
        " ",
        el("button", { type: "button", class: "make-default", disabled: isDefault,
          onclick: () => attempt(() => makeDefault(name), (a) => `Default state is now ${name} (${a.game_file}).`) },
        "Set default")));
  });
  replace(byId("states-rows"), rows);
  setStates(answer.states, answer.current);
}

async function load(name) {
  showStates(await post("states/load", { name }));
}

async function makeDefault(name) {
  const answer = await post("states/default", { name });
  showStates(answer);
  return answer;
}

async function save() {
  const name = byId("state-name").value.trim();
  const answer = await post("states/save", { name, default: byId("state-default").checked, force: byId("state-force").checked });
  showStates(answer);
  // The outcome of RamSearch.save_state: "made", "replaced" (with replace ticked) or "up to date".
  const what = { made: "saved", "up to date": "is up to date (the same state was there)" }[answer.status] ?? answer.status;
  return `State ${answer.name} ${what}: ${answer.path}.`;
}

function showMovies(movies) {
  replace(byId("movie-rows"), movies.map((movie) => el("tr", { "data-movie": movie.name },
    el("td", { class: "mono" }, movie.name),
    el("td", { class: "num dim" }, `${movie.bytes.toLocaleString("en")} bytes`),
    el("td", {}, el("button", { type: "button", onclick: () => attempt(() => post("movies/play", { name: movie.name }),
      (a) => `Replaying ${movie.name}: ${a.frames.toLocaleString("en")} frames.`) }, "Replay")))));
}

function showRecording(on) {
  recording = on;
  byId("record").textContent = on ? "Stop and save" : "Record";
  byId("record").classList.toggle("error", on);
  byId("movie-name").hidden = !on;
}

async function record() {
  if (!recording) {
    await post("movies/record");
    showRecording(true);
    byId("movie-name").focus();
    return "Recording the inputs from now: play, then stop and save.";
  }
  const answer = await post("movies/stop", { name: byId("movie-name").value.trim(), force: byId("state-force").checked });
  showRecording(false);
  showMovies(answer.movies);
  return `Wrote ${answer.frames.toLocaleString("en")} frames to ${answer.path}.`;
}

export async function init() {
  replace(byId("states-body"),
    el("div", { class: "scroll short" }, el("table", { id: "states-table" }, el("tbody", { id: "states-rows" }))),
    el("form", { id: "state-form", class: "row" },
      el("label", {}, "save the moment as ", el("input", { id: "state-name", size: 14, placeholder: "Zone1.Mine" })),
      el("label", {}, el("input", { type: "checkbox", id: "state-default" }), " default"),
      el("label", { title: "Replace a file of that name" }, el("input", { type: "checkbox", id: "state-force" }), " replace"),
      el("button", { type: "submit", id: "state-save" }, "Save state")),
    el("h3", {}, "Movies (.bk2)"),
    el("div", { class: "row" },
      el("button", { type: "button", id: "record" }, "Record"),
      el("input", { id: "movie-name", size: 14, placeholder: "movie name", hidden: true, "aria-label": "movie name" })),
    el("table", { id: "movies-table" }, el("tbody", { id: "movie-rows" })));
  attemptOnSubmit(byId("state-form"), save, (line) => line);
  byId("record").addEventListener("click", () => attempt(record, (line) => line));
  on("status", (status) => {
    if (typeof status.recording === "boolean" && status.recording !== recording) showRecording(status.recording);
    // A reset from the Play panel loads a state too: the row of the state played is the highlighted one.
    for (const row of byId("states-rows").querySelectorAll("tr")) row.classList.toggle("selected", row.dataset.state === status.state);
  });
  showStates(await get("states"));
  const movies = await get("movies");
  showMovies(movies.movies);
  showRecording(Boolean(movies.recording));
}
