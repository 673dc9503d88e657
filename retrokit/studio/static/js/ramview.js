// RAM view: a grid of a RAM region (16 bytes a row) with live values; a byte that changed since the last
// update is highlighted, and one that differs from a chosen snapshot of the RAM search is outlined. The
// server streams the region only while this panel is shown, because drawing 4 KiB 20 times a second costs.

import { api, post } from "./api.js";
import { byId, el, hex, parseNumber, replace } from "./dom.js";
import { on } from "./socket.js";
import { attempt, attemptOnSubmit } from "./status.js";

const COLUMNS = 16;
let visible = false;
let cells = []; // <td> per byte offset
let view = null; // {start, length}

function grid(start, length) {
  cells = [];
  const rows = [];
  rows.push(el("tr", {}, el("th", {}, ""), Array.from({ length: COLUMNS }, (_, i) => el("th", {}, i.toString(16).toUpperCase()))));
  for (let row = 0; row < length; row += COLUMNS) {
    const tds = [];
    for (let col = 0; col < COLUMNS && row + col < length; col += 1) {
      const td = el("td", { title: hex(start + row + col) }, "··");
      cells.push(td);
      tds.push(td);
    }
    rows.push(el("tr", {}, el("th", { class: "mono" }, hex(start + row)), tds));
  }
  replace(byId("ram-grid"), rows);
}

function show(report) {
  if (!view || report.start !== view.start || report.length !== view.length) {
    view = { start: report.start, length: report.length };
    grid(report.start, report.length);
  }
  const changed = new Set(report.changed);
  const differs = new Set(report.differs ?? []);
  report.values.forEach((value, i) => {
    const td = cells[i];
    td.textContent = value.toString(16).toUpperCase().padStart(2, "0");
    td.classList.toggle("changed", changed.has(i));
    td.classList.toggle("differs", differs.has(i));
  });
  byId("ram-frame").textContent = `frame ${report.frame}${report.snapshot === null || report.snapshot === undefined ? "" : `, against snapshot ${report.snapshot}`}`;
}

function wanted() {
  const start = parseNumber(byId("ram-start").value, "start address");
  const length = parseNumber(byId("ram-length").value, "length") ?? 256;
  const snapshot = parseNumber(byId("ram-snapshot").value, "snapshot");
  if (start === null) throw new Error(`Expected the region's start address, e.g. ${byId("ram-start").defaultValue}.`);
  const body = { start: hex(start), length };
  if (snapshot !== null) body.snapshot = snapshot;
  return body;
}

async function watch() {
  if (!visible) return;
  show(await post("ram/watch", wanted()));
}

export async function init(info) {
  replace(byId("ramview"),
    el("h2", {}, "RAM view"),
    el("form", { id: "ram-form", class: "row" },
      // The system's RAM region (its start and first bytes, from /api/info): 0xFF0000 on a Genesis, 0x80 on a 2600.
      el("label", {}, "from ", el("input", { id: "ram-start", class: "address", value: hex(info.ram.start) })),
      el("label", {}, "bytes ", el("input", { id: "ram-length", type: "number", min: 16, max: 4096, step: 16, value: info.ram.length })),
      el("label", { title: "Outline the bytes that differ from this snapshot of the RAM search" }, "compare with snapshot ",
        el("input", { id: "ram-snapshot", size: 3, placeholder: "none" })),
      el("button", { type: "submit" }, "Show")),
    el("p", { class: "dim" }, el("output", { id: "ram-frame" }), " · ", el("span", { class: "changed" }, "changed since the last update"),
      " · ", el("span", { class: "differs" }, "differs from the snapshot")),
    el("div", { class: "scroll tall" }, el("table", { id: "ram-grid", class: "ramgrid" })));
  attemptOnSubmit(byId("ram-form"), watch);
  on("ram", (report) => {
    if (visible) show(report);
  });
}

export function shown(now) {
  if (now === visible) return;
  visible = now;
  if (now) attempt(watch);
  else api("DELETE", "ram/watch").catch(() => {});
}

