// The studio page: ask the server what game this is (/api/info), then build each panel and open the socket.
// Each panel lives in its own module with an init(info) function; a panel that fails to start shows its error
// and leaves the others working.

import { get } from "./api.js";
import { byId, setAddressDigits } from "./dom.js";
import * as play from "./play.js";
import * as socket from "./socket.js";
import { say } from "./status.js";
import * as states from "./states.js";
import * as search from "./search.js";
import * as watch from "./watch.js";
import * as scenario from "./scenario.js";
import * as clickfind from "./clickfind.js";
import * as ramview from "./ramview.js";
import * as validate from "./validate.js";
import * as newgame from "./newgame.js";

const TOOLS = { search, watch, scenario, clickfind, ramview, validate, newgame };

/** Show one tool panel; tell each tool whether it is visible (the RAM view only streams while shown). */
function showTab(name) {
  if (!(name in TOOLS)) name = "search";
  for (const tab of byId("tabs").querySelectorAll("button")) {
    const selected = tab.dataset.panel === name;
    tab.setAttribute("aria-selected", String(selected));
    byId(tab.dataset.panel).hidden = !selected;
  }
  for (const [key, tool] of Object.entries(TOOLS)) tool.shown?.(key === name);
  history.replaceState(null, "", `${location.search}#${name}`);
}

async function boot() {
  let info;
  try {
    info = await get("info");
  } catch (error) {
    say(error.message, "error");
    byId("connection").textContent = "refused";
    return;
  }
  document.title = `${info.game} · retrokit studio`;
  byId("game-name").textContent = `${info.game} (${info.system})`;
  setAddressDigits(info.ram.digits);
  play.init(info);
  // The panels start at once, not one after the other: each waits for its own answers from the server, and in
  // turn they kept the page from being ready for the sum of those waits.
  await Promise.all(Object.entries({ states, ...TOOLS }).map(async ([name, module]) => {
    try {
      await module.init(info);
    } catch (error) {
      say(`The ${name} panel could not start: ${error.message}`, "error");
    }
  }));
  for (const tab of byId("tabs").querySelectorAll("button")) tab.addEventListener("click", () => showTab(tab.dataset.panel));
  showTab(location.hash.slice(1));
  window.addEventListener("hashchange", () => showTab(location.hash.slice(1))); // a link or Back to #watch
  socket.on("error", (message) => say(message.error, "error"));
  socket.connect();
  newgame.afterReload(socket.send); // queued until the socket opens
  document.body.dataset.ready = "true"; // the browser tests wait for this
}

// An unsaved scenario edit is not lost by closing the tab: the browser asks first.
window.addEventListener("beforeunload", (event) => {
  if (scenario.unsaved()) {
    event.preventDefault();
    event.returnValue = "";
  }
});

boot();
