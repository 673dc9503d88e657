// RAM search: the session's RamSearch (the same filters, snapshots, undo/redo, poke and game.yaml writer as
// `retrokit ramsearch`), driven from a form. The candidate table lists groups of candidates as `ramsearch show`
// does; the server pushes the listed rows' live values ({"type": "candidates"}) while the game runs.
//
// A filter compares the newest snapshot with the one before (or another, or a number). While playing, "now"
// is not a snapshot yet, so by default the page takes one first: a filter then compares the game as it is
// on the screen with the last snapshot, as BizHawk's RAM Search does.

import { get, post } from "./api.js";
import { byId, el, hex, parseNumber, replace } from "./dom.js";
import { on } from "./socket.js";
import { attempt, attemptOnSubmit } from "./status.js";
import { refresh as refreshWatch } from "./watch.js";

const LIMIT = 100;
const NEEDS_NUMBER = new Set(["changed-by"]);
const COMPARES_SNAPSHOT = new Set(["increased", "decreased", "changed", "unchanged"]);

let state = null; // GET /search
const liveCells = new Map(); // "address|type" -> the <td> of its live value
let selected = null; // the row chosen for poke and "add as field"

const key = (address, type) => `${address}|${type}`;

function thanOptions() {
  const options = [el("option", { value: "" }, "the number"), el("option", { value: "previous" }, "previous snapshot"),
    el("option", { value: "first" }, "first snapshot")];
  (state?.snapshots ?? []).forEach((label, index) => options.push(el("option", { value: String(index) }, `snapshot ${index}: ${label}`)));
  options.push(el("option", { value: "address" }, "the value at address…"), el("option", { value: "changes" }, "change count"));
  return options;
}

/** Show the search's status: count, snapshots, filters applied, undo/redo. */
function showStatus(status) {
  state = status;
  byId("search-count").textContent = `${status.count.toLocaleString("en")} candidates`;
  byId("search-undo").disabled = !status.can_undo;
  byId("search-redo").disabled = !status.can_redo;
  const op = byId("search-op");
  if (op.options.length === 0) replace(op, status.ops.map((name) => el("option", { value: name }, name)));
  const than = byId("search-than");
  const keep = than.value;
  replace(than, thanOptions());
  than.value = [...than.options].some((o) => o.value === keep) ? keep : "";
  replace(byId("search-history"),
    status.snapshots.map((label, index) => el("li", { class: "dim" }, `snapshot ${index}: ${label}`)),
    status.history.map((line) => el("li", {}, line)));
  byId("search-types").placeholder = `${status.types.length} types: ${status.types.join(" ")}`;
  formChanged();
}

/** Show the boxes the chosen operation takes. */
function formChanged() {
  const op = byId("search-op").value;
  const than = byId("search-than").value;
  byId("search-value").disabled = COMPARES_SNAPSHOT.has(op) || (than !== "" && than !== "changes" && !NEEDS_NUMBER.has(op));
  byId("search-than-address").hidden = than !== "address";
}

function scaleText(row) {
  if (row.scale) return row.scale;
  return row.scales && row.scales.length > 1 ? row.scales.map((s) => s || "=").join(",") : "-";
}

function choose(row, tr) {
  selected = row;
  for (const other of byId("search-rows").querySelectorAll("tr")) other.classList.remove("selected");
  tr.classList.add("selected");
  byId("field-address").value = row.hex;
  byId("field-type").value = row.type;
  byId("poke-address").value = row.hex;
  byId("poke-type").value = row.type;
  byId("poke-value").value = String(row.value);
}

/** List the candidates (the first LIMIT groups by address); their live values then arrive by socket. */
export async function list() {
  const answer = await get(`search/candidates?limit=${LIMIT}`);
  liveCells.clear();
  const rows = answer.rows.map((row) => {
    const live = el("td", { class: "num live" }, String(row.value));
    liveCells.set(key(row.address, row.type), live);
    const tr = el("tr", { "data-address": row.hex, "data-type": row.type },
      el("td", { class: "mono" }, row.hex),
      el("td", { class: "mono", title: row.also.length ? `also ${row.also.join(" ")}` : "" }, row.type,
        row.also.length ? el("span", { class: "dim" }, ` +${row.also.length}`) : null),
      el("td", { class: "mono" }, scaleText(row)),
      el("td", { class: "num" }, String(row.changes)),
      el("td", { class: "mono" }, row.values.join(" ")),
      live);
    tr.addEventListener("click", () => choose(row, tr));
    return tr;
  });
  replace(byId("search-rows"), rows);
  // "groups" is null when the candidates are too many to group them all (the server lists the first ones only).
  const groups = answer.groups === null ? "many" : answer.groups.toLocaleString("en");
  byId("search-listed").textContent = answer.more
    ? `the first ${answer.rows.length} of ${groups} groups by address (types reading the same bytes alike)`
    : `${groups} groups (types reading the same bytes alike)`;
  selected = null;
}

async function refresh() {
  showStatus(await get("search"));
  await list();
}

async function filter() {
  const op = byId("search-op").value;
  const choice = byId("search-than").value;
  const body = { op };
  const value = parseNumber(byId("search-value").value, "filter's number");
  if (!byId("search-value").disabled && value !== null) body.value = value;
  if (choice === "address") body.than = hex(parseNumber(byId("search-than-address").value, "address") ?? 0);
  else if (choice !== "") body.than = /^\d+$/.test(choice) ? Number(choice) : choice;
  if (byId("search-snap-first").checked) await post("search/snapshot", { label: `before ${op}` });
  const answer = await post("search/filter", body);
  showStatus(answer);
  await list();
  return `${answer.filter}: ${answer.before.toLocaleString("en")} -> ${answer.count.toLocaleString("en")} candidates.`;
}

async function addField() {
  const name = byId("field-name").value.trim();
  const lo = parseNumber(byId("field-lo").value, "range's low end");
  const hi = parseNumber(byId("field-hi").value, "range's high end");
  if ((lo === null) !== (hi === null)) throw new Error("Expected both ends of the range, or neither.");
  const body = { name, address: byId("field-address").value.trim(), type: byId("field-type").value.trim(),
    force: byId("field-force").checked };
  if (lo !== null) body.range = [lo, hi];
  const answer = await post("search/field", body);
  refreshWatch();
  const range = answer.range ? `, range [${answer.range.join(", ")}]` : "";
  return `Wrote field ${answer.name} (${answer.hex}, ${answer.type}${range}) into ${answer.path}.`;
}

/** Find a field in one go (POST /search/find, as `retrokit ramsearch find`): play what changes it and what keeps
 * it, in turn, filtering after each, until one value is left; it fills "add as field", or is added if asked. */
async function find() {
  const name = byId("find-name").value.trim();
  const kind = byId("find-kind").value;
  const body = { name, changes: byId("find-changes").value, keeps: byId("find-keeps").value, kind };
  if (kind === "becomes") body.value = parseNumber(byId("find-value").value, "number it becomes");
  if (byId("find-save").checked) {
    const lo = parseNumber(byId("field-lo").value, "range's low end");
    const hi = parseNumber(byId("field-hi").value, "range's high end");
    if ((lo === null) !== (hi === null)) throw new Error("Expected both ends of the range, or neither.");
    Object.assign(body, { save: true, force: byId("field-force").checked }, lo === null ? {} : { range: [lo, hi] });
  }
  const answer = await post("search/find", body);
  showStatus(answer);
  await list();
  if (!answer.found) {
    throw new Error(`Expected one value left; ${answer.reason} (${answer.left.toLocaleString("en")} candidates).`);
  }
  const found = answer.rows[0];
  Object.assign(byId("field-name"), { value: name });
  Object.assign(byId("field-address"), { value: found.hex });
  Object.assign(byId("field-type"), { value: found.type });
  const said = `Found ${name || "it"}: ${found.hex} ${found.type} (${answer.reason}).`;
  if (!answer.field) return said;
  refreshWatch();
  const range = answer.field.range ? `, range [${answer.field.range.join(", ")}]` : "";
  return `${said} Wrote field ${answer.field.name} (${answer.field.hex}, ${answer.field.type}${range}) into ${answer.field.path}.`;
}

async function poke() {
  const value = parseNumber(byId("poke-value").value, "value");
  if (value === null) throw new Error("Expected a value to poke.");
  const answer = await post("search/poke", { address: byId("poke-address").value.trim(), value,
    type: byId("poke-type").value.trim() || "|u1" });
  // Live values come with frames; a paused game has none, so show the poked value and the fields now.
  const cell = liveCells.get(key(answer.address, answer.type));
  if (cell) cell.textContent = String(answer.value);
  await refreshWatch();
  return `Poked ${hex(answer.address)} (${answer.type}): it now reads ${answer.value}.`;
}

export async function init(info) {
  const panel = byId("search");
  replace(panel,
    el("h2", {}, "RAM search"),
    el("div", { class: "row" },
      el("strong", { id: "search-count" }, ""),
      el("button", { type: "button", id: "search-new", title: "Every address and type a candidate again, from the game now" }, "New search"),
      el("input", { id: "search-types", size: 24, "aria-label": "types of a new search (space-separated codes; empty: all)" }),
      el("button", { type: "button", id: "search-snapshot" }, "Snapshot"),
      el("button", { type: "button", id: "search-undo" }, "Undo"),
      el("button", { type: "button", id: "search-redo" }, "Redo")),
    el("form", { id: "search-filter", class: "row" },
      el("label", {}, "keep values ", el("select", { id: "search-op" })),
      el("input", { id: "search-value", size: 8, placeholder: "number", "aria-label": "the filter's number" }),
      el("label", {}, "than ", el("select", { id: "search-than" })),
      el("input", { id: "search-than-address", class: "address", placeholder: hex(info.ram.start), hidden: true, "aria-label": "address compared with" }),
      el("label", { title: "Take a snapshot of the game now before filtering, so the filter sees what the screen shows" },
        el("input", { type: "checkbox", id: "search-snap-first", checked: true }), " snapshot now"),
      el("button", { type: "submit", id: "search-apply" }, "Filter")),
    el("details", {}, el("summary", { class: "dim" }, "snapshots and filters"), el("ol", { id: "search-history", start: 1 })),
    el("p", { class: "dim", id: "search-listed" }),
    el("div", { class: "scroll" }, el("table", { id: "search-table" },
      el("thead", {}, el("tr", {}, ["address", "type", "scale", "changes", "values at snapshots", "now"].map((h) => el("th", {}, h)))),
      el("tbody", { id: "search-rows" }))),
    el("h3", {}, "Find a field"),
    el("form", { id: "find-form", class: "row", title: "Plays both scripts in turn from the game now, filtering after each, until one value is left" },
      el("label", {}, "play ", el("input", { id: "find-changes", size: 14, placeholder: "RIGHT*200", "aria-label": "a script that changes the field" })),
      el("label", {}, "which ", el("select", { id: "find-kind" },
        ["decreases", "increases", "changes", "becomes"].map((kind) => el("option", { value: kind }, kind)))),
      el("input", { id: "find-value", size: 5, placeholder: "N", hidden: true, "aria-label": "the number it becomes" }),
      el("label", {}, " it; then ", el("input", { id: "find-keeps", size: 10, placeholder: "_*130", "aria-label": "a script that keeps the field" })),
      el("label", {}, " keeps it; name ", el("input", { id: "find-name", size: 10, placeholder: "lives" })),
      el("label", { title: "Add it to game.yaml, with the range and replace boxes below" },
        el("input", { type: "checkbox", id: "find-save" }), " add as field"),
      el("button", { type: "submit", id: "find" }, "Find")),
    el("h3", {}, "Add as field (game.yaml)"),
    el("form", { id: "field-form", class: "row" },
      el("label", {}, "name ", el("input", { id: "field-name", size: 12, placeholder: "lives" })),
      el("label", {}, "address ", el("input", { id: "field-address", class: "address" })),
      el("label", {}, "type ", el("input", { id: "field-type", size: 5, placeholder: "|u1" })),
      el("label", {}, "range ", el("input", { id: "field-lo", size: 4, placeholder: "lo" }), " to ",
        el("input", { id: "field-hi", size: 4, placeholder: "hi" })),
      el("label", {}, el("input", { type: "checkbox", id: "field-force" }), " replace"),
      el("button", { type: "submit", id: "field-add" }, "Add field")),
    el("h3", {}, "Poke"),
    el("form", { id: "poke-form", class: "row" },
      el("label", {}, "address ", el("input", { id: "poke-address", class: "address" })),
      el("label", {}, "type ", el("input", { id: "poke-type", size: 5, value: "|u1" })),
      el("label", {}, "value ", el("input", { id: "poke-value", size: 8 })),
      el("button", { type: "submit", id: "poke" }, "Poke")));

  byId("search-op").addEventListener("change", formChanged);
  byId("search-than").addEventListener("change", formChanged);
  attemptOnSubmit(byId("search-filter"), filter, (line) => line);
  byId("search-new").addEventListener("click", () => attempt(async () => {
    const types = byId("search-types").value.trim();
    showStatus(await post("search/new", types ? { types: types.split(/[\s,]+/) } : {}));
    await list();
    return state.count;
  }, (count) => `New search: ${count.toLocaleString("en")} candidates.`));
  byId("search-snapshot").addEventListener("click", () => attempt(async () => {
    const answer = await post("search/snapshot", { label: "snapshot" });
    showStatus(answer);
    await list();
    return answer.snapshot;
  }, (index) => `Snapshot ${index}.`));
  for (const [verb, key, did] of [["undo", "undone", "Undid"], ["redo", "redone", "Redid"]]) {
    byId(`search-${verb}`).addEventListener("click", () => attempt(async () => {
      const answer = await post(`search/${verb}`);
      showStatus(answer);
      await list();
      return `${did} ${answer[key]}: ${answer.count.toLocaleString("en")} candidates.`;
    }, (line) => line));
  }
  attemptOnSubmit(byId("field-form"), addField, (line) => line);
  attemptOnSubmit(byId("find-form"), find, (line) => line);
  byId("find-kind").addEventListener("change", () => { byId("find-value").hidden = byId("find-kind").value !== "becomes"; });
  attemptOnSubmit(byId("poke-form"), poke, (line) => line);

  // Live values of the listed rows; a changed value flashes.
  // One layout per message, not one per changed cell: restarting each cell's animation by reading its size
  // forced a layout of the page per cell, which kept a core busy while a game played (100 rows, 20 a second).
  on("candidates", (message) => {
    const changed = [];
    for (const [address, type, value] of message.values) {
      const cell = liveCells.get(key(address, type));
      if (!cell || cell.textContent === String(value)) continue;
      cell.textContent = String(value);
      cell.classList.remove("flash");
      changed.push(cell);
    }
    if (changed.length === 0) return;
    void byId("search-rows").offsetWidth; // one reflow restarts every removed animation
    for (const cell of changed) cell.classList.add("flash");
  });
  await refresh();
}

export function shown() {}
