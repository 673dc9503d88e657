// Validate: run `retrokit validate`'s checks (retrokit.testing.check_game) on the game and show the report:
// one row per check, its state and scenario, its result and its message (a failure says how to fix it).

import { post } from "./api.js";
import { byId, el, replace } from "./dom.js";
import { on } from "./socket.js";
import { attempt } from "./status.js";

const WORDS = { pass: "passed", warn: "warnings", fail: "failed", skip: "skipped" };

function showReport(report) {
  const counts = report.counts ?? {};
  byId("validate-summary").textContent = `${report.game}: ${report.passed ? "passed" : "FAILED"} (` +
    Object.keys(WORDS).map((s) => `${counts[s] ?? 0} ${WORDS[s]}`).join(", ") + ")";
  byId("validate-summary").className = report.passed ? "ok" : "error";
  replace(byId("validate-rows"), report.results.map((r) => el("tr", { class: r.status },
    el("td", {}, r.check),
    el("td", { class: "mono" }, [r.state, r.scenario ? `[${r.scenario}]` : ""].filter(Boolean).join(" ")),
    el("td", { class: r.status }, r.status.toUpperCase()),
    el("td", {}, el("pre", {}, r.message)))));
}

async function run() {
  const button = byId("validate-run");
  button.disabled = true;
  byId("validate-summary").textContent = "checking… (the game plays on meanwhile)";
  byId("validate-summary").className = "dim";
  try {
    const answer = await post("validate", {});
    const report = answer;
    showReport(report);
    return `Validated ${report.game}: ${report.passed ? "passed" : "failed"}.`;
  } finally {
    button.disabled = false;
  }
}

/** Progress while the checks run: the stage, and what it is on (a state, a scenario). */
function progress(message) {
  if (message.stage === "done" || !byId("validate-run").disabled) return;
  byId("validate-summary").textContent = `checking ${message.game ?? ""}: ${message.stage}${message.detail ? ` (${message.detail})` : ""}…`;
}

export async function init() {
  replace(byId("validate"),
    el("h2", {}, "Validate"),
    el("p", { class: "dim" }, "Runs every check of `retrokit validate` on this game: its files against the schema, each state, each scenario, each movie, and a smoke run."),
    el("div", { class: "row" }, el("button", { type: "button", id: "validate-run" }, "Validate")),
    el("p", { id: "validate-summary" }),
    el("div", { class: "scroll tall report" }, el("table", { id: "validate-table" },
      el("thead", {}, el("tr", {}, ["check", "state", "result", "message"].map((h) => el("th", {}, h)))),
      el("tbody", { id: "validate-rows" }))));
  byId("validate-run").addEventListener("click", () => attempt(run, (line) => line));
  on("validate", progress);
}

export function shown() {}
