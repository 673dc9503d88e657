// Watch: every field of the game with its live value (decoded by the same reader the envs use), and editing a
// field's address, type and range, which rewrites its line in game.yaml through the RAM search's writer.

import { get, api } from "./api.js";
import { byId, el, parseNumber, replace } from "./dom.js";
import { on } from "./socket.js";
import { attemptOnSubmit } from "./status.js";

const valueCells = new Map(); // field name -> <td>
let shownFrame = null; // the frame of the values shown
let reading = false;

/** Show values read at a frame; an older push arriving late is dropped. The frame is on the table too. */
function showAt(frame, values) {
  if (frame !== undefined && shownFrame !== null && frame < shownFrame) return;
  shownFrame = frame ?? shownFrame;
  byId("watch-table").dataset.frame = String(shownFrame);
  showValues(values);
}

function showValues(values) {
  for (const [name, value] of Object.entries(values)) {
    const cell = valueCells.get(name);
    if (cell) cell.textContent = shownValue(value);
  }
}

let pausedAt = null; // the frame the game is paused at (null: running)

/** Read every value once the game is paused at a frame not shown yet (one read at a time). */
async function readPaused() {
  if (reading || pausedAt === null || pausedAt === shownFrame) return;
  reading = true;
  try {
    const answer = await get("fields");
    showAt(answer.frame, Object.fromEntries(answer.fields.map((f) => [f.name, f.value])));
  } catch {
    // the next status tries again
  } finally {
    reading = false;
  }
  readPaused(); // paused elsewhere meanwhile
}

function shownValue(value) {
  return typeof value === "object" && value !== null ? JSON.stringify(value) : String(value);
}

/** An inline editor in place of a field's row. */
function editor(field, tr) {
  const address = el("input", { class: "address", value: field.hex, "aria-label": "address" });
  const type = el("input", { size: 5, value: field.type, "aria-label": "type" });
  const lo = el("input", { size: 4, value: field.range ? String(field.range[0]) : "", placeholder: "lo", "aria-label": "range low" });
  const hi = el("input", { size: 4, value: field.range ? String(field.range[1]) : "", placeholder: "hi", "aria-label": "range high" });
  const save = el("button", { type: "submit" }, "Save");
  const cancel = el("button", { type: "button", onclick: () => refresh() }, "Cancel");
  const form = el("form", { class: "row" }, address, type, lo, " to ", hi, save, cancel);
  attemptOnSubmit(form, async () => {
    const low = parseNumber(lo.value, "range's low end");
    const high = parseNumber(hi.value, "range's high end");
    if ((low === null) !== (high === null)) throw new Error("Expected both ends of the range, or neither.");
    const answer = await api("PATCH", `fields/${encodeURIComponent(field.name)}`,
      { address: address.value.trim(), type: type.value.trim(), range: low === null ? null : [low, high] });
    await refresh();
    return answer;
  }, (answer) => `Wrote field ${answer.name} (${answer.hex}, ${answer.type}) into ${answer.path}.`);
  replace(tr, el("td", { class: "mono" }, field.name), el("td", { colspan: 4 }, form));
  address.focus();
}

/** Read the fields again (after one was added or edited). */
export async function refresh() {
  const answer = await get("fields");
  valueCells.clear();
  const rows = answer.fields.map((field) => {
    const value = el("td", { class: "num live" }, shownValue(field.value));
    valueCells.set(field.name, value);
    const tr = el("tr", { "data-field": field.name });
    const edit = el("button", { type: "button", class: "small", title: field.mask === null || field.mask === undefined ? "Edit address, type and range" : "A masked field: edit it in game.yaml" }, "Edit");
    edit.disabled = field.mask !== null && field.mask !== undefined;
    edit.addEventListener("click", () => editor(field, tr));
    replace(tr, el("td", { class: "mono" }, field.name), el("td", { class: "mono" }, field.hex),
      el("td", { class: "mono" }, field.type), el("td", { class: "mono" }, field.range ? `[${field.range.join(", ")}]` : ""),
      value, el("td", {}, edit));
    return tr;
  });
  replace(byId("watch-rows"), rows);
  shownFrame = null;
  showAt(answer.frame, {});
  byId("watch-count").textContent = `${answer.fields.length} fields of ${answer.game}`;
}

export async function init() {
  replace(byId("watch"),
    el("h2", {}, "Watch"),
    el("p", { class: "dim", id: "watch-count" }),
    el("div", { class: "scroll tall" }, el("table", { id: "watch-table" },
      el("thead", {}, el("tr", {}, ["field", "address", "type", "range", "value", ""].map((h) => el("th", {}, h)))),
      el("tbody", { id: "watch-rows" }))));
  on("fields", (message) => showAt(message.frame, message.values));
  // Values are pushed every few frames; when the game stops (a pause, the end of a frame advance or of a
  // replay) the last push may be a frame or two old, so read them once more: paused, they are exact.
  on("status", (status) => {
    pausedAt = status.paused ? status.frame : null;
    readPaused();
  });
  await refresh();
}

export function shown() {}
