// Scenario: the YAML in an editor (CodeMirror 5), compiled as it is typed, its errors marked at the line and
// column the language reports; saving writes the game's scenario file; "watch live" runs the editor's text
// after every frame and plots its reward, cumulative reward and done over the last seconds.
//
// Every edit is also kept by the server as a draft (PUT /api/scenario/draft), so a closed tab or a stopped
// server loses nothing: opening the scenario again restores the draft. The page still asks before it drops
// an unsaved edit itself (opening another scenario, discarding, closing the tab).

import { api, get, post, ApiError } from "./api.js";
import { byId, el, replace } from "./dom.js";
import { drawPlot, rangeText } from "./plot.js";
import { on } from "./socket.js";
import { attempt, background, say } from "./status.js";

const SECONDS = 10; // the plot's width in game time
const DEBOUNCE_MS = 400;

let editor = null;
let name = null; // the scenario open
let savedText = ""; // its text on disk
let marks = [];
let markedLines = [];
let timer = null;
let frameRate = 60;
const samples = new Map(); // frame -> [frame, reward, total, done]
let plotQueued = false;

/** Whether the editor holds an edit not saved to the scenario's file. */
export function unsaved() {
  return editor !== null && editor.getValue() !== savedText;
}

function clearMarks() {
  for (const mark of marks) mark.clear();
  for (const line of markedLines) editor.removeLineClass(line, "background", "cm-error-line");
  marks = [];
  markedLines = [];
}

/** Mark an error at its line and column (both from 1, as the language reports them) and list it. */
function showErrors(result) {
  clearMarks();
  const list = byId("scenario-errors");
  if (result.ok) {
    replace(list);
    const fields = result.fields?.length ? `reads ${result.fields.join(", ")}` : "reads no field";
    byId("scenario-state").textContent = `compiles (${result.players} player${result.players === 1 ? "" : "s"}; ${fields})`;
    byId("scenario-state").className = "ok";
    return;
  }
  byId("scenario-state").textContent = "does not compile";
  byId("scenario-state").className = "error";
  const where = result.line ? `line ${result.line}, column ${result.column ?? 1}: ` : "";
  const item = el("li", { "data-line": result.line ?? "", "data-column": result.column ?? "" },
    el("a", { href: "#", onclick: (event) => {
      event.preventDefault();
      if (result.line) {
        editor.focus();
        editor.setCursor({ line: result.line - 1, ch: (result.column ?? 1) - 1 });
      }
    } }, where + result.error),
    // The rest of the language's message: the source line and a caret under the place (fixed-width text).
    result.message ? el("pre", { class: "dim" }, result.message.split("\n").slice(1).join("\n")) : null);
  replace(list, item);
  if (result.line) {
    const line = Math.min(result.line - 1, editor.lineCount() - 1);
    const text = editor.getLine(line) ?? "";
    const ch = Math.min(Math.max((result.column ?? 1) - 1, 0), text.length);
    // Underline the name or number at the column (or one character), where the error points.
    const rest = text.slice(ch).match(/^[\w.]+/);
    const end = ch + Math.max(1, rest ? rest[0].length : 1);
    marks.push(editor.markText({ line, ch }, { line, ch: end }, { className: "cm-error-mark", title: result.error }));
    editor.addLineClass(line, "background", "cm-error-line");
    markedLines.push(line);
  }
}

/** Keep the edit as the server's draft (or drop the draft when the text is the file's again), and compile. */
async function edited() {
  const text = editor.getValue();
  const scenario = encodeURIComponent(name);
  byId("scenario-unsaved").hidden = !unsaved();
  if (unsaved()) showErrors(await api("PUT", "scenario/draft", { name, text }));
  else {
    await api("DELETE", `scenario/draft?name=${scenario}`);
    showErrors(await post("scenario/compile", { name, text }));
  }
}

/** Open a scenario: the file's text, or the unsaved draft the server kept. */
async function open(wanted) {
  if (unsaved() && !confirm(`Your edit of ${name} is not saved. Open ${wanted || "another scenario"} and leave it as a draft?`)) return;
  const answer = await get(`scenario${wanted ? `?name=${encodeURIComponent(wanted)}` : ""}`);
  name = answer.name;
  savedText = answer.text;
  replace(byId("scenario-names"), answer.names.map((n) => el("option", { value: n })));
  byId("scenario-name").value = name;
  byId("scenario-target").textContent = answer.writable ? `saves to ${answer.save_to}` : `read-only: ${answer.why_not}`;
  byId("scenario-save").disabled = !answer.writable;
  editor.setValue(answer.draft ?? answer.text);
  editor.clearHistory();
  if (answer.draft !== null && answer.draft !== undefined) say(`Restored your unsaved edit of ${name}: the server kept it as a draft.`);
  await edited();
}

async function save() {
  try {
    const answer = await post("scenario/save", { name, text: editor.getValue() });
    savedText = editor.getValue();
    byId("scenario-unsaved").hidden = true;
    return `Saved scenario ${answer.name} to ${answer.saved}.`;
  } catch (error) {
    if (error instanceof ApiError && error.data) showErrors({ ok: false, ...error.data });
    throw error;
  }
}

async function discard() {
  if (!unsaved()) return "Nothing to discard: the editor holds the saved scenario.";
  if (!confirm(`Drop your unsaved edit of ${name} and go back to the saved file?`)) return "Kept your edit.";
  editor.setValue(savedText);
  await edited();
  return `Dropped the edit of ${name}.`;
}

async function goLive() {
  samples.clear();
  try {
    showReward(await post("scenario/live", { name, text: editor.getValue() }));
  } catch (error) {
    if (error instanceof ApiError && error.data) showErrors({ ok: false, ...error.data });
    throw error;
  }
  byId("scenario-stop").disabled = false;
  return `Watching ${name}'s reward live: play the game.`;
}

async function stopLive() {
  await api("DELETE", "scenario/live");
  byId("scenario-stop").disabled = true;
  byId("reward-live").textContent = "off";
  return "Stopped the live reward.";
}

function number(value) {
  return Number.isInteger(value) ? String(value) : value.toFixed(3);
}

let filling = false;

/** Fetch the last frames' samples (GET /api/scenario/live): a push carries only the newest few, so frames run
 * faster than the pushes (a frame advance of 200, 8x) would leave a gap in the plot. */
async function fill() {
  if (filling) return;
  filling = true;
  try {
    const report = await get("scenario/live");
    if (report.live) for (const sample of report.samples ?? []) samples.set(sample[0], sample);
    queuePlot();
  } finally {
    filling = false;
  }
}

/** Keep the last SECONDS of samples, and draw them at the next animation frame. */
function queuePlot() {
  const newest = samples.size ? Math.max(...samples.keys()) : 0;
  const keep = newest - Math.round(SECONDS * frameRate);
  for (const frame of samples.keys()) if (frame < keep) samples.delete(frame);
  if (plotQueued) return;
  plotQueued = true;
  requestAnimationFrame(() => {
    plotQueued = false;
    const ordered = [...samples.values()].sort((a, b) => a[0] - b[0]);
    drawPlot(byId("reward-plot"), ordered);
    byId("range-reward").textContent = rangeText(ordered.map((s) => s[1]));
    byId("range-total").textContent = rangeText(ordered.map((s) => s[2]));
  });
}

/** A reward report: merge its samples (they overlap between pushes), show the numbers, plot. */
function showReward(report) {
  if (report.error) {
    byId("reward-live").textContent = "stopped: the scenario failed";
    showErrors({ ok: false, ...report.error });
    return;
  }
  const known = samples.size ? Math.max(...samples.keys()) : null;
  const oldest = report.samples?.length ? report.samples[0][0] : null;
  if (known !== null && oldest !== null && oldest > known + 1) background(fill);
  for (const sample of report.samples ?? []) samples.set(sample[0], sample);
  const newest = report.frame ?? 0;
  const last = report.samples?.length ? report.samples[report.samples.length - 1] : null;
  byId("reward-live").textContent = `${report.name}, frame ${newest}`;
  byId("reward-now").textContent = last ? number(last[1]) : "0";
  byId("reward-total").textContent = number(report.total ?? 0);
  byId("reward-done").textContent = report.done ? "yes" : "no";
  byId("reward-done").className = report.done ? "error" : "";
  queuePlot();
}

export async function init(info) {
  frameRate = info.frame_rate ?? 60;
  replace(byId("scenario"),
    el("h2", {}, "Scenario"),
    el("div", { class: "row" },
      el("label", {}, "scenario ", el("input", { id: "scenario-name", list: "scenario-names", size: 14 })),
      el("datalist", { id: "scenario-names" }),
      el("button", { type: "button", id: "scenario-open" }, "Open"),
      el("button", { type: "button", id: "scenario-save" }, "Save"),
      el("button", { type: "button", id: "scenario-discard" }, "Discard edit"),
      el("span", { id: "scenario-unsaved", class: "warn", hidden: true }, "unsaved (kept as a draft)")),
    el("p", { class: "dim", id: "scenario-target" }),
    el("textarea", { id: "scenario-text" }),
    el("p", {}, el("output", { id: "scenario-state" })),
    el("ul", { id: "scenario-errors", class: "compile-errors" }),
    el("h3", {}, "Live reward"),
    el("div", { class: "row" },
      el("button", { type: "button", id: "scenario-live" }, "Watch live"),
      el("button", { type: "button", id: "scenario-stop", disabled: true }, "Stop"),
      el("span", { class: "dim" }, "scenario: ", el("output", { id: "reward-live" }, "off"))),
    el("p", { class: "legend" },
      el("span", { class: "reward" }, "reward ", el("output", { id: "reward-now" }, "–"), " (", el("output", { id: "range-reward" }), ")"),
      el("span", { class: "cumulative" }, "cumulative ", el("output", { id: "reward-total" }, "–"), " (", el("output", { id: "range-total" }), ")"),
      el("span", { class: "done" }, "done ", el("output", { id: "reward-done" }, "–"))),
    el("canvas", { id: "reward-plot", class: "plot", "aria-label": `reward over the last ${SECONDS} seconds` }));

  editor = CodeMirror.fromTextArea(byId("scenario-text"), { mode: "yaml", lineNumbers: true, indentUnit: 2,
    tabSize: 2, extraKeys: { Tab: (cm) => cm.replaceSelection("  ") } });
  editor.on("changes", () => {
    byId("scenario-unsaved").hidden = !unsaved();
    clearTimeout(timer);
    timer = setTimeout(() => background(edited), DEBOUNCE_MS);
  });
  byId("scenario-open").addEventListener("click", () => attempt(() => open(byId("scenario-name").value.trim())));
  byId("scenario-save").addEventListener("click", () => attempt(save, (line) => line));
  byId("scenario-discard").addEventListener("click", () => attempt(discard, (line) => line));
  byId("scenario-live").addEventListener("click", () => attempt(goLive, (line) => line));
  byId("scenario-stop").addEventListener("click", () => attempt(stopLive, (line) => line));
  on("reward", showReward);
  await open(null);
}

export function shown(visible) {
  if (visible && editor) editor.refresh(); // CodeMirror measures itself wrong while hidden
}
