// One line at the bottom of the page for what just happened: the result of an action, or the server's one-line
// error. Errors stay until the next message so a user can read them; both are plain text.

import { byId } from "./dom.js";

let timer = null;

/** Show a message; kind is "ok" or "error". */
export function say(message, kind = "ok") {
  const line = byId("message");
  line.textContent = message;
  line.className = kind;
  clearTimeout(timer);
  if (kind === "ok") timer = setTimeout(() => { if (line.textContent === message) line.textContent = ""; }, 6000);
}

/** Run an async action from a button, reporting its error (an ApiError carries the server's line). The line is
 * cleared first, so what it shows afterwards is this action's outcome, not an older one's. */
export async function attempt(action, done) {
  const line = byId("message");
  line.textContent = "";
  line.className = "";
  try {
    const result = await action();
    if (done) say(typeof done === "function" ? done(result) : done);
    return result;
  } catch (error) {
    say(error.message, "error");
    return undefined;
  }
}
