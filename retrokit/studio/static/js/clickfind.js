// Click to find: click a point of the screen, and the server pokes each RAM cell of a region (the search's
// candidates, or an address range) on a copy of the moment, and lists the cells whose poke changed that pixel.
// The game itself is not disturbed; the job runs in small chunks between frames and reports its progress.

import { post } from "./api.js";
import { byId, el, hex, parseNumber, replace } from "./dom.js";
import { pixelAt } from "./play.js";
import { on } from "./socket.js";
import { attempt } from "./status.js";

let active = false; // the panel is shown: a click on the screen starts a search
let job = null;

function swatch(color) {
  const node = el("span", { class: "swatch", title: `rgb(${color.join(", ")})` });
  // Numbers only (the server's colour is three integers), set as a style property, not markup.
  node.style.backgroundColor = `rgb(${color.map((c) => Number(c) | 0).join(",")})`;
  return node;
}

function region() {
  if (byId("cf-candidates").checked) return "candidates";
  const start = parseNumber(byId("cf-start").value, "region's start");
  const length = parseNumber(byId("cf-length").value, "region's length");
  if (start === null || length === null) throw new Error("Expected the region's start address and length.");
  return { start: hex(start), length };
}

function show(report) {
  if (job && report.id < job.id) return; // an older job's last words
  job = report;
  byId("cf-point").replaceChildren(`(${report.x}, ${report.y}) `, report.color?.length ? swatch(report.color) : "");
  const progress = byId("cf-progress");
  progress.max = Math.max(1, report.total);
  progress.value = report.done;
  const what = report.error ? `stopped: ${report.error}` : report.cancelled ? "cancelled"
    : report.finished ? `done in ${report.seconds} s` : "searching…";
  byId("cf-state").textContent = `${report.done.toLocaleString("en")} of ${report.total.toLocaleString("en")} cells poked, ${what}; ${report.hits.length} change the pixel`;
  byId("cf-cancel").disabled = report.finished;
  replace(byId("cf-rows"), report.hits.map((hit) => el("tr", { "data-address": hit.hex },
    el("td", { class: "mono" }, hit.hex),
    el("td", { class: "mono" }, hit.fields.join(", ")),
    el("td", { class: "num" }, String(hit.value)),
    el("td", {}, hit.pokes.map((p) => el("span", { class: "poke" }, `${p.value} → `, swatch(p.color), " "))))));
}

async function start(event) {
  const { x, y } = pixelAt(event);
  const frames = parseNumber(byId("cf-frames").value, "frames") ?? 2;
  show(await post("clickfind", { x, y, region: region(), frames }));
  return `Looking for what draws (${x}, ${y}).`;
}

export async function init(info) {
  replace(byId("clickfind"),
    el("h2", {}, "Click to find"),
    el("p", { class: "dim" }, "Click a point of the game's screen: each cell of the region is poked on a copy of this moment, and the cells whose poke changes that pixel are listed."),
    el("div", { class: "row" },
      el("label", {}, el("input", { type: "radio", name: "cf-region", id: "cf-candidates", checked: true }), " the RAM search's candidates"),
      el("label", {}, el("input", { type: "radio", name: "cf-region", id: "cf-range" }), " the region "),
      el("input", { id: "cf-start", class: "address", value: hex(info.ram.start), "aria-label": "region start" }),
      el("label", {}, "length ", el("input", { id: "cf-length", type: "number", min: 1, max: 8192, value: info.ram.length })),
      el("label", {}, "frames after a poke ", el("input", { id: "cf-frames", type: "number", min: 1, max: 8, value: 2 }))),
    el("div", { class: "row" },
      el("span", {}, "pixel ", el("output", { id: "cf-point" }, "–")),
      el("progress", { id: "cf-progress", max: 1, value: 0 }),
      el("button", { type: "button", id: "cf-cancel", disabled: true }, "Cancel")),
    el("p", { id: "cf-state", class: "dim" }),
    el("div", { class: "scroll" }, el("table", {},
      el("thead", {}, el("tr", {}, ["address", "fields", "value", "pokes that change it"].map((h) => el("th", {}, h)))),
      el("tbody", { id: "cf-rows" }))));
  byId("screen").addEventListener("click", (event) => {
    if (active) attempt(() => start(event), (line) => line);
  });
  byId("cf-cancel").addEventListener("click", () => attempt(async () => show(await post("clickfind/cancel")), "Cancelled."));
  on("clickfind", show);
}

export function shown(visible) {
  active = visible;
  byId("screen").classList.toggle("pick", visible);
}
